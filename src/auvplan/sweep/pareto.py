"""The energy / navigation trade-off of a sweep: points and their non-dominated front.

Each point is one setting of the varied keys: its fleet energy [J] against the navigation
objective, ``terrain_information`` (mean information, higher is better) or, once a navigation
evaluation filled it, ``tan_rmse_m`` (TAN position RMSE [m], lower is better). Points are
labelled by ``weights.terrain`` when it is swept (else by the first varied key) and grouped by
the other varied keys (and by the seed when each seed is its own mission, the scenario
family); runs that differ only in a mission file's seed are averaged. The front is taken per
group among plans that CONVERGED (others are drawn, not ranked), and, when every group is the
same mission, also over all groups together (``on_overall_front``).

**The energy-only reference.** A point with ``weights.terrain = 0`` is the energy-only plan
(the optimiser sees neither the desired path nor the information reward). Each point is
compared with its group's reference (or, for one mission, the first group's when its own
group has none): ``energy_increase`` = E / E_ref − 1 and ``improvement``, the relative gain in
navigation (1 − RMSE / RMSE_ref for TAN, I / I_ref − 1 for information), both fractions.
:func:`trade_off` picks from them the best improvement within an energy budget (issue 13: 10 %)
and the least energy that reaches a target improvement (30 %).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Final

import numpy as np
import pandas as pd

from auvplan._typing import BoolArray, FloatArray
from auvplan.sweep.table import TAN_COLUMN

#: The key whose values label the points when it is swept.
LABEL_KEY: Final = "weights.terrain"
INFORMATION_COLUMN: Final = "terrain_information"
ENERGY_COLUMN: Final = "energy_J"
#: Issue 13's target: this much better navigation for at most this much more energy [-].
TARGET_IMPROVEMENT: Final = 0.30
ENERGY_BUDGET: Final = 0.10


@dataclass(frozen=True)
class ParetoView:
    """The points of a sweep's trade-off.

    ``points`` has the columns ``group`` (text naming the other varied values, ``""`` for a
    single group), ``label`` (the value of ``label_key``), ``energy_J``, the ``objective``
    column, ``n_runs`` (runs averaged), ``converged``, ``on_front``, ``on_overall_front``,
    ``is_reference`` (an energy-only plan), ``energy_increase`` and ``improvement`` (module
    notes; NaN without a reference). ``same_mission`` is False when groups are different
    missions (the scenario family), whose energies do not compare.
    """

    points: pd.DataFrame
    label_key: str | None
    objective: str
    maximize: bool
    same_mission: bool


def non_dominated(energy: FloatArray, objective: FloatArray, *, maximize: bool) -> BoolArray:
    """Which points no other point beats on both axes (less energy, better objective).

    Point ``i`` is dominated when some ``j`` has ``energy[j] <= energy[i]`` and an objective at
    least as good, one of the two strictly.

    Examples
    --------
    >>> non_dominated(np.array([1.0, 2.0, 3.0, 2.5]), np.array([0.1, 0.5, 0.9, 0.4]),
    ...               maximize=True).tolist()
    [True, True, True, False]
    """
    better = objective if maximize else -objective
    no_worse = (energy[None, :] <= energy[:, None]) & (better[None, :] >= better[:, None])
    strictly = (energy[None, :] < energy[:, None]) | (better[None, :] > better[:, None])
    return np.asarray(~(no_worse & strictly).any(axis=1), dtype=np.bool_)


def pareto_view(
    frame: pd.DataFrame, keys: Sequence[str], *, seeds_are_missions: bool
) -> ParetoView | None:
    """The trade-off points of a sweep table (:func:`auvplan.sweep.table.sweep_frame`).

    Parameters
    ----------
    frame : DataFrame
        The sweep's table.
    keys : sequence of str
        The varied keys (columns of ``frame``).
    seeds_are_missions : bool
        True when each seed is a different mission (the scenario family): seeds are then
        groups, not repetitions to average.

    Returns
    -------
    ParetoView or None
        None when no run has both an energy and the objective.
    """
    objective = TAN_COLUMN if frame[TAN_COLUMN].notna().any() else INFORMATION_COLUMN
    usable = frame[frame[ENERGY_COLUMN].notna() & frame[objective].notna()].copy()
    if usable.empty:
        return None
    label_key = LABEL_KEY if LABEL_KEY in keys else (keys[0] if keys else None)
    if label_key is None and seeds_are_missions:
        label_key = "seed"
    group_keys = [key for key in keys if key != label_key]
    if seeds_are_missions and label_key != "seed":
        group_keys.append("seed")
    usable["group"] = [
        ", ".join(f"{key}={row[key]}" for key in group_keys) for _, row in usable.iterrows()
    ]
    usable["label"] = usable[label_key] if label_key is not None else ""
    usable["converged"] = usable["status"] == "CONVERGED"
    points = (
        usable.groupby(["group", "label"], sort=False)
        .agg(
            energy_J=(ENERGY_COLUMN, "mean"),
            objective=(objective, "mean"),
            n_runs=(ENERGY_COLUMN, "size"),
            converged=("converged", "all"),
        )
        .reset_index()
        .rename(columns={"objective": objective})
    )
    maximize = objective == INFORMATION_COLUMN
    converged = points[points["converged"]]
    points["on_front"] = False
    for _, members in converged.groupby("group", sort=False):
        points.loc[members.index[_front(members, objective, maximize)], "on_front"] = True
    points["on_overall_front"] = False
    if not seeds_are_missions:
        points.loc[converged.index[_front(converged, objective, maximize)], "on_overall_front"] = (
            True
        )
    _compare_with_reference(
        points, label_key, objective, maximize, same_mission=not seeds_are_missions
    )
    return ParetoView(points, label_key, objective, maximize, not seeds_are_missions)


def trade_off(
    view: ParetoView, *, energy_budget: float = ENERGY_BUDGET, target: float = TARGET_IMPROVEMENT
) -> dict[str, dict[str, Any] | None]:
    """The best trade-offs of converged, non-reference points against the energy-only plan.

    Parameters
    ----------
    view : ParetoView
        From :func:`pareto_view`.
    energy_budget : float
        Largest ``energy_increase`` [-] allowed for ``best_within_budget``.
    target : float
        ``improvement`` [-] that ``cheapest_reaching_target`` must reach.

    Returns
    -------
    dict
        ``best_within_budget``: the point of largest (positive) improvement with
        ``energy_increase <= energy_budget``; ``cheapest_reaching_target``: the point of least
        energy increase with ``improvement >= target``; each a record of the points table, or
        None.

    Examples
    --------
    >>> points = pd.DataFrame({"group": "", "label": [0.0, 1.0, 3.0], "energy_increase":
    ...     [0.0, 0.05, 0.4], "improvement": [0.0, 0.1, 0.35], "converged": True,
    ...     "is_reference": [True, False, False]})
    >>> view = ParetoView(points, "weights.terrain", "tan_rmse_m", False, True)
    >>> {key: value["label"] for key, value in trade_off(view).items()}
    {'best_within_budget': 1.0, 'cheapest_reaching_target': 3.0}
    """
    points = view.points
    candidates = points[
        points["converged"] & ~points["is_reference"] & points["improvement"].notna()
    ]
    within = candidates[
        (candidates["energy_increase"] <= energy_budget) & (candidates["improvement"] > 0.0)
    ]
    reaching = candidates[candidates["improvement"] >= target]
    return {
        "best_within_budget": _record(within, "improvement", largest=True),
        "cheapest_reaching_target": _record(reaching, "energy_increase", largest=False),
    }


def _record(points: pd.DataFrame, column: str, *, largest: bool) -> dict[str, Any] | None:
    """The row of ``points`` with the largest (smallest) ``column`` as a dict, or None."""
    if points.empty:
        return None
    index = points[column].idxmax() if largest else points[column].idxmin()
    return {  # plain Python values (numpy scalars unwrapped), ready for JSON
        str(key): value.item() if isinstance(value, np.generic) else value
        for key, value in points.loc[index].items()
    }


def _front(points: pd.DataFrame, objective: str, maximize: bool) -> BoolArray:
    return non_dominated(
        points[ENERGY_COLUMN].to_numpy(float), points[objective].to_numpy(float), maximize=maximize
    )


def _compare_with_reference(
    points: pd.DataFrame,
    label_key: str | None,
    objective: str,
    maximize: bool,
    *,
    same_mission: bool,
) -> None:
    """Fill ``is_reference``, ``energy_increase`` and ``improvement`` in place (module notes)."""
    points["is_reference"] = (label_key == LABEL_KEY) & (points["label"] == 0.0)
    points["energy_increase"] = np.nan
    points["improvement"] = np.nan
    references = points[points["is_reference"]]
    if references.empty:
        return
    for group, members in points.groupby("group", sort=False):
        own = references[references["group"] == group]
        if own.empty and not same_mission:
            continue
        reference = (own if not own.empty else references).iloc[0]
        energy = members[ENERGY_COLUMN] / reference[ENERGY_COLUMN] - 1.0
        ratio = members[objective] / reference[objective]
        points.loc[members.index, "energy_increase"] = energy
        points.loc[members.index, "improvement"] = ratio - 1.0 if maximize else 1.0 - ratio


__all__ = ["ParetoView", "non_dominated", "pareto_view", "trade_off"]
