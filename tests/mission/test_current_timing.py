"""Stage 2 in a current that changes in time: the time laws use the current when the vehicle
passes, not the current at ``t = 0`` (issue 26)."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pytest

from auvplan.errors import InfeasibleError
from auvplan.io.vehicles import load_vehicle
from auvplan.mission.config import DeconflictionConfig, FleetConfig, parse_mission
from auvplan.mission.current import mean_ground_speed, water_speed_times
from auvplan.mission.fleet import FleetLayout
from auvplan.mission.pipeline import fleet_layout, run_optimization
from auvplan.mission.preplan import run_preplan
from auvplan.mission.still_water import fly_in_current
from auvplan.mission.timing import SPEED_MARGIN, run_deconfliction
from auvplan.ocean import GriddedCurrent
from auvplan.terrain import GridGeometry
from auvplan.terrain.spline import SplineSurface
from auvplan.vehicle import build_vehicle_model, top_speed

#: Eastward current [m/s] before and after it turns; the slices are 60 s apart.
FLOOD, EBB, SLICE_S, TURN_SLICE = 0.3, -0.3, 60.0, 10


def _reversing(slice_s: float = SLICE_S) -> GriddedCurrent:
    """A uniform eastward current of FLOOD that turns to EBB around t = TURN_SLICE · slice_s."""
    geometry = GridGeometry(9, 41, 50.0, 50.0, -200.0, -200.0)
    values = [FLOOD if k < TURN_SLICE else EBB for k in range(3 * TURN_SLICE)]
    zero = SplineSurface.fit(geometry, np.zeros((9, 41)))
    return GriddedCurrent(
        tuple(zero for _ in values),
        tuple(SplineSurface.fit(geometry, np.full((9, 41), v)) for v in values),
        time_step=slice_s,
        start_offset=0.0,
        to_axes=np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
    )


@pytest.fixture(scope="module")
def medusa() -> Any:
    return build_vehicle_model(load_vehicle("medusa"))


def _east_leg(length: float) -> np.ndarray:
    east = np.linspace(100.0, 100.0 + length, 400)
    return np.column_stack([np.full_like(east, 200.0), east])


def _arrival(length: float, water_speed: float, current: GriddedCurrent) -> float:
    """Time [s] to cover ``length`` eastward at ``water_speed`` (Heun's method, 0.5 s steps)."""

    def speed(position: float, time: float) -> float:
        drift = current.velocity(np.array([200.0]), np.array([100.0 + position]), np.array([time]))
        return water_speed + float(drift[1][0])

    position, time, step = 0.0, 0.0, 0.5
    while position < length:
        first = speed(position, time)
        second = speed(position + step * first, time + step)
        covered = 0.5 * step * (first + second)
        if position + covered >= length:
            return time + step * (length - position) / covered
        position, time = position + covered, time + step
    return time


def _stage(medusa: Any, fleet: dict[str, float], path: np.ndarray, current: GriddedCurrent) -> Any:
    return run_deconfliction(
        FleetLayout(names=("blue",), models=(medusa,)),
        (path,),
        np.array([np.pi / 2]),
        np.array([np.pi / 2]),
        fleet=FleetConfig.model_validate({"safety_radius_m": 5.0, **fleet}),
        settings=DeconflictionConfig(),
        dt=1.0,
        current=current,
    )


def test_passage_times_follow_the_turning_current() -> None:
    """At 0.5 m/s through the water the leg is flown at 0.8 m/s before the turn and 0.2 m/s
    after it; the fixed point agrees with a direct integration (the t = 0 current would give
    the whole leg at 0.8 m/s)."""
    current, length = _reversing(), 900.0
    path = _east_leg(length)
    expected = _arrival(length, 0.5, current)
    times = water_speed_times(path, 0.5, current)
    assert times[-1] == pytest.approx(expected, rel=0.01)
    assert length / mean_ground_speed(path, 0.5, current) == pytest.approx(expected, rel=0.01)
    assert expected > 1.3 * length / (0.5 + FLOOD)


def test_cruise_horizon_uses_the_current_when_the_vehicle_passes(medusa: Any) -> None:
    current, length = _reversing(), 900.0
    stage = _stage(medusa, {"cruise_speed": 0.5}, _east_leg(length), current)
    assert stage.horizon == pytest.approx(_arrival(length, 0.5, current), rel=0.03)
    # the reference flies through the water at about the cruise speed on average, not the
    # 0.8 m/s of the flood against the ebb
    surge = stage.desired_states[0][:, 3]
    assert float(np.mean(surge)) == pytest.approx(0.5, abs=0.1)


def test_fixed_horizon_checks_the_ebb_it_meets(medusa: Any) -> None:
    """A horizon that needs the flood's help all the way: feasible at t = 0's current, refused
    once the vehicle meets the ebb later (its top speed cannot hold the ground speed)."""
    current, length = _reversing(), 1800.0
    top = SPEED_MARGIN * top_speed(medusa)
    ground = top + 0.5 * FLOOD  # above top + EBB, below top + FLOOD
    with pytest.raises(InfeasibleError, match="horizon_s"):
        _stage(medusa, {"horizon_s": length / ground}, _east_leg(length), current)
    horizon = float(np.ceil(1.05 * length / (top + EBB)))
    stage = _stage(medusa, {"horizon_s": horizon}, _east_leg(length), current)
    assert stage.horizon == horizon


class _FrozenAtStart:
    """``field`` as a planner that knows only the forecast's first hour would see it: t = 0."""

    def __init__(self, field: GriddedCurrent) -> None:
        self.field = field

    def velocity(self, north: Any, east: Any, time: Any) -> Any:
        return self.field.velocity(north, east, np.zeros_like(np.asarray(time, dtype=float)))

    def gradient(self, north: Any, east: Any, time: Any) -> Any:
        return self.field.gradient(north, east, np.zeros_like(np.asarray(time, dtype=float)))


def test_planning_in_the_changing_current_costs_less_than_the_t0_plan_flown_in_it() -> None:
    """The plan made in the turning current, flown in it with its own regulator, needs no more
    energy than the plan made in the current frozen at t = 0 flown in the same true current
    (and it arrives better: the frozen plan's regulator fights the ebb it did not expect)."""
    config = parse_mission(
        {
            "terrain": {
                "synthetic": True,
                "window": {"north": [0.0, 120.0], "east": [300.0, 500.0]},
            },
            "fleet": {"horizon_s": 240.0, "safety_radius_m": 5.0},
            "vehicle": [
                {
                    "name": "blue",
                    "start": {"north": 60.0, "east": 30.0, "heading_deg": 90.0, "speed": 0.5},
                    "goal": {"north": 60.0, "east": 150.0, "heading_deg": 90.0},
                }
            ],
            "weights": {"terrain": 0.0},
            "solver": {"dt_s": 2.0},
        }
    )
    true = _reversing(slice_s=12.0)  # turns around t = 120 s, half-way
    layout = fleet_layout(config)
    preplan = run_preplan(config)
    flown = []
    for assumed in (true, _FrozenAtStart(true)):
        stage1 = dataclasses.replace(preplan, current=assumed)
        stage2 = run_deconfliction(
            layout, stage1.paths, stage1.starts[:, 2], stage1.goals[:, 2],
            fleet=config.fleet, settings=config.deconfliction, dt=config.solver.dt,
            current=assumed,
        )  # fmt: skip
        plan = run_optimization(config, layout, stage1, stage2, 0.0)
        assert plan.verdict.success, plan.verdict.message
        flown.append(fly_in_current(plan, layout, preplan.goals, config.solver.dt, true))
    knowing, frozen = flown
    assert knowing.energy[0] <= frozen.energy[0]
    assert knowing.arrival_error[0] < frozen.arrival_error[0]
