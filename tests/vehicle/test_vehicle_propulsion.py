"""Four-quadrant propeller, smoothing effect, low-order approximation, motor current."""

from __future__ import annotations

import dataclasses
import math

import _vehicle_oracle as oracle
import casadi as ca
import numpy as np
import pytest

from auvplan.io.vehicles import load_vehicle
from auvplan.vehicle import VehicleParams, build_vehicle_model
from auvplan.vehicle.approximation import approximation_error_table, smoothing_effect
from auvplan.vehicle.propulsion import (
    fit_current_curve,
    open_water_thrust_torque,
    smooth_thrust_torque_expression,
    thrust_coefficient,
    torque_coefficient,
)
from auvplan.vehicle.trim import trim_surge


@pytest.fixture(scope="module")
def params() -> VehicleParams:
    return load_vehicle("medusa")


def _smooth_propeller(params: VehicleParams, order: int, eps: float) -> ca.Function:
    v_a = ca.SX.sym("v_a")
    n = ca.SX.sym("n")
    thrust, torque = smooth_thrust_torque_expression(
        v_a, n, params.propeller, params.hull.rho, order=order, eps_inflow=eps
    )
    return ca.Function("prop", [v_a, n], [thrust, torque])


def test_published_coefficient_checks(params: VehicleParams) -> None:
    # vehicle.md §3.1: C_T*(0) = 0.31247 → K_T0 = 0.5934; C_Q*(0) = 0.067062 → K_Q0 = 0.12736
    c_t0 = float(thrust_coefficient(np.array(0.0), params.propeller))
    c_q0 = float(torque_coefficient(np.array(0.0), params.propeller))
    assert c_t0 == pytest.approx(0.31247, abs=2e-5)
    assert c_q0 == pytest.approx(0.067062, abs=2e-6)
    assert 1.8990 * c_t0 == pytest.approx(0.5934, abs=1e-4)
    # K_T at J = 0.4, 0.8, 1.0: 0.478, 0.338, 0.243 (first quadrant, J = 0.7π tan β)
    for j, k_t in ((0.4, 0.478), (0.8, 0.338), (1.0, 0.243)):
        beta = math.atan(j / (0.7 * math.pi))
        c_t = float(thrust_coefficient(np.array(beta), params.propeller))
        assert math.pi / 8 * (j**2 + 0.49 * math.pi**2) * c_t == pytest.approx(k_t, abs=1e-3)
    # ranges over β (vehicle.md §3.1)
    beta = np.linspace(-np.pi, np.pi, 20001)
    c_t = thrust_coefficient(beta, params.propeller)
    assert c_t.min() == pytest.approx(-0.775, abs=2e-3)
    assert c_t.max() == pytest.approx(0.856, abs=2e-3)


def test_numpy_series_matches_loop_oracle(params: VehicleParams, rng: np.random.Generator) -> None:
    for beta in rng.uniform(-np.pi, np.pi, 10):
        expected = oracle.coefficient(beta, params.propeller.A_T, params.propeller.B_T)
        assert float(thrust_coefficient(np.array(beta), params.propeller)) == pytest.approx(
            expected
        )


@pytest.mark.parametrize("order", [1, 3, 30])
def test_smooth_form_matches_atan2_form_in_all_quadrants(
    params: VehicleParams, rng: np.random.Generator, order: int
) -> None:
    prop = _smooth_propeller(params, order, params.eps_inflow)
    for sign_v, sign_n in ((1, 1), (1, -1), (-1, -1), (-1, 1)):
        v_a = sign_v * rng.uniform(0.2, 2.0, 20)
        n = sign_n * rng.uniform(5.0, 75.0, 20)
        thrust, torque = open_water_thrust_torque(
            v_a, n, params.propeller, params.hull.rho, order=order
        )
        for i in range(20):
            t_s, q_s = (float(v) for v in prop(v_a[i], n[i]))
            # relative error of harmonic k is ≈ (k-2) ε²/(2 V²) ≤ 28 · 4e-4 / (2 · 0.8) ≈ 7e-3
            # of that harmonic; the high harmonics are small, so the total is ~1e-4 of T_max
            scale = 0.5 * params.hull.rho * (v_a[i] ** 2 + (0.7 * math.pi * n[i] * 0.057) ** 2)
            scale *= params.propeller.disc_area
            assert t_s == pytest.approx(thrust[i], abs=5e-4 * scale)
            assert q_s == pytest.approx(torque[i], abs=5e-4 * scale * 0.057)


def test_smooth_form_is_exact_zero_at_rest_and_finite_nearby(params: VehicleParams) -> None:
    prop = _smooth_propeller(params, 30, params.eps_inflow)
    assert [float(v) for v in prop(0.0, 0.0)] == [0.0, 0.0]
    v_a, n = ca.SX.sym("v_a"), ca.SX.sym("n")
    thrust, torque = prop(v_a, n)
    z = ca.vertcat(v_a, n)
    hessian = ca.Function("h", [v_a, n], [ca.hessian(thrust, z)[0], ca.hessian(torque, z)[0]])
    for point in ((0.0, 0.0), (1e-9, -1e-9), (0.01, 0.0), (0.0, 0.1), (-1e-4, 1e-4)):
        for value in hessian(*point):
            assert np.all(np.isfinite(np.asarray(value)))


def test_smoothing_effect_below_one_permille(params: VehicleParams) -> None:
    rows = smoothing_effect(params)
    assert [row.condition for row in rows] == ["bollard", "cruise 0.5 m/s", "cruise 1.0 m/s"]
    for row in rows:
        assert abs(row.thrust) < 1e-5
        assert abs(row.torque) < 1e-5
        assert abs(row.power) < 1e-3  # dominated by the smooth |u| in the drag, ε²/(2u²)
    # a 10x larger ε_V would be visible: the quantification is sensitive
    coarse = dataclasses.replace(params, eps_inflow=1.0)
    assert abs(smoothing_effect(coarse)[1].thrust) > 1e-3


def test_approximation_table_matches_reference_numbers(params: VehicleParams) -> None:
    # vehicle.md §3.2 (rms ΔC_T*, max ΔC_T*, rms ΔC_Q*, max ΔC_Q*)
    published = {
        1: (0.093, 0.253, 0.0226, 0.078),
        3: (0.075, 0.208, 0.0169, 0.054),
        5: (0.047, 0.173, 0.0130, 0.053),
        10: (0.023, 0.084, 0.0070, 0.030),
        20: (0.0068, 0.022, 0.0027, 0.010),
    }
    rows = approximation_error_table(params, list(published), n_beta=3600)
    for row in rows:
        got = (
            row.rms_thrust_coefficient,
            row.max_thrust_coefficient,
            row.rms_torque_coefficient,
            row.max_torque_coefficient,
        )
        np.testing.assert_allclose(got, published[row.order], rtol=0.03, atol=5e-4)
    # rms error falls monotonically with the order (Parseval: truncation is L2-optimal)
    rms = [row.rms_thrust_coefficient for row in rows]
    assert rms == sorted(rms, reverse=True)
    # the effect on steady power is consistent with an independent trim of each model
    row3 = rows[1]
    full = trim_surge(build_vehicle_model(params), 1.0).power - params.hotel_power
    low = trim_surge(build_vehicle_model(params, propeller_order=3), 1.0).power
    assert row3.propulsion_power[1] == pytest.approx((low - params.hotel_power) / full - 1.0)
    assert approximation_error_table(params, [30])[0].max_thrust_coefficient == 0.0


def test_truncation_is_least_squares_optimal(
    params: VehicleParams, rng: np.random.Generator
) -> None:
    beta = np.linspace(-np.pi, np.pi, 3600, endpoint=False)
    full = thrust_coefficient(beta, params.propeller)
    truncated = thrust_coefficient(beta, params.propeller, order=3)
    base_error = np.mean((truncated - full) ** 2)
    for _ in range(5):  # any other order-3 series is worse
        a = params.propeller.A_T[:4] + rng.normal(scale=0.01, size=4)
        b = params.propeller.B_T[:4] + rng.normal(scale=0.01, size=4)
        other = sum(a[k] * np.cos(k * beta) + b[k] * np.sin(k * beta) for k in range(4))
        assert np.mean((other - full) ** 2) > base_error


def test_measured_current_model(params: VehicleParams) -> None:
    motor = params.motor
    assert motor.current_curve_n is not None
    assert motor.current_curve_amps is not None
    measured = dataclasses.replace(
        params, motor=dataclasses.replace(motor, current_model="measured")
    )
    model = build_vehicle_model(measured)
    for n in (15.0, 45.0, 75.0):
        i_ps, _ = model.current([0, 0, 0, 0, 0, 0, n, n])
        # the packaged curve is the bollard current, 1.746e-3 n² A
        assert float(i_ps) == pytest.approx(1.746e-3 * n**2, rel=0.01)
    # odd in n, zero at n = 0, independent of the inflow
    i_ps, i_sb = model.current([0, 0, 0, 1.0, 0, 0, 40.0, -40.0])
    assert float(i_ps) == pytest.approx(-float(i_sb))
    assert float(model.current(np.zeros(8))[0]) == 0.0
    # at bollard the measured and the torque models agree (the curve was made that way)
    torque_model = build_vehicle_model(params)
    state = [0, 0, 0, 0, 0, 0, 60.0, 60.0]
    assert float(model.power(state, [0, 0])) == pytest.approx(
        float(torque_model.power(state, [0, 0])), rel=0.01
    )
    coefficients = fit_current_curve(motor, params.eps_sign_n)
    assert coefficients.shape == (4,)
