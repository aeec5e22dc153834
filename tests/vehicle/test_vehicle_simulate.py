"""Simulation: RK4 grid vs adaptive reference; physics checks against reference/vehicle.md."""

from __future__ import annotations

import math

import _vehicle_oracle as oracle
import numpy as np
import pytest

from auvplan.errors import InputError
from auvplan.io.vehicles import load_vehicle
from auvplan.vehicle import VehicleModel, build_vehicle_model, energy
from auvplan.vehicle.simulate import rk4_simulate, rk4_step_function, simulate_adaptive
from auvplan.vehicle.trim import (
    bollard,
    energy_per_metre,
    max_yaw_rate,
    optimal_cruise_speed,
    steady_motion,
    top_speed,
    trim_surge,
    trim_turn,
    vehicle_characteristics,
)


@pytest.fixture(scope="module")
def model() -> VehicleModel:
    return build_vehicle_model(load_vehicle("medusa"))


# A 50 s manoeuvre on a 0.5 s zero-order-hold grid: accelerate to ~1 m/s, turn to starboard,
# straighten, back down through zero propeller speed (all four quadrants), stop.
MANOEUVRE = (
    (1, (0.8, 0.8)),
    (20, (0.0, 0.0)),
    (1, (0.3, -0.3)),
    (20, (0.0, 0.0)),
    (1, (-0.3, 0.3)),
    (15, (0.0, 0.0)),
    (2, (-0.8, -0.8)),
    (20, (0.0, 0.0)),
    (1, (0.8, 0.8)),
    (19, (0.0, 0.0)),
)
MANOEUVRE_DT = 0.5


def manoeuvre_inputs() -> np.ndarray:
    return np.vstack([np.tile(c, (n, 1)) for n, c in MANOEUVRE])


def test_rk4_matches_adaptive_reference_on_a_manoeuvre(model: VehicleModel) -> None:
    inputs = manoeuvre_inputs()
    t_end = inputs.shape[0] * MANOEUVRE_DT
    reference = simulate_adaptive(model, np.zeros(8), inputs, (0.0, t_end))
    assert reference.success
    assert reference.states[:, 5].max() > 0.5  # the turn happened (to starboard)
    assert reference.states[:, 3].min() < -0.5  # and the backing
    errors = {}
    for substeps in (1, 5):
        dt = MANOEUVRE_DT / substeps
        states = rk4_simulate(model, np.zeros(8), np.repeat(inputs, substeps, axis=0), dt)
        grid = states[::substeps]
        errors[dt] = float(np.max(np.hypot(*(grid[:, :2] - reference.states[:, :2]).T)))
    # measured: 0.024 m at dt = 0.5 s, 0.0014 m at dt = 0.1 s (benchmarks/bench_vehicle.py)
    assert errors[0.5] < 0.1
    assert errors[0.1] < 0.005
    assert errors[0.1] < errors[0.5] / 5


def test_swapped_inputs_give_the_mirrored_trajectory(model: VehicleModel) -> None:
    inputs = manoeuvre_inputs()
    states = rk4_simulate(model, np.zeros(8), inputs, MANOEUVRE_DT)
    mirrored = rk4_simulate(model, np.zeros(8), inputs[:, ::-1], MANOEUVRE_DT)
    np.testing.assert_allclose(mirrored[:, [0, 3]], states[:, [0, 3]], atol=1e-9)
    np.testing.assert_allclose(mirrored[:, [1, 2, 4, 5]], -states[:, [1, 2, 4, 5]], atol=1e-9)
    np.testing.assert_allclose(mirrored[:, [6, 7]], states[:, [7, 6]], atol=1e-9)
    assert states[:, 1].max() > 1.0  # the manoeuvre does go east (starboard turn first)


def test_rk4_rollout_equals_repeated_steps(model: VehicleModel, rng: np.random.Generator) -> None:
    inputs = rng.uniform(-0.3, 0.3, (6, 2))
    x0 = np.array([1.0, 2.0, 0.3, 0.5, 0.0, 0.1, 30.0, 25.0])
    states = rk4_simulate(model, x0, inputs, 0.2)
    step = rk4_step_function(model, 0.2)
    manual = [x0]
    for c in inputs:
        manual.append(np.asarray(step(manual[-1], c)).ravel())
    np.testing.assert_allclose(states, np.array(manual), rtol=1e-14, atol=1e-12)
    with pytest.raises(InputError, match="dt"):
        rk4_simulate(model, x0, inputs, 0.0)
    with pytest.raises(InputError, match="initial state"):
        rk4_simulate(model, x0[:5], inputs, 0.1)


def test_adaptive_with_control_law(model: VehicleModel) -> None:
    law = lambda t: np.array([0.2 * math.cos(t), 0.2 * math.sin(t)])  # noqa: E731
    result = simulate_adaptive(model, np.zeros(8), law, (0.0, 3.0), t_eval=np.linspace(0, 3, 4))
    assert result.success
    np.testing.assert_allclose(result.time, [0, 1, 2, 3])
    # n_ps(t) = ∫ w_c tanh(0.2 cos t) dt, checked by quadrature
    t = np.linspace(0.0, 3.0, 30001)
    n_ps = np.trapezoid(150.0 * np.tanh(0.2 * np.cos(t)), t)
    assert result.states[-1, 6] == pytest.approx(n_ps, rel=1e-6)


def test_bollard_thrust_and_torque(model: VehicleModel) -> None:
    pull = bollard(model)
    assert pull.thrust == pytest.approx(36.1, rel=0.01)  # vehicle.md §4 option A
    assert pull.torque == pytest.approx(0.442, rel=0.01)
    # 2 × 235 W electrical + 40 W hotel (vehicle.md §5); 235 W is rounded
    assert pull.power == pytest.approx(2 * 235.0 + 40.0, rel=0.01)


def test_top_speed(model: VehicleModel) -> None:
    speed = top_speed(model)
    assert speed == pytest.approx(1.48, rel=0.01)
    thrust, _, _, _ = model.thrust_torque([0, 0, 0, speed, 0, 0, 75.0, 75.0])
    assert float(thrust) == pytest.approx(30.2, rel=0.01)  # "thrust falls to 30.2 N each"
    # drag balance; the smooth |u| = sqrt(u² + ε²) changes the drag by ε²/(2u²) ≈ 2e-5
    assert 2 * float(thrust) == pytest.approx(27.5 * speed**2, rel=1e-4)


@pytest.mark.parametrize(
    ("speed", "n_expected", "propulsion_power"),
    # vehicle.md §5 table; powers there are rounded to 1 W, n to 0.1 rev/s (1 rev/s at 1.5 m/s)
    [(0.5, 25.3, 14.0), (1.0, 50.6, 118.0), (1.5, 76.0, 412.0)],
)
def test_steady_power(
    model: VehicleModel, speed: float, n_expected: float, propulsion_power: float
) -> None:
    n, power = trim_surge(model, speed)
    assert n == pytest.approx(n_expected, abs=0.15)
    assert power - model.params.hotel_power == pytest.approx(propulsion_power, abs=1.0)
    # independent (unsmoothed) oracle: the trim is an equilibrium up to the smoothing of
    # |u| (X_|u|u ε²/2 / m_u ≈ 3e-5 m/s²) and the power is R_a I² + K_e ω I
    state = np.array([0, 0, 0, speed, 0, 0, n, n])
    assert oracle.dynamics(state, np.zeros(2), model.params)[3] == pytest.approx(0, abs=1e-4)
    assert power == pytest.approx(oracle.power(state, model.params), rel=1e-4)


def test_max_yaw_rate_is_a_steady_spin(model: VehicleModel) -> None:
    rate = max_yaw_rate(model)
    motion = steady_motion(model, 75.0, -75.0)
    assert rate == motion.r
    state = np.array([0, 0, 0, motion.u, motion.v, motion.r, 75.0, -75.0])
    # equilibrium of the unsmoothed oracle up to the smoothing of |u|, |v|, |r| (< 2e-4)
    np.testing.assert_allclose(oracle.dynamics(state, np.zeros(2), model.params)[3:6], 0, atol=2e-4)
    # vehicle.md §2 quotes 1.03 rad/s for a ±36 N differential with no inflow; the
    # four-quadrant propeller gives less reverse thrust and the inflow l r reduces both, so
    # the steady rate is lower but of that size
    hull = model.params.hull
    moment = model.params.l * 2 * bollard(model).thrust
    upper = (-hull.N_r - math.sqrt(hull.N_r**2 - 4 * hull.N_rr * moment)) / (2 * hull.N_rr)
    assert upper == pytest.approx(1.03, abs=0.01)
    assert 0.85 * upper < rate < upper


def test_steady_turn_is_an_equilibrium_and_circles(model: VehicleModel) -> None:
    speed, rate = 0.5, 0.1
    turn = trim_turn(model, speed, rate)
    assert turn.n_ps > turn.n_sb  # port surplus for a starboard turn
    state = np.array([0, 0, 0, speed, turn.v, rate, turn.n_ps, turn.n_sb])
    np.testing.assert_allclose(oracle.dynamics(state, np.zeros(2), model.params)[3:6], 0, atol=2e-4)
    np.testing.assert_allclose(np.asarray(model.dynamics(state, [0, 0])).ravel()[3:6], 0, atol=1e-9)
    # a full circle returns to the start; radius = U / r
    period = 2 * math.pi / rate
    n_steps = 630
    states = rk4_simulate(model, state, np.zeros((n_steps, 2)), period / n_steps)
    np.testing.assert_allclose(states[-1, :2], [0.0, 0.0], atol=1e-3)
    radius = math.hypot(speed, turn.v) / rate
    course = math.atan2(turn.v, speed)  # the centre lies to starboard of the velocity
    centre = radius * np.array([-math.sin(course), math.cos(course)])
    distances = np.hypot(*(states[:, :2] - centre).T)
    np.testing.assert_allclose(distances, radius, rtol=1e-4)


def test_optimal_cruise_speed_minimises_energy_per_metre(model: VehicleModel) -> None:
    speed, cost = optimal_cruise_speed(model)
    assert 0.3 < speed < 1.0
    assert cost == pytest.approx(energy_per_metre(model, speed))
    grid = np.linspace(0.2, 1.4, 61)
    costs = [energy_per_metre(model, u) for u in grid]
    assert cost <= min(costs) + 1e-9
    assert abs(speed - grid[int(np.argmin(costs))]) <= 0.02 + 1e-12
    # along a steady cruise, energy per metre = E / distance
    n = trim_surge(model, speed).n
    states = np.tile([0, 0, 0, speed, 0, 0, n, n], (11, 1)).astype(float)
    states[:, 0] = speed * np.arange(11)
    total = energy(np.arange(11.0), states, np.zeros((11, 2)), model)
    assert total / (10 * speed) == pytest.approx(cost, rel=1e-9)


def test_characteristics_bundle(model: VehicleModel) -> None:
    table = vehicle_characteristics(model)
    assert table.bollard_thrust == bollard(model).thrust
    assert table.top_speed == top_speed(model)
    assert table.power_at_1_0 == trim_surge(model, 1.0).power
    assert set(table.to_dict()) >= {"cruise_speed", "cruise_energy_per_metre", "max_yaw_rate"}


def test_directional_stability_of_the_dsor_hull(model: VehicleModel) -> None:
    """With m_v > m_u the Munk moment (m_u - m_v) u v destabilises yaw at speed: straight
    motion is stable at 0.5 m/s and unstable at 1.0 m/s (a property of the published data
    set, which DSOR flies under feedback; the optimiser's regulator must stabilise it)."""
    import casadi as ca

    x = ca.SX.sym("x", 8)
    jacobian = ca.Function("A", [x], [ca.jacobian(model.dynamics(x, ca.DM.zeros(2)), x)])
    real_parts = {}
    for speed in (0.5, 1.0):
        n = trim_surge(model, speed).n
        a = np.asarray(jacobian([0, 0, 0, speed, 0, 0, n, n]))[3:6, 3:6]
        real_parts[speed] = np.linalg.eigvals(a).real.max()
    assert real_parts[0.5] < 0.0 < real_parts[1.0]
    # a small differential at 1 m/s therefore settles in a tight steady turn
    motion = steady_motion(model, 53.5, 46.1)
    assert motion.r > 0.3
