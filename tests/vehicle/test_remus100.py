"""The REMUS 100-class vehicle: its file against Fossen's model, derivatives, steady states.

Source values (``_remus_oracle``): Fossen's PythonVehicleSimulator ``remus100.py`` states "The
maximum speed of 2.5 m/s is obtained when the propeller runs at 1525 rpm"; no source found
states a REMUS 100 turning radius, so the turning radius is checked against Fossen's own
equations (transcribed independently in ``_remus_oracle``).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import _remus_oracle as fossen
import numpy as np
import pytest
from _derivatives import check_derivatives

from auvplan.cli.main import main
from auvplan.io.vehicles import load_vehicle
from auvplan.vehicle import (
    ActuatedVehicleParams,
    VehicleModel,
    build_vehicle_model,
    energy_per_metre,
    max_yaw_rate,
    optimal_cruise_speed,
    regulator_floor,
    rk4_simulate,
    stable_rk4_step,
    steady_motion,
    tightest_turn,
    top_speed,
    trim_surge,
)
from auvplan.vehicle.operating import operating_state
from auvplan.vehicle.simulate import rk4_step_function


@pytest.fixture(scope="module")
def model() -> VehicleModel:
    return build_vehicle_model(load_vehicle("remus100"))


def test_file_holds_fossens_numbers(model: VehicleModel) -> None:
    vehicle = model.vehicle
    assert isinstance(vehicle, ActuatedVehicleParams)
    hull = vehicle.hull
    # hull from the spheroid formulas (Fossen 2021 sec. 8.4.2), rounded to 4 digits in the file
    assert hull.m == pytest.approx(fossen.MASS, rel=2e-4)
    assert hull.I_z == pytest.approx(fossen.I_Z, rel=2e-4)
    assert hull.m_u == pytest.approx(fossen.M[0], rel=2e-4)
    assert hull.m_v == pytest.approx(fossen.M[1], rel=2e-4)
    assert hull.m_r == pytest.approx(fossen.M[2], rel=2e-4)
    assert (hull.X_u, hull.Y_v, hull.N_r) == pytest.approx(
        (-fossen.M[0] / 20, -fossen.M[1] / 20, -fossen.M[2] / 1), rel=2e-4
    )
    assert hull.X_uu == pytest.approx(-0.5 * fossen.RHO * fossen.PLANFORM * fossen.CD_0, rel=2e-4)
    assert hull.crossflow is not None
    assert hull.crossflow.drag_coefficient == pytest.approx(fossen.HOERNER, rel=1e-3)
    assert not hull.added_mass_coriolis
    (thruster,) = vehicle.thrusters
    assert thruster.n_max == pytest.approx(fossen.N_MAX_RPM / 60)
    (rudder,) = vehicle.surfaces
    assert rudder.area == pytest.approx(fossen.RUDDER_AREA)
    assert rudder.delta_max == pytest.approx(fossen.DELTA_MAX)
    assert model.state_names == ("north", "east", "psi", "u", "v", "r", "n_prop", "delta_rudder")
    assert model.input_names == ("c_prop", "c_rudder")
    assert (model.thruster_states, model.surface_states) == (("n_prop",), ("delta_rudder",))
    assert model.state_units == ("m", "m", "rad", "m/s", "m/s", "rad/s", "rev/s", "rad")
    assert model.state_limits == (
        ("n_prop", pytest.approx(25.4167, rel=1e-4)),
        ("delta_rudder", pytest.approx(math.radians(15))),
    )


def _points(rng: np.random.Generator) -> list[tuple[str, np.ndarray, np.ndarray]]:
    points = []
    for label, sign_u, sign_n in (
        ("ahead", 1, 1), ("crash-back", 1, -1), ("backing", -1, -1), ("crash-ahead", -1, 1)
    ):  # fmt: skip
        for _ in range(2):
            state = np.array(
                [
                    *rng.uniform(-50, 50, 2),
                    rng.uniform(-np.pi, np.pi),
                    sign_u * rng.uniform(0.3, 2.5),
                    rng.uniform(-0.3, 0.3),
                    rng.uniform(-0.3, 0.3),
                    sign_n * rng.uniform(1.0, 25.0),
                    rng.uniform(-0.26, 0.26),
                ]
            )
            points.append((label, state, rng.uniform(-2, 2, 2)))
    points.append(("rest", np.zeros(8), np.zeros(2)))
    points.append(("near rest", np.r_[0, 0, 0.3, 1e-3, -1e-3, 2e-3, 1e-2, 0.1], np.ones(2)))
    return points


def test_dynamics_power_and_rk4_derivatives_match_finite_differences(
    model: VehicleModel, rng: np.random.Generator
) -> None:
    points = _points(rng)
    check_derivatives(model.dynamics, points, rng)
    check_derivatives(model.power, points, rng)
    check_derivatives(rk4_step_function(model, 0.5), points, rng)


def test_model_matches_fossens_equations(model: VehicleModel, rng: np.random.Generator) -> None:
    """Ahead motion with the rudder anywhere in its range: the file's model is Fossen's.

    The file's simplifications (|u| u drag, 0.944 u advance) differ by O(v²/u²).
    """
    for _ in range(20):
        u = rng.uniform(0.5, 2.5)
        v, r = rng.uniform(-0.05, 0.05) * u, rng.uniform(-0.3, 0.3)
        n, delta = rng.uniform(3.0, 25.4), rng.uniform(-0.26, 0.26)
        state = np.array([0, 0, 0, u, v, r, n, delta])
        got = np.asarray(model.dynamics(state, [0, 0])).ravel()[3:6]
        expected = fossen.nu_dot(u, v, r, delta, 60 * n)
        scale = np.array([0.05 * u**2, 0.05 * u**2, 0.05 * u**2])  # ~ drag / mass [m/s²]
        np.testing.assert_allclose(got, expected, atol=0.02 * scale.max(), rtol=0.01)


def test_steady_surge_is_a_thrust_drag_balance(model: VehicleModel) -> None:
    """At the trim, (1 - t) T equals the hull drag computed from the file's coefficients."""
    hull = model.vehicle.hull
    (thruster,) = model.vehicle.thrusters
    for speed in (0.5, 1.0, 1.5, 2.0):
        n, _ = trim_surge(model, speed)
        state = operating_state(model, u=speed, throttle=n)
        thrust = float(model.thrust_torque(state)[0])
        drag = -hull.X_uu * speed**2 - hull.X_u * math.exp(-3.0 * speed) * speed
        # equal up to the smoothing |u| = sqrt(u² + ε²), ε = 0.01 m/s: ε²/(2u²) <= 2e-4
        assert (1 - thruster.thrust_deduction) * thrust == pytest.approx(drag, rel=3e-4)
        # and the propeller law itself: T = rho D^4 (K_T0 n^2 + K_T' (0.944 u / D) n)
        prop = thruster.propeller
        k_t = 0.4566 * n**2 + (0.1798 - 0.4566) / 0.6632 * 0.944 * speed / 0.14 * n
        assert thrust == pytest.approx(1026 * 0.14**4 * k_t, rel=1e-3)
        assert prop.diameter == 0.14


def test_top_speed_is_the_stated_one(model: VehicleModel) -> None:
    speed = top_speed(model)
    assert speed == pytest.approx(fossen.STATED_TOP_SPEED, rel=0.05)  # 2.5 m/s at 1525 rpm
    assert speed == pytest.approx(fossen.top_speed(), rel=1e-3)


def test_turning_radius_is_fossens(model: VehicleModel) -> None:
    cruise = optimal_cruise_speed(model).speed
    turn = tightest_turn(model, cruise)
    _, v, r, radius = fossen.full_rudder_turn(cruise)
    assert turn.radius == pytest.approx(radius, rel=0.01)
    assert turn.state[model.index("delta_rudder")] == pytest.approx(fossen.DELTA_MAX)
    assert turn.state[model.index("r")] == pytest.approx(r, rel=0.01)
    assert turn.state[model.index("v")] == pytest.approx(v, rel=0.02)
    # the steady turn flown with RK4 closes a circle of that radius, centre to starboard
    period = 2 * math.pi / turn.state[model.index("r")]
    states = rk4_simulate(model, turn.state, np.zeros((600, 2)), period / 600)
    np.testing.assert_allclose(states[-1, :2], [0.0, 0.0], atol=1e-3 * turn.radius)
    course = math.atan2(turn.state[model.index("v")], cruise)
    centre = turn.radius * np.array([-math.sin(course), math.cos(course)])
    np.testing.assert_allclose(np.hypot(*(states[:, :2] - centre).T), turn.radius, rtol=1e-4)


def test_rudder_turns_the_bow_and_saturates_by_the_rate_law(model: VehicleModel) -> None:
    state = operating_state(model, u=1.5, throttle=15.0)
    state[model.index("delta_rudder")] = 0.1
    xdot = np.asarray(model.dynamics(state, [0.0, 0.5])).ravel()
    assert xdot[model.index("r")] > 0.0  # positive rudder turns to starboard
    assert xdot[model.index("v")] < 0.0  # lift to port pushes the stern to port
    assert xdot[model.index("delta_rudder")] == pytest.approx(math.radians(150) * math.tanh(0.5))
    assert max_yaw_rate(model) == pytest.approx(steady_motion(model, 1525 / 60, math.radians(15)).r)


def test_energy_per_metre_has_an_interior_minimum(model: VehicleModel) -> None:
    cruise = optimal_cruise_speed(model)
    grid = np.linspace(0.2, 2.4, 45)
    costs = np.array([energy_per_metre(model, float(u)) for u in grid])
    best = int(np.argmin(costs))
    assert 0 < best < grid.size - 1
    assert np.all(np.diff(costs[: best + 1]) < 0)
    assert np.all(np.diff(costs[best:]) > 0)
    assert cruise.energy_per_metre <= costs.min() + 1e-9
    assert abs(cruise.speed - grid[best]) <= grid[1] - grid[0]
    # hotel load over speed dominates slow, propulsion (~u²) fast
    assert costs[0] > 2 * cruise.energy_per_metre
    assert costs[-1] > 2 * cruise.energy_per_metre


def test_optimiser_hooks_are_generic(model: VehicleModel) -> None:
    floor = regulator_floor(model)
    assert set(floor) == {"n_prop"}  # the rudder is not floored
    assert 0.0 < floor["n_prop"] < trim_surge(model, optimal_cruise_speed(model).speed).n
    step = stable_rk4_step(model)
    assert 0.05 < step < 5.0


def test_cli_reports_within_five_percent_of_the_source(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["vehicle", "remus100", "--json"]) == 0
    table = json.loads(capsys.readouterr().out)["characteristics"]
    # Fossen, remus100.py: "maximum speed of 2.5 m/s ... when the propeller runs at 1525 rpm"
    assert table["top_speed"] == pytest.approx(2.5, rel=0.05)
    # turning radius at full rudder (15 deg) at the cruise speed, from Fossen's equations
    radius = fossen.full_rudder_turn(table["cruise_speed"])[3]
    assert table["turning_radius"] == pytest.approx(radius, rel=0.05)
    assert table["n_max"] == pytest.approx(1525 / 60)
    bollard = 1026 * 0.14**4 * 0.4566 * (1525 / 60) ** 2  # rho D^4 K_T0 n^2, n = 1525 rpm
    assert table["bollard_thrust"] == pytest.approx(bollard, rel=1e-4)
    assert 0.5 < table["cruise_speed"] < 1.5


def test_cli_text_and_validation_figure(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    figure = tmp_path / "remus100.png"
    assert main(["vehicle", "remus100", "--figure", str(figure)]) == 0
    out = capsys.readouterr().out
    assert "K_T and K_Q linear in J" in out
    assert "turning radius" in out
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert figure.stat().st_size > 10_000
