"""Fossen's remus100 equations restricted to surge, sway and yaw: an independent reference.

Transcribed from T. I. Fossen's PythonVehicleSimulator ``vehicles/remus100.py`` (MIT licence,
commit 7e1db8edeafed3bdb24874013dd9259a10fb19ff; same model in MSS ``VESSELS/remus100.m``)
as written there, not from the vehicle file: the hull from the spheroid formulas, the surge
drag ``-½ρ U_r² S C_D0``, the advance speed ``0.944 U``, the propeller's reverse branch, the
21 cross-flow stations of ``crossFlowDrag``, the rudder's lift and drag, linear damping
faded by ``exp(-3 U_r)`` in surge and sway, ``C_A`` horizontal terms zeroed. Roll, pitch and
heave are held at rest (the horizontal plane of the 6-DOF model).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq, root

RHO = 1026.0
LENGTH, DIAMETER = 1.6, 0.19
A, B = LENGTH / 2, DIAMETER / 2
PLANFORM = 0.7 * LENGTH * DIAMETER
MASS = 4 / 3 * math.pi * RHO * A * B**2
I_Z = MASS * (A**2 + B**2) / 5
_E = math.sqrt(1 - (B / A) ** 2)
_ALPHA0 = (2 * (1 - _E**2) / _E**3) * (0.5 * math.log((1 + _E) / (1 - _E)) - _E)
_BETA0 = 1 / _E**2 - (1 - _E**2) / (2 * _E**3) * math.log((1 + _E) / (1 - _E))
K1 = _ALPHA0 / (2 - _ALPHA0)
K2 = _BETA0 / (2 - _BETA0)
K_PRIME = (
    _E**4 * (_BETA0 - _ALPHA0) / ((2 - _E**2) * (2 * _E**2 - (2 - _E**2) * (_BETA0 - _ALPHA0)))
)
M = np.array([MASS * (1 + K1), MASS * (1 + K2), I_Z * (1 + K_PRIME)])
CD_0 = 0.42 * math.pi * B**2 / PLANFORM
# Hoerner's 2-D cross-flow coefficient at B/(2T) = 0.5, interpolated in Fossen's table
HOERNER = float(np.interp(0.5, [0.4933, 0.5585], [1.2108, 1.0836]))
RUDDER_AREA, RUDDER_LIFT, RUDDER_X = 2 * 0.00665, 0.5, -A
DELTA_MAX = math.radians(15.0)
N_MAX_RPM = 1525.0
#: "The maximum speed of 2.5 m/s is obtained when the propeller runs at 1525 rpm" (remus100.py)
STATED_TOP_SPEED = 2.5


def nu_dot(u: float, v: float, r: float, delta: float, n_rpm: float) -> np.ndarray:
    """``(u̇, v̇, ṙ)`` of Fossen's remus100 in the horizontal plane, no current."""
    speed = math.hypot(u, v)
    n = n_rpm / 60.0
    diameter, advance = 0.14, 0.944 * speed
    if n > 0:
        thrust = (
            RHO
            * diameter**4
            * (0.4566 * abs(n) * n + (0.1798 - 0.4566) / 0.6632 * (advance / diameter) * abs(n))
        )
    else:
        thrust = RHO * diameter**4 * 0.4566 * abs(n) * n
    drag = -0.5 * RHO * speed**2 * PLANFORM * CD_0
    sway = moment = 0.0
    dx, station = LENGTH / 20, -LENGTH / 2
    for _ in range(21):
        flow = abs(v + station * r) * (v + station * r)
        sway -= 0.5 * RHO * DIAMETER * HOERNER * flow * dx
        moment -= 0.5 * RHO * DIAMETER * HOERNER * station * flow * dx
        station += dx
    pressure = 0.5 * RHO * speed**2 * RUDDER_AREA * RUDDER_LIFT
    rudder_x, rudder_y = -pressure * delta**2, -pressure * delta
    fade = math.exp(-3 * speed)
    return np.array(
        [
            (0.9 * thrust + rudder_x + drag + MASS * v * r - M[0] / 20 * fade * u) / M[0],
            (rudder_y + sway - MASS * u * r - M[1] / 20 * fade * v) / M[1],
            (RUDDER_X * rudder_y + moment - M[2] / 1 * r) / M[2],
        ]
    )


def top_speed() -> float:
    """Straight-line speed at 1525 rpm [m/s]."""
    return float(brentq(lambda u: nu_dot(u, 0.0, 0.0, 0.0, N_MAX_RPM)[0], 0.1, 5.0, xtol=1e-12))


def full_rudder_turn(speed: float) -> tuple[float, float, float, float]:
    """Steady turn at surge ``speed`` with the rudder at +15°: ``(rpm, v, r, radius)``."""
    solution = root(
        lambda z: nu_dot(speed, z[1], z[2], DELTA_MAX, z[0]), [600.0, 0.0, 0.05], tol=1e-12
    )
    assert solution.success
    rpm, v, r = solution.x
    return float(rpm), float(v), float(r), math.hypot(speed, v) / abs(r)
