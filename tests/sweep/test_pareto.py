"""The non-dominated front (against a loop oracle), the trade-off points and the figure."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from auvplan.sweep import (
    TAN_COLUMN,
    RunRecord,
    non_dominated,
    pareto_view,
    sweep_frame,
    trade_off,
)
from auvplan.viz.sweep import plot_pareto


def _dominated_by_loop(energy: np.ndarray, objective: np.ndarray, maximize: bool) -> list[bool]:
    sign = 1.0 if maximize else -1.0
    front = []
    for i in range(len(energy)):
        beaten = any(
            energy[j] <= energy[i]
            and sign * objective[j] >= sign * objective[i]
            and (energy[j] < energy[i] or sign * objective[j] > sign * objective[i])
            for j in range(len(energy))
        )
        front.append(not beaten)
    return front


@pytest.mark.parametrize("maximize", [True, False])
def test_non_dominated_matches_loop(rng: np.random.Generator, maximize: bool) -> None:
    for _ in range(20):
        n = int(rng.integers(1, 30))
        energy = rng.integers(0, 8, n).astype(float)  # ties on purpose
        objective = rng.integers(0, 8, n).astype(float)
        expected = _dominated_by_loop(energy, objective, maximize)
        assert non_dominated(energy, objective, maximize=maximize).tolist() == expected


def _record(weight: float, seed: int, energy: float, info: float, status: str = "CONVERGED"):
    return RunRecord(
        f"w{weight}s{seed}", {"weights.terrain": weight}, seed, status,
        energy=energy, terrain_information=info, folder=None,
    )  # fmt: skip


def test_points_average_mission_seeds_and_rank_converged_only() -> None:
    records = [
        _record(0.0, 0, 100.0, 0.40),
        _record(0.0, 1, 102.0, 0.42),
        _record(1.0, 0, 120.0, 0.60),
        _record(1.0, 1, 120.0, 0.60),
        _record(3.0, 0, 130.0, 0.55),  # dominated by weight 1
        _record(9.0, 0, 90.0, 0.90, status="NOT_CONVERGED"),  # would dominate everything
    ]
    frame = sweep_frame(records, ["weights.terrain"])
    view = pareto_view(frame, ["weights.terrain"], seeds_are_missions=False)
    assert view is not None
    assert view.objective == "terrain_information"
    assert view.maximize
    points = view.points.set_index("label")
    assert points.loc[0.0, "energy_J"] == pytest.approx(101.0)
    assert points.loc[0.0, "n_runs"] == 2
    assert points["on_front"].to_dict() == {0.0: True, 1.0: True, 3.0: False, 9.0: False}
    figure = plot_pareto(view)
    assert isinstance(figure, Figure)
    assert figure.axes[0].get_xlabel() == "fleet energy [kJ]"
    # 4 points, and the star on the energy-only one
    assert sum(len(c.get_offsets()) for c in figure.axes[0].collections) == 5


def test_filled_tan_column_switches_objective_and_scenarios_group_by_seed() -> None:
    records = [_record(w, s, 100.0 + 10 * w + s, 0.5) for s in (0, 1) for w in (0.0, 1.0)]
    frame = sweep_frame(records, ["weights.terrain"])
    frame[TAN_COLUMN] = [20.0, 12.0, 25.0, 25.0]
    view = pareto_view(frame, ["weights.terrain"], seeds_are_missions=True)
    assert view is not None
    assert view.objective == TAN_COLUMN
    assert not view.maximize
    assert sorted(set(view.points["group"])) == ["seed=0", "seed=1"]
    fronts = view.points.groupby("group")["on_front"].sum().to_dict()
    assert fronts == {"seed=0": 2, "seed=1": 1}  # seed 1: weight 1 costs more, no better
    axes = plot_pareto(view).axes[0]
    assert "[%]" in axes.get_xlabel()  # different missions: energy relative to each one's least
    assert axes.get_ylabel().startswith("TAN position RMSE [m]")


def test_no_points_without_energy() -> None:
    frame = sweep_frame(
        [RunRecord("a", {"weights.terrain": 1.0}, None, "PREPLANNED")], ["weights.terrain"]
    )
    assert pareto_view(frame, ["weights.terrain"], seeds_are_missions=False) is None
    assert isinstance(frame, pd.DataFrame)


def test_overall_front_matches_loop_and_points_compare_with_energy_only(
    rng: np.random.Generator,
) -> None:
    weights, informations = (0.0, 0.5, 1.0, 3.0), (0.0, 30.0)
    records = [
        RunRecord(
            f"w{w}i{i}",
            {"weights.terrain": w, "weights.information": i},
            None,
            "CONVERGED",
            energy=100.0 if w == 0.0 else float(rng.uniform(100.0, 130.0)),
            terrain_information=0.5,
            folder=None,
        )
        for i in informations
        for w in weights
    ]
    keys = ["weights.terrain", "weights.information"]
    frame = sweep_frame(records, keys)
    frame[TAN_COLUMN] = [
        4.0 if w == 0.0 else rng.uniform(2.5, 4.5) for _ in informations for w in weights
    ]
    view = pareto_view(frame, keys, seeds_are_missions=False)
    assert view is not None
    points = view.points
    expected = _dominated_by_loop(
        points["energy_J"].to_numpy(), points[TAN_COLUMN].to_numpy(), maximize=False
    )
    assert points["on_overall_front"].tolist() == expected
    assert points["is_reference"].tolist() == [w == 0.0 for _ in informations for w in weights]
    np.testing.assert_allclose(points["energy_increase"], points["energy_J"] / 100.0 - 1.0)
    np.testing.assert_allclose(points["improvement"], 1.0 - points[TAN_COLUMN] / 4.0)
    best = trade_off(view, energy_budget=0.15, target=0.2)
    candidates = points[~points["is_reference"]]
    within = candidates[(candidates["energy_increase"] <= 0.15) & (candidates["improvement"] > 0)]
    reaching = candidates[candidates["improvement"] >= 0.2]
    for name, chosen, column, pick in (
        ("best_within_budget", within, "improvement", max),
        ("cheapest_reaching_target", reaching, "energy_increase", min),
    ):
        if chosen.empty:
            assert best[name] is None
        else:
            assert best[name] is not None
            assert best[name][column] == pick(chosen[column])
    axes = plot_pareto(view).axes[0]
    assert "energy-only plan (terrain weight 0)" in axes.get_legend_handles_labels()[1]


def test_no_reference_without_a_zero_terrain_weight() -> None:
    frame = sweep_frame(
        [_record(1.0, 0, 120.0, 0.6), _record(3.0, 0, 130.0, 0.7)], ["weights.terrain"]
    )
    view = pareto_view(frame, ["weights.terrain"], seeds_are_missions=False)
    assert view is not None
    assert not view.points["is_reference"].any()
    assert view.points["improvement"].isna().all()
    assert trade_off(view) == {"best_within_budget": None, "cheapest_reaching_target": None}
