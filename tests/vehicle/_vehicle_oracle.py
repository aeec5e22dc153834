"""Slow, loop-based reference implementation of the MEDUSA model (exact atan2 and |.|).

Written from reference/vehicle.md §1 in component form (not the matrix form of the library),
so that it is an independent check of ``build_vehicle_model``.
"""

from __future__ import annotations

import math

import numpy as np

from auvplan.vehicle.params import VehicleParams


def coefficient(beta: float, a: np.ndarray, b: np.ndarray) -> float:
    return sum(a[k] * math.cos(k * beta) + b[k] * math.sin(k * beta) for k in range(a.size))


def propeller(v_a: float, n: float, params: VehicleParams) -> tuple[float, float]:
    prop = params.propeller
    v_p = 0.7 * math.pi * n * prop.diameter
    beta = math.atan2(v_a, v_p)
    q = 0.5 * params.hull.rho * (v_a**2 + v_p**2) * math.pi * (prop.diameter / 2) ** 2
    thrust = prop.c_T * coefficient(beta, prop.A_T, prop.B_T) * q
    torque = prop.c_Q * coefficient(beta, prop.A_Q, prop.B_Q) * q * prop.diameter
    return thrust, torque


def dynamics(state: np.ndarray, inputs: np.ndarray, params: VehicleParams) -> np.ndarray:
    hull = params.hull
    _, _, psi, u, v, r, n_ps, n_sb = (float(s) for s in state)
    m_u, m_v, m_r = hull.m - hull.X_udot, hull.m - hull.Y_vdot, hull.I_z - hull.N_rdot
    t_ps, _ = propeller(u + params.l * r, n_ps, params)
    t_sb, _ = propeller(u - params.l * r, n_sb, params)
    u_dot = (m_v * v * r + hull.X_u * u + hull.X_uu * abs(u) * u + t_ps + t_sb) / m_u
    v_dot = (-m_u * u * r + hull.Y_v * v + hull.Y_vv * abs(v) * v) / m_v
    r_dot = (
        (m_u - m_v) * u * v + hull.N_r * r + hull.N_rr * abs(r) * r + params.l * (t_ps - t_sb)
    ) / m_r
    return np.array(
        [
            u * math.cos(psi) - v * math.sin(psi),
            u * math.sin(psi) + v * math.cos(psi),
            r,
            u_dot,
            v_dot,
            r_dot,
            params.w_c * math.tanh(float(inputs[0])),
            params.w_c * math.tanh(float(inputs[1])),
        ]
    )


def power(state: np.ndarray, params: VehicleParams) -> float:
    motor = params.motor
    _, _, _, u, _, r, n_ps, n_sb = (float(s) for s in state)
    total = params.hotel_power
    for v_a, n in ((u + params.l * r, n_ps), (u - params.l * r, n_sb)):
        _, torque = propeller(v_a, n, params)
        current = torque / motor.K_e + motor.I_0 * float(np.sign(n))
        total += motor.R_a * current**2 + motor.K_e * 2 * math.pi * n * current
    return total
