"""MEDUSA dynamics: exact derivatives vs finite differences, oracle, symmetry, batching."""

from __future__ import annotations

import dataclasses

import _vehicle_oracle as oracle
import casadi as ca
import numpy as np
import pytest

from auvplan.errors import InputError
from auvplan.io.vehicles import load_vehicle
from auvplan.vehicle import (
    VehicleModel,
    VehicleParams,
    build_vehicle_model,
    electrical_power,
    energy,
    vessel_dynamics,
)
from auvplan.vehicle.simulate import rk4_step_function


@pytest.fixture(scope="module")
def params() -> VehicleParams:
    return load_vehicle("medusa")


@pytest.fixture(scope="module")
def model(params: VehicleParams) -> VehicleModel:
    return build_vehicle_model(params)


# (sign of u, sign of n): the four propeller quadrants (v_a = u ± l r keeps the sign of u)
QUADRANTS = {
    "ahead": (1.0, 1.0),
    "crash-back": (1.0, -1.0),
    "backing": (-1.0, -1.0),
    "crash-ahead": (-1.0, 1.0),
}


def _random_state(rng: np.random.Generator, sign_u: float, sign_n: float) -> np.ndarray:
    return np.array(
        [
            rng.uniform(-50, 50),
            rng.uniform(-50, 50),
            rng.uniform(-np.pi, np.pi),
            sign_u * rng.uniform(0.3, 1.5),
            rng.uniform(-0.2, 0.2),
            rng.uniform(-0.5, 0.5),
            sign_n * rng.uniform(3.0, 75.0),
            sign_n * rng.uniform(3.0, 75.0),
        ]
    )


def _near_rest_states(rng: np.random.Generator) -> list[np.ndarray]:
    states = [np.zeros(8)]
    for scale_nu, scale_n in ((1e-3, 1e-2), (1e-2, 0.1), (0.0, 1e-3)):
        state = np.zeros(8)
        state[2] = rng.uniform(-np.pi, np.pi)
        state[3:6] = rng.uniform(-scale_nu, scale_nu, 3)
        state[6:8] = rng.choice([-1.0, 1.0], 2) * scale_n
        states.append(state)
    # propeller stopped while its inflow is exactly zero (v_a,ps = u + l r = 0) but moving
    states.append(np.array([0.0, 0.0, 0.3, 0.3, 0.05, -2.0, 0.0, 10.0]))
    return states


def _test_points(rng: np.random.Generator) -> list[tuple[str, np.ndarray, np.ndarray]]:
    points = []
    for name, (sign_u, sign_n) in QUADRANTS.items():
        for _ in range(2):
            points.append((name, _random_state(rng, sign_u, sign_n), rng.uniform(-2.0, 2.0, 2)))
    for state in _near_rest_states(rng):
        points.append(("near rest", state, rng.uniform(-1.0, 1.0, 2)))
    return points


def _jacobian_and_hessian(
    function: ca.Function, n_out: int
) -> tuple[ca.Function, ca.Function, ca.Function]:
    """Exact J = ∂f/∂z, gradient g = ∇(λ·f), H = ∇²(λ·f) with z = (x, c)."""
    x = ca.SX.sym("x", 8)
    c = ca.SX.sym("c", 2)
    lam = ca.SX.sym("lam", n_out)
    z = ca.vertcat(x, c)
    out = function(x, c)
    weighted = ca.dot(lam, out)
    hessian, gradient = ca.hessian(weighted, z)
    return (
        ca.Function("J", [x, c], [ca.jacobian(out, z)]),
        ca.Function("g", [x, c, lam], [gradient]),
        ca.Function("H", [x, c, lam], [hessian]),
    )


def _central_difference(function, z: np.ndarray, step: float) -> np.ndarray:
    columns = []
    for i in range(z.size):
        h = step * max(1.0, abs(z[i]))
        plus, minus = z.copy(), z.copy()
        plus[i] += h
        minus[i] -= h
        columns.append((function(plus) - function(minus)) / (2 * h))
    return np.column_stack(columns)


def _check_derivatives(function: ca.Function, n_out: int, rng: np.random.Generator) -> None:
    jac, grad, hess = _jacobian_and_hessian(function, n_out)

    def value(z: np.ndarray) -> np.ndarray:
        return np.asarray(function(z[:8], z[8:]), dtype=float).ravel()

    for label, state, inputs in _test_points(rng):
        z = np.concatenate([state, inputs])
        lam = rng.normal(size=n_out)
        exact_j = np.asarray(jac(state, inputs))
        exact_h = np.asarray(hess(state, inputs, lam))
        assert np.all(np.isfinite(exact_j)), label
        assert np.all(np.isfinite(exact_h)), label
        numeric_j = _central_difference(value, z, 1e-6).reshape(n_out, 10)
        np.testing.assert_allclose(exact_j, numeric_j, rtol=1e-5, atol=1e-6, err_msg=label)

        def gradient(point: np.ndarray, lam: np.ndarray = lam) -> np.ndarray:
            return np.asarray(grad(point[:8], point[8:], lam), dtype=float).ravel()

        numeric_h = _central_difference(gradient, z, 1e-5)
        np.testing.assert_allclose(exact_h, numeric_h, rtol=1e-4, atol=1e-5, err_msg=label)
        np.testing.assert_allclose(exact_h, exact_h.T, atol=1e-12)


def test_dynamics_derivatives_match_finite_differences(
    model: VehicleModel, rng: np.random.Generator
) -> None:
    _check_derivatives(model.dynamics, 8, rng)


def test_power_derivatives_match_finite_differences(
    model: VehicleModel, rng: np.random.Generator
) -> None:
    _check_derivatives(model.power, 1, rng)


def test_rk4_step_derivatives_match_finite_differences(
    model: VehicleModel, rng: np.random.Generator
) -> None:
    _check_derivatives(rk4_step_function(model, 0.5), 8, rng)


def test_low_order_model_derivatives_match_finite_differences(
    params: VehicleParams, rng: np.random.Generator
) -> None:
    _check_derivatives(build_vehicle_model(params, propeller_order=3).dynamics, 8, rng)


def test_dynamics_match_loop_oracle_in_all_quadrants(
    params: VehicleParams, model: VehicleModel, rng: np.random.Generator
) -> None:
    # away from v_a = v_p = 0 the smoothing changes f by < 1e-4 relative
    for name, (sign_u, sign_n) in QUADRANTS.items():
        for _ in range(5):
            state = _random_state(rng, sign_u, sign_n)
            inputs = rng.uniform(-2, 2, 2)
            expected = oracle.dynamics(state, inputs, params)
            got = np.asarray(model.dynamics(state, inputs)).ravel()
            np.testing.assert_allclose(got, expected, rtol=1e-4, atol=1e-4, err_msg=name)
            assert float(model.power(state, inputs)) == pytest.approx(
                oracle.power(state, params), rel=1e-4, abs=1e-3
            )


def test_power_oracle_with_no_load_current(params: VehicleParams, rng: np.random.Generator) -> None:
    motor = dataclasses.replace(params.motor, I_0=0.4)
    with_i0 = dataclasses.replace(params, motor=motor)
    model = build_vehicle_model(with_i0)
    for sign_u, sign_n in QUADRANTS.values():
        state = _random_state(rng, sign_u, sign_n)
        # sgn_ε(n) differs from sgn(n) by < ε²/(2n²) ≈ 1.4e-2 at |n| ≥ 3 rev/s → rel 1e-3 on I_0
        assert float(model.power(state, np.zeros(2))) == pytest.approx(
            oracle.power(state, with_i0), rel=2e-3
        )


def test_state_is_finite_and_at_rest_everything_vanishes(model: VehicleModel) -> None:
    xdot = np.asarray(model.dynamics(np.zeros(8), np.zeros(2))).ravel()
    np.testing.assert_array_equal(xdot, np.zeros(8))
    thrust = [float(v) for v in model.thrust_torque(np.zeros(8))]
    assert thrust == [0.0, 0.0, 0.0, 0.0]
    assert float(model.power(np.zeros(8), np.zeros(2))) == model.params.hotel_power


def test_port_surplus_thrust_turns_to_starboard(model: VehicleModel) -> None:
    state = np.array([0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 40.0, 20.0])
    xdot = np.asarray(model.dynamics(state, np.zeros(2))).ravel()
    assert xdot[5] > 0.0  # r_dot > 0: bow to starboard (heading increases clockwise)
    # heading north (psi = 0), surge moves north; heading east (psi = π/2) moves east
    east = np.asarray(model.dynamics(np.r_[0, 0, np.pi / 2, state[3:]], np.zeros(2))).ravel()
    assert east[1] == pytest.approx(0.5)
    assert east[0] == pytest.approx(0.0, abs=1e-12)


def test_mirror_symmetry(model: VehicleModel, rng: np.random.Generator) -> None:
    mirror = np.array([1.0, -1.0, -1.0, 1.0, -1.0, -1.0])  # north, east, psi, u, v, r
    for _ in range(10):
        state = _random_state(rng, rng.choice([-1.0, 1.0]), rng.choice([-1.0, 1.0]))
        inputs = rng.uniform(-2, 2, 2)
        mirrored = np.concatenate([state[:6] * mirror, state[[7, 6]]])
        xdot = np.asarray(model.dynamics(state, inputs)).ravel()
        xdot_mirrored = np.asarray(model.dynamics(mirrored, inputs[::-1])).ravel()
        expected = np.concatenate([xdot[:6] * mirror, xdot[[7, 6]]])
        np.testing.assert_allclose(xdot_mirrored, expected, rtol=1e-12, atol=1e-12)


def test_batched_evaluation_matches_pointwise(
    model: VehicleModel, rng: np.random.Generator
) -> None:
    states = np.array([_random_state(rng, 1.0, 1.0) for _ in range(7)])
    inputs = rng.uniform(-1, 1, (7, 2))
    batched = vessel_dynamics(states, inputs, model)
    pointwise = np.array(
        [np.asarray(model.dynamics(s, c)).ravel() for s, c in zip(states, inputs, strict=True)]
    )
    np.testing.assert_array_equal(batched, pointwise)
    power = electrical_power(states, inputs, model)
    assert power.shape == (7,)
    np.testing.assert_array_equal(
        power, [float(model.power(s, c)) for s, c in zip(states, inputs, strict=True)]
    )
    with pytest.raises(InputError, match="inputs must have shape"):
        vessel_dynamics(states, inputs[:3], model)


def test_energy_is_trapezoid_of_power(model: VehicleModel, rng: np.random.Generator) -> None:
    n_t = 11
    time = np.cumsum(rng.uniform(0.1, 1.0, n_t))
    states = np.array([_random_state(rng, 1.0, 1.0) for _ in range(n_t)])
    inputs = np.zeros((n_t, 2))
    power = np.array([oracle.power(s, model.params) for s in states])
    expected = sum(
        0.5 * (power[k] + power[k + 1]) * (time[k + 1] - time[k]) for k in range(n_t - 1)
    )
    assert energy(time, states, inputs, model) == pytest.approx(expected, rel=1e-4)
    # constant power P over T seconds gives P T exactly
    steady = np.tile(states[0], (5, 1))
    assert energy(np.linspace(0, 8, 5), steady, np.zeros((5, 2)), model) == pytest.approx(
        8.0 * float(model.power(states[0], np.zeros(2))), rel=1e-12
    )
    with pytest.raises(InputError, match="increasing"):
        energy(time[::-1], states, inputs, model)


def test_propeller_order_is_validated(params: VehicleParams) -> None:
    with pytest.raises(InputError, match="order"):
        build_vehicle_model(params, propeller_order=31)
    assert build_vehicle_model(params, propeller_order=0).propeller_order == 0
