"""Replanning (issue 27): the rest of the golden mission's plan from t = 60 s.

The golden mission's two MEDUSAs cross with a certified separation of 10.06 m for 10 m
required, so blue 30 m off its plan keeps the old schedule ahead of it or west of it and
needs it deconflicted anew east of it (towards green); each must give a plan that converges
and meets every constraint.
"""

from __future__ import annotations

from datetime import timedelta
from typing import Any

import numpy as np
import pytest

from auvplan.deconfliction import timed_positions
from auvplan.errors import InputError
from auvplan.mission.assembly import WarmStart, assemble_problem
from auvplan.mission.costs import cost_breakdown
from auvplan.mission.parent import ParentPlan, parent_from_result
from auvplan.mission.remainder import fade_factors, shift_schedule
from auvplan.mission.replan import replan_mission, replan_step
from auvplan.mission.states import given_states
from auvplan.mission.timing import SPEED_MARGIN
from auvplan.optimization import Trajectory
from auvplan.vehicle import top_speed

AT = 60.0


@pytest.fixture(scope="module")
def parent(golden_solved: tuple[Any, Any, Any]) -> ParentPlan:
    return parent_from_result(golden_solved[1], digest=None)


def _step(parent: ParentPlan) -> int:
    return round(AT / parent.deconfliction.dt)


def _moved(parent: ParentPlan, north: float, east: float) -> dict[str, Any]:
    """Vehicle ``blue``'s state of the plan at ``AT``, moved by ``north, east`` [m]."""
    x = parent.states[0][_step(parent)]
    state = {"north": x[0] + north, "east": x[1] + east, "heading_deg": np.degrees(x[2])}
    return {"blue": {**{key: float(value) for key, value in state.items()}, "speed": float(x[3])}}


def test_replan_with_the_plans_own_states_is_the_rest_of_the_plan(parent: ParentPlan) -> None:
    """Bellman: the tail of an optimal plan is optimal for the tail problem."""
    replanned = replan_mission(parent, AT, {})
    result, step = replanned.result, _step(parent)
    assert replanned.origin.schedule == "kept"
    assert result.problem is None
    assert result.plan is not None
    assert result.deconfliction is not None
    assert result.deconfliction.horizon == pytest.approx(parent.deconfliction.horizon - AT)
    for i, states in enumerate(result.plan.states):
        np.testing.assert_array_equal(states[0], parent.states[i][step])  # the full state
        assert np.max(np.abs(states[:, :2] - parent.states[i][step:, :2])) < 0.05  # [m]
    stage2 = result.deconfliction
    tail = Trajectory(
        stage2.layout.stack([x[step:] for x in parent.states]),
        stage2.layout.stack([u[step:] for u in parent.inputs]),
    )
    config = result.config
    assembled = assemble_problem(
        stage2.layout, result.preplan, stage2, weights=config.weights,
        terrain_weight=config.weights.terrain, safety_radius=config.fleet.safety_radius,
        comms=config.comms, warm_start=WarmStart(tail.states[0]),
    )  # fmt: skip
    old = cost_breakdown(assembled.problem, assembled.functions, tail).total
    new = result.plan.costs.total
    assert abs(new - old) <= 5e-3 * abs(old)
    start = parent.config.mission.start_time + timedelta(seconds=AT)
    assert result.config.mission.start_time == start


def test_a_replan_on_two_cores_is_the_one_core_replan_to_the_bit(parent: ParentPlan) -> None:
    states = given_states(_moved(parent, 30.0, 0.0), parent.deconfliction.layout.names)
    one, two = (replan_mission(parent, AT, states, jobs=jobs).result.plan for jobs in (1, 2))
    assert one is not None
    assert two is not None
    assert two.result.status.name == "CONVERGED"
    for ours, theirs in zip(two.states, one.states, strict=True):
        np.testing.assert_array_equal(ours, theirs)


@pytest.mark.parametrize(
    ("north", "east", "schedule"),
    [(30.0, 0.0, "kept"), (0.0, -30.0, "kept"), (0.0, 30.0, "deconflicted")],
    ids=["ahead", "west", "east"],
)
def test_a_vehicle_30_m_off_gets_a_plan_that_meets_every_constraint(
    parent: ParentPlan, north: float, east: float, schedule: str
) -> None:
    states = given_states(_moved(parent, north, east), parent.deconfliction.layout.names)
    replanned = replan_mission(parent, AT, states)
    result = replanned.result
    assert replanned.origin.schedule == schedule
    assert result.problem is None  # CONVERGED, every constraint met between samples
    assert result.plan is not None
    assert result.plan.verdict.status.name == "CONVERGED"
    levels = result.config.solver.pronto_options().epsilon_levels()
    first = levels[-2] if schedule == "kept" else levels[0]  # the old plan re-centred one level up
    assert result.plan.result.history[0].epsilon == pytest.approx(first)
    wanted = parent.states[0][_step(parent), :2] + [north, east]
    np.testing.assert_allclose(result.plan.states[0][0, :2], wanted, atol=1e-9)
    separation = 2.0 * result.config.fleet.safety_radius
    assert result.plan.separations["blue"]["green"] >= separation
    np.testing.assert_allclose(
        [x[-1, :2] for x in result.plan.states], result.preplan.goals[:, :2], atol=1.0
    )


def test_the_shifted_schedule_is_the_old_one_from_the_new_start(parent: ParentPlan) -> None:
    stage2 = parent.deconfliction
    limits = np.array([SPEED_MARGIN * top_speed(model) for model in stage2.layout.models])
    deviations = np.array([[0.0, 30.0], [0.0, 0.0]])
    rest = shift_schedule(
        stage2.problem, stage2.coordination, at=AT, horizon=stage2.horizon,
        deviations=deviations, speed_limits=limits,
    )  # fmt: skip
    time = rest.schedule.time
    assert time[0] == 0.0
    assert time[-1] == pytest.approx(stage2.horizon - AT)
    assert np.all(np.diff(rest.schedule.progress, axis=1) >= -1e-12)
    new = timed_positions(rest.schedule, rest.problem, time)
    old = timed_positions(stage2.coordination, stage2.problem, time + AT)
    offsets = fade_factors(time, rest.fade_times)[:, :, None] * rest.deviations[:, None, :]
    np.testing.assert_allclose(new - old, offsets, atol=1e-6)
    np.testing.assert_allclose(new[0, 0] - old[0, 0], deviations[0], atol=1e-9)
    faded = time >= rest.fade_times[0]
    assert 0.0 < rest.fade_times[0] <= time[-1]
    np.testing.assert_allclose(new[:, faded], old[:, faded], atol=1e-6)
    speeds = np.diff(rest.schedule.progress, axis=1) / np.diff(time)
    assert np.all(speeds <= limits[:, None] * 1.0001 + 1e-9)
    kept = shift_schedule(
        stage2.problem, stage2.coordination, at=AT, horizon=stage2.horizon,
        deviations=np.zeros((2, 2)), speed_limits=limits,
    )  # fmt: skip
    assert kept.schedule.certificate.min_separation >= stage2.coordination.min_separation - 1e-9
    assert not rest.schedule.success  # 30 m east, blue comes within 9 m of green


def test_a_vehicle_that_cannot_make_it_is_named(parent: ParentPlan) -> None:
    far = {"blue": {"north": 390.0, "east": 10.0, "heading_deg": 0.0, "speed": 0.5}}
    result = replan_mission(parent, 140.0, given_states(far, ("blue", "green"))).result
    assert result.plan is None
    assert result.problem is not None
    assert result.problem.startswith("plan FAILED: vehicle blue can no longer reach its goal")


@pytest.mark.parametrize(
    ("at", "message"),
    [
        (0.0, "strictly between 0 and the horizon"),
        (-5.0, "strictly between 0 and the horizon"),
        (150.0, "strictly between 0 and the horizon"),
        (float("nan"), "strictly between 0 and the horizon"),
        (60.2, "not a multiple of the plan's solver.dt_s"),
    ],
)
def test_a_replanning_time_outside_the_plan_is_refused(at: float, message: str) -> None:
    with pytest.raises(InputError, match=message):
        replan_step(at, 150.0, 0.5)


def test_a_state_faster_than_the_vehicle_is_refused(parent: ParentPlan) -> None:
    states = _moved(parent, 0.0, 0.0)
    states["blue"]["speed"] = 5.0
    with pytest.raises(InputError, match="exceeds its top speed"):
        replan_mission(parent, AT, given_states(states, ("blue", "green")))
