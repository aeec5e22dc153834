"""The decomposed fleet solve (issue 27): vehicle by vehicle against the others' plans.

Four MEDUSAs cross in a 60 m square (two pairs 20 m apart on parallel lanes, a comm range
between two of them), so separations are active and every vehicle is every other's
neighbour: the vehicle-by-vehicle solve must reach the coupled Newton solve's optimum, keep
every constraint between samples, and be a fixed point of its own sweeps.
"""

from __future__ import annotations

import dataclasses
import tomllib
from typing import Any

import numpy as np
import pytest

from auvplan.errors import InputError
from auvplan.mission import pipeline
from auvplan.mission.assembly import AssembledProblem, assemble_problem, check_optimizer_memory
from auvplan.mission.config import MissionConfig, parse_mission
from auvplan.mission.decomposition import _Helper, _nearest_within, solve_decomposed
from auvplan.mission.fleet import FleetLayout
from auvplan.mission.models import vehicle_model
from auvplan.mission.pipeline import Stage
from auvplan.mission.preplan import PreplanStage
from auvplan.optimization import ProntoStatus, Trajectory


def _mission(
    horizon_s: float, length: float, lanes: list[tuple[str, float, float, float]], extra: str = ""
) -> str:
    """A mission of MEDUSAs on straight lanes: ``(name, north, east, heading_deg)`` starts at
    0.5 m/s, each going ``length`` [m] along its heading; ``extra`` TOML after them."""
    vehicles = "".join(
        f'[[vehicle]]\nname = "{name}"\n'
        f"start = {{ north = {north}, east = {east}, heading_deg = {heading}, speed = 0.5 }}\n"
        f"goal = {{ north = {north + length * np.cos(np.radians(heading)):g}, "
        f"east = {east + length * np.sin(np.radians(heading)):g}, heading_deg = {heading} }}\n"
        for name, north, east, heading in lanes
    )
    return (
        f"[terrain]\nsynthetic = true\n[fleet]\nhorizon_s = {horizon_s}\n"
        f"safety_radius_m = 5.0\n{vehicles}{extra}[solver]\ndt_s = 1.0\n"
    )


CROSSING = _mission(
    240.0,
    100.0,
    [("a", 150.0, 400.0, 0.0), ("b", 200.0, 350.0, 90.0), ("c", 150.0, 420.0, 0.0),
     ("d", 220.0, 350.0, 90.0)],
    '[[comm]]\npair = ["a", "d"]\nmax_range_m = 90.0\n',
)  # fmt: skip


def _config(text: str, fleet: str) -> MissionConfig:
    return parse_mission(tomllib.loads(text + f'fleet = "{fleet}"\n'))


def _assembled(
    config: MissionConfig, run: pipeline.MissionResult
) -> tuple[AssembledProblem, PreplanStage]:
    """The stage-3 problem of a run's stages 1 and 2, for the decomposed solve."""
    assert run.deconfliction is not None
    assembled = assemble_problem(
        pipeline.fleet_layout(config), run.preplan, run.deconfliction, weights=config.weights,
        terrain_weight=config.weights.terrain, safety_radius=config.fleet.safety_radius,
        comms=config.comms, decomposed=True,
    )  # fmt: skip
    return assembled, run.preplan


@pytest.fixture(scope="module")
def planned() -> dict[str, pipeline.MissionResult]:
    return {
        mode: pipeline.run_mission(_config(CROSSING, mode)) for mode in ("coupled", "decomposed")
    }


def test_the_decomposed_plan_reaches_the_coupled_optimum(
    planned: dict[str, pipeline.MissionResult],
) -> None:
    coupled, decomposed = planned["coupled"].plan, planned["decomposed"].plan
    assert coupled is not None
    assert decomposed is not None
    for plan in (coupled, decomposed):
        assert plan.result.status is ProntoStatus.CONVERGED
        assert plan.verdict.success, plan.verdict.message  # every constraint between samples
    assert decomposed.result.message.startswith("converged vehicle by vehicle")
    assert (coupled.fleet_solve, decomposed.fleet_solve) == ("coupled", "decomposed")
    # each vehicle optimal given the others: Newton's optimum on the whole fleet (46,195.8 J)
    # up to the best-response gap, 2.6e-4 here where every separation is active
    objective = {
        name: plan.result.running_cost + plan.result.terminal_cost
        for name, plan in (("coupled", coupled), ("decomposed", decomposed))
    }
    assert objective["decomposed"] == pytest.approx(objective["coupled"], rel=1e-3)
    # the active separations: both plans fly the pairs within 5 % of 2 r_c + margin
    closest = [min(d.values()) for d in decomposed.separations.values()]
    assert 10.0 <= min(closest) < 10.5


def test_the_decomposed_plan_is_a_fixed_point_of_its_sweeps(
    planned: dict[str, pipeline.MissionResult],
) -> None:
    """From its own plan at the last barrier level, no vehicle's problem takes a step."""
    result = planned["decomposed"]
    assert result.plan is not None
    config = _config(CROSSING, "decomposed")
    assembled, preplan = _assembled(config, result)
    solved = result.plan.result
    options = config.solver.pronto_options()
    options = dataclasses.replace(
        options, eps_initial=options.eps_final, delta_initial=solved.delta
    )
    again = solve_decomposed(
        dataclasses.replace(assembled, guess=solved.trajectory), preplan, options
    )
    assert again.status is ProntoStatus.CONVERGED
    assert again.n_iter == 0
    assert len(again.history) == 4  # one convergence check each, one sweep
    np.testing.assert_array_equal(again.trajectory.states, solved.trajectory.states)


GROUPS = _mission(
    200.0,
    80.0,
    [("a", 150.0, 100.0, 0.0), ("b", 190.0, 60.0, 90.0), ("c", 150.0, 600.0, 0.0),
     ("d", 190.0, 560.0, 90.0)],
)  # fmt: skip


@pytest.fixture(scope="module")
def groups() -> tuple[MissionConfig, AssembledProblem, PreplanStage]:
    """Two crossings 500 m apart, through stage 2, and their stage-3 problem."""
    config = _config(GROUPS, "decomposed")
    return (config, *_assembled(config, pipeline.run_mission(config, stage=Stage.DECONFLICT)))


def test_two_processes_solve_vehicles_that_share_no_term_side_by_side(
    groups: tuple[MissionConfig, AssembledProblem, PreplanStage], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Two crossings 500 m apart: the second process takes the far group's vehicles, and
    the plan is the one a single process makes, to the last bit."""
    config, assembled, preplan = groups
    options = config.solver.pronto_options()
    submitted: list[int] = []
    submit = _Helper.submit

    def spy(self: _Helper, vehicle: Any, *args: Any) -> None:
        submitted.append(vehicle.index)
        submit(self, vehicle, *args)

    monkeypatch.setattr(_Helper, "submit", spy)
    one = solve_decomposed(assembled, preplan, options, jobs=1)
    two = solve_decomposed(assembled, preplan, options, jobs=2)
    assert submitted[:2] == [2, 3]  # a beside c, then b beside d
    for result in (one, two):
        assert result.status is ProntoStatus.CONVERGED
    np.testing.assert_array_equal(one.trajectory.states, two.trajectory.states)
    np.testing.assert_array_equal(one.regulator_gains, two.regulator_gains)
    assert one.cost == two.cost


def test_a_stop_from_the_callback_ends_the_solve_with_max_iter(
    groups: tuple[MissionConfig, AssembledProblem, PreplanStage],
) -> None:
    config, assembled, preplan = groups

    def stop(_record: object) -> None:
        raise StopIteration

    result = solve_decomposed(assembled, preplan, config.solver.pronto_options(), callback=stop)
    assert result.status is ProntoStatus.MAX_ITER
    assert result.message == "stopped by the callback"
    assert isinstance(result.trajectory, Trajectory)


def test_neighbours_are_ranked_by_distance_within_the_reach_only() -> None:
    # vehicle 0 at the origin; 1 passes 30 m away at stage 1; 2 stays 100 m away; 3 at 10 m
    where = np.zeros((4, 4, 2))
    where[1, :, 1] = [90.0, 30.0, 60.0, 90.0]
    where[2, :, 1] = 100.0
    where[3, :, 0] = 10.0
    others, rank = _nearest_within(where, 0, reach=50.0)
    np.testing.assert_array_equal(others, [1, 2, 3])
    np.testing.assert_array_equal(
        rank, [[np.inf, np.inf, 0.0], [1.0, np.inf, 0.0], [np.inf, np.inf, 0.0]]
    )  # the last node (stage N) is no stage: its parameters are stage N-1's


def test_auto_decomposes_from_eight_vehicles_and_the_memory_check_follows() -> None:
    config = _config(CROSSING, "auto")
    assert not config.solver.decomposes(7)
    assert config.solver.decomposes(8)
    assert not _config(CROSSING, "coupled").solver.decomposes(32)
    assert _config(CROSSING, "decomposed").solver.decomposes(2)
    with pytest.raises(InputError, match=r"solver\.fleet"):
        _config(CROSSING, "jacobi")
    medusa = vehicle_model("medusa", 3)
    fleet = FleetLayout(tuple(f"v{i}" for i in range(32)), (medusa,) * 32)
    with pytest.raises(InputError, match="GiB"):
        check_optimizer_memory(fleet, 3600)  # 32 coupled MEDUSAs x 1 h at 1 s: ~47 GiB
    check_optimizer_memory(fleet, 3600, decomposed=True)  # one vehicle at a time


def test_a_vehicle_whose_problem_fails_names_itself_in_the_fleet_status(
    groups: tuple[MissionConfig, AssembledProblem, PreplanStage],
) -> None:
    config, assembled, preplan = groups
    options = dataclasses.replace(config.solver.pronto_options(), max_iter=2)
    result = solve_decomposed(assembled, preplan, options)
    assert result.status is ProntoStatus.MAX_ITER
    assert result.message == "a: reached max_iter = 2"
    assert result.min_slack > 0.0  # the best plan, whole and flyable: every vehicle projected
    np.testing.assert_array_equal(result.trajectory.states[0], assembled.problem.initial_state)


def test_jobs_run_a_coupled_solve_on_threads_and_a_decomposed_one_on_processes(
    planned: dict[str, pipeline.MissionResult], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``jobs = 2``: the coupled solve evaluates its stages on two threads, to the same plan
    to the bit; beside a decomposed solve's second process each solve keeps one thread."""
    threads: list[int] = []
    for name in ("solve_pronto", "solve_decomposed"):
        solver = getattr(pipeline, name)

        def spy(*args: Any, _solver: Any = solver, **kwargs: Any) -> Any:
            options = kwargs["options"] if "options" in kwargs else args[2]
            threads.append(options.n_threads)
            return _solver(*args, **kwargs)

        monkeypatch.setattr(pipeline, name, spy)
    coupled = pipeline.run_mission(_config(CROSSING, "coupled"), jobs=2)
    assert threads == [2]
    assert coupled.plan is not None
    assert planned["coupled"].plan is not None
    for ours, theirs in zip(coupled.plan.states, planned["coupled"].plan.states, strict=True):
        np.testing.assert_array_equal(ours, theirs)
    decomposed = pipeline.run_mission(_config(CROSSING, "decomposed"), jobs=2)
    assert threads == [2, 1]
    assert decomposed.plan is not None
