"""The ocean current through the mission pipeline: config, dynamics, optimiser, energies."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np
import pytest

from auvplan.cli.main import main
from auvplan.errors import InputError
from auvplan.io.vehicles import load_vehicle
from auvplan.mission.config import parse_mission
from auvplan.mission.fleet import current_parameters, vehicle_stage_functions
from auvplan.mission.pipeline import MissionResult, run_mission, run_optimization
from auvplan.ocean import GriddedCurrent, UniformCurrent
from auvplan.terrain import GridGeometry
from auvplan.terrain.spline import SplineSurface
from auvplan.vehicle import build_vehicle_model, electrical_power, reference_states


def _mission(current: dict[str, Any] | None, *, east_goal: float = 150.0) -> dict[str, Any]:
    """One MEDUSA on a short eastward leg over a corner of the synthetic bank."""
    document: dict[str, Any] = {
        "terrain": {"synthetic": True, "window": {"north": [0.0, 120.0], "east": [300.0, 500.0]}},
        "fleet": {"horizon_s": 240.0, "safety_radius_m": 5.0},
        "vehicle": [
            {
                "name": "blue",
                "start": {"north": 60.0, "east": 30.0, "heading_deg": 90.0, "speed": 0.5},
                "goal": {"north": 60.0, "east": east_goal, "heading_deg": 90.0},
            }
        ],
        "weights": {"terrain": 0.0},
        "solver": {"dt_s": 2.0},
    }
    if current is not None:
        document["current"] = current
    return document


@pytest.fixture(scope="module")
def medusa() -> Any:
    return build_vehicle_model(load_vehicle("medusa"))


def test_current_table() -> None:
    config = parse_mission(_mission({"east": 0.2}))
    assert config.current is not None
    assert (config.current.east, config.current.north) == (0.2, None)
    config = parse_mission(_mission({"file": "c.nc"}), base_dir=Path("/data"))
    assert config.current is not None
    assert config.current.file == Path("/data/c.nc")
    for bad, message in (({}, "give a current file"), ({"east": 9.0}, "current.east")):
        with pytest.raises(InputError, match=message):
            parse_mission(_mission(bad))


def test_holding_station_costs_the_power_of_moving_through_water(medusa: Any) -> None:
    """In a 0.4 m/s current, heading into it at 0.4 m/s through the water holds station."""
    trim = reference_states(
        medusa, np.array([[0.0, 0.0, -np.pi / 2]]), np.array([0.4]), np.zeros(1)
    )
    state, inputs = trim[0], np.zeros(medusa.n_u)
    dt, n_steps = 0.1, 600
    step = _rk4(medusa.dynamics_in_current, dt)
    power = []
    for _ in range(n_steps):
        power.append(float(medusa.power(state, inputs)))
        state = step(state, inputs, np.array([0.0, 0.4]))
    assert np.hypot(state[0], state[1]) < 0.3  # held within 0.3 m over 60 s (it would drift 24 m)
    still = electrical_power(trim, np.zeros((1, medusa.n_u)), medusa)[0]
    assert np.mean(power) == pytest.approx(still, rel=1e-3)
    assert (
        still
        > electrical_power(
            reference_states(medusa, np.zeros((1, 3)), np.zeros(1), np.zeros(1)),
            np.zeros((1, medusa.n_u)),
            medusa,
        )[0]
    )  # and more than resting


def _rk4(function: ca.Function, dt: float) -> Any:
    def step(x: np.ndarray, c: np.ndarray, drift: np.ndarray) -> np.ndarray:
        def f(y: np.ndarray) -> np.ndarray:
            return np.asarray(function(y, c, drift)).ravel()

        k1 = f(x)
        k2 = f(x + 0.5 * dt * k1)
        k3 = f(x + 0.5 * dt * k2)
        k4 = f(x + dt * k3)
        return x + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)

    return step


def _eddy() -> GriddedCurrent:
    """A smooth, curved field in the local frame (a Gaussian eddy), one time slice."""
    geometry = GridGeometry(41, 41, 10.0, 10.0)
    north, east = np.meshgrid(geometry.north, geometry.east, indexing="ij")
    bump = 0.3 * np.exp(-((north - 200.0) ** 2 + (east - 200.0) ** 2) / (2 * 80.0**2))
    v_n = bump * (east - 200.0) / 80.0
    v_e = -bump * (north - 200.0) / 80.0
    return GriddedCurrent(
        (SplineSurface.fit(geometry, v_n),),
        (SplineSurface.fit(geometry, v_e),),
        time_step=1.0,
        start_offset=0.0,
        to_axes=np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
    )


def test_stage_dynamics_linearise_the_true_field(medusa: Any, rng: np.random.Generator) -> None:
    """``v_c,k + G_k (p - p_d)`` matches the field to second order in the offset ``p - p_d``."""
    f_water, _ = vehicle_stage_functions(medusa)
    f_current, _ = vehicle_stage_functions(medusa, has_current=True)
    field = _eddy()
    desired = reference_states(
        medusa, np.array([[150.0, 230.0, 0.3]]), np.array([0.5]), np.zeros(1)
    )
    parameters = np.hstack([desired[0], current_parameters(medusa, desired, np.zeros(1), field)[0]])
    direction = rng.normal(size=2)
    errors = []
    for size in (8.0, 4.0, 2.0):
        state = desired[0].copy()
        state[:2] += size * direction / np.linalg.norm(direction)
        drift = np.asarray(f_current(state, np.zeros(2), parameters)).ravel()
        drift -= np.asarray(f_water(state, np.zeros(2), desired[0])).ravel()
        true = np.ravel(field.velocity(state[:1], state[1:2], np.zeros(1)))
        errors.append(np.linalg.norm(drift[:2] - true))
        assert not np.any(drift[2:])  # the current moves the position only
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.15)
    assert errors[1] / errors[2] == pytest.approx(4.0, rel=0.15)


def _plan(current: dict[str, Any] | None, **changes: Any) -> MissionResult:
    result = run_mission(parse_mission(_mission(current, **changes)))
    assert result.plan is not None, result.failure
    return result


def test_zero_current_gives_the_still_water_plan() -> None:
    """A zero ``[current]`` plans exactly as still water; the current's code path with
    ``v_c = 0`` (other compiled kernels, other rounding) agrees to round-off."""
    still, zero = _plan(None), _plan({"east": 0.0, "north": 0.0})
    assert still.plan is not None
    assert zero.plan is not None
    np.testing.assert_array_equal(zero.plan.states, still.plan.states)
    np.testing.assert_array_equal(zero.plan.inputs, still.plan.inputs)
    np.testing.assert_array_equal(zero.plan.energy, still.plan.energy)

    config = still.config
    preplan = dataclasses.replace(still.preplan, current=UniformCurrent(0.0, 0.0))
    assert still.deconfliction is not None
    layout = still.deconfliction.layout
    path = run_optimization(config, layout, preplan, still.deconfliction, 0.0)
    np.testing.assert_allclose(path.states, still.plan.states, rtol=0, atol=1e-5)
    np.testing.assert_allclose(path.energy, still.plan.energy, rtol=1e-9)


def test_downstream_leg_costs_less_than_upstream() -> None:
    downstream, upstream = _plan({"east": 0.15}), _plan({"east": -0.15})
    assert downstream.plan is not None
    assert upstream.plan is not None
    assert downstream.plan.verdict.success
    assert upstream.plan.verdict.success
    assert downstream.plan.energy[0] < 0.9 * upstream.plan.energy[0]
    # the surge through the water is lower downstream, higher upstream than the ground speed
    u = downstream.plan.states[0][:, 3], upstream.plan.states[0][:, 3]
    assert np.mean(u[0]) < 0.5 < np.mean(u[1])


def test_compare_no_current_flies_the_still_water_plan() -> None:
    """On a straight leg of fixed duration the ground track is given, so the still-water plan
    flown with its regulator needs about the energy of the plan that knew the current (the
    regulator supplies the missing thrust) while its own still-water estimate is far off."""
    config = parse_mission(_mission({"east": -0.15}))
    result = run_mission(config, compare_no_current=True)
    comparison = result.current_comparison
    assert comparison is not None
    assert result.plan is not None
    using, still = comparison.using_current, comparison.still_water
    assert using.energy[0] == pytest.approx(result.plan.energy[0], rel=0.01)
    assert still.energy[0] == pytest.approx(using.energy[0], rel=0.03)
    assert comparison.still_water_plan.energy[0] < 0.85 * still.energy[0]
    assert using.arrival_error[0] < 0.2 < still.arrival_error[0]
    assert comparison.saving == pytest.approx(np.sum(still.energy) - np.sum(using.energy))


def test_bad_current_file_exits_2_with_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import tomli_w

    (tmp_path / "currents.nc").write_text("not NetCDF\n")
    mission = tmp_path / "m.toml"
    mission.write_bytes(tomli_w.dumps(_mission({"file": "currents.nc"})).encode())
    code = main(["plan", str(mission), "-o", str(tmp_path / "out"), "--stage", "preplan"])
    err = capsys.readouterr().err
    assert code == 2
    assert len(err.splitlines()) == 1
    assert "currents.nc" in err
    assert "unreadable" in err


def test_independent_checker_flies_the_true_current(tmp_path: Path) -> None:
    """``scenarios.check`` integrates the plan in the mission's current: its defect is tiny,
    and the same plan checked as if in still water is off by the drift."""
    import tomli_w

    from auvplan.scenarios.check import check

    with_current, still = tmp_path / "current.toml", tmp_path / "still.toml"
    with_current.write_bytes(tomli_w.dumps(_mission({"east": -0.15, "north": 0.1})).encode())
    still.write_bytes(tomli_w.dumps(_mission(None)).encode())
    out = tmp_path / "out"
    assert main(["-q", "plan", str(with_current), "-o", str(out), "--no-figures"]) == 0
    report = check(out)
    assert report.passed, report.failures
    assert report.max_position_defect_m["blue"] < 1e-3
    assert check(out, mission=still).max_position_defect_m["blue"] > 0.1


@dataclasses.dataclass(frozen=True)
class _ShearCurrent:
    """Eastward ``speed`` north of ``north_split`` [m], westward south of it (a test field)."""

    speed: float
    north_split: float

    def velocity(
        self, north: np.ndarray, east: np.ndarray, time: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        north = np.asarray(north, dtype=np.float64)
        return np.zeros(north.shape), np.where(north > self.north_split, self.speed, -self.speed)

    def gradient(self, north: np.ndarray, east: np.ndarray, time: np.ndarray) -> np.ndarray:
        return np.zeros((np.size(north), 2, 2))


def test_routes_ride_the_current_round_an_island() -> None:
    """Eastward water north of an island and westward south of it: the eastbound route
    passes north, the westbound one south, each paying U/(U + c) of its still-water cost."""
    from auvplan.mission.current import cell_currents, current_move_factor
    from auvplan.planning import CircleObstacle, EdgeModel, plan_route

    geometry = GridGeometry(21, 41, 10.0, 10.0)
    cost = np.ones(geometry.shape)
    island = (CircleObstacle(100.0, 200.0, 40.0),)
    current, water = _ShearCurrent(0.3, 100.0), 0.6
    factor = current_move_factor(geometry, cell_currents(geometry, current), water)

    def route(start: tuple[float, float], goal: tuple[float, float], **kw: Any) -> Any:
        return plan_route(
            cost, geometry, start, goal, obstacles=island, edge_model=EdgeModel.CROSSED, **kw
        )

    east = route((100.0, 0.0), (100.0, 400.0), move_factor=factor)
    west = route((100.0, 400.0), (100.0, 0.0), move_factor=factor)
    assert np.all(east.points[1:-1, 0] >= 100.0)
    assert np.all(west.points[1:-1, 0] <= 100.0)
    still_east = route((100.0, 0.0), (100.0, 400.0))
    # along the straight east-west stretches the move costs U / (U + c) = 2/3 of still water
    assert east.cost < still_east.cost * 0.8
    # a westward move north of the island goes against the current: U / (U - c) = 2
    np.testing.assert_allclose(factor[3][15, 5], water / (water - 0.3))  # westward, north half
