"""The energy / navigation trade-off of a sweep: points and their non-dominated front.

Each point is one setting of the varied keys: its fleet energy [J] against the navigation
objective, ``terrain_information`` (mean information, higher is better) or, once a navigation
evaluation filled it, ``tan_rmse_m`` (TAN position RMSE [m], lower is better). Points are
labelled by ``weights.terrain`` when it is swept (else by the first varied key) and grouped by
the other varied keys (and by the seed when each seed is its own mission, the scenario
family); runs that differ only in a mission file's seed are averaged. The front is taken per
group among plans that CONVERGED (others are drawn, not ranked).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np
import pandas as pd

from auvplan._typing import BoolArray, FloatArray
from auvplan.sweep.table import TAN_COLUMN

#: The key whose values label the points when it is swept.
LABEL_KEY: Final = "weights.terrain"
INFORMATION_COLUMN: Final = "terrain_information"
ENERGY_COLUMN: Final = "energy_J"


@dataclass(frozen=True)
class ParetoView:
    """The points of a sweep's trade-off.

    ``points`` has the columns ``group`` (text naming the other varied values, ``""`` for a
    single group), ``label`` (the value of ``label_key``), ``energy_J``, the ``objective``
    column, ``n_runs`` (runs averaged), ``converged`` and ``on_front``. ``same_mission`` is
    False when groups are different missions (the scenario family), whose energies do not
    compare.
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
    points["on_front"] = False
    for _, members in points[points["converged"]].groupby("group", sort=False):
        front = non_dominated(
            members[ENERGY_COLUMN].to_numpy(float),
            members[objective].to_numpy(float),
            maximize=maximize,
        )
        points.loc[members.index[front], "on_front"] = True
    return ParetoView(points, label_key, objective, maximize, not seeds_are_missions)


__all__ = ["ParetoView", "non_dominated", "pareto_view"]
