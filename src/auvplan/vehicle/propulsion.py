"""Four-quadrant propeller and DC-motor models: smooth CasADi expressions and numpy references.

Propeller (Roddy et al. 2006; Fossen 2021, sec. 9.5)::

    v_p = 0.7 π n D                      blade speed at 0.7 R [m/s], n in rev/s
    β   = atan2(v_a, v_p)                advance angle [rad]
    C*(β) = Σ_{k=0}^{K} A[k] cos kβ + B[k] sin kβ
    T = c_T ½ρ C_T*(β) V_r² πR²,   Q = c_Q ½ρ C_Q*(β) V_r² πR² D,   V_r² = v_a² + v_p²

Smooth form used by the optimiser (no atan2, twice continuously differentiable everywhere)::

    S = v_a² + v_p²,  V_ε² = S + ε_V²,  z = (v_p + i v_a)/V_ε = ρ e^{iβ},  ρ = sqrt(S/V_ε²)
    C*(β) V_r²  ≈  A[0] S + Σ_{k≥1} V_ε² (A[k] Re z^k + B[k] Im z^k)

``z^k`` is built by angle addition (complex multiplication), so ``V_ε² z^k`` is a
homogeneous polynomial of degree ``k`` divided by ``V_ε^{k-2}``: smooth because
``V_ε ≥ ε_V > 0``, and exactly zero thrust at ``v_a = v_p = 0``. The relative error of the
k-th harmonic is ``ρ^{k-2} - 1 ≈ -(k - 2) ε_V²/(2S)``, i.e. about 1e-5 at cruise for
``ε_V = 0.02`` m/s.

Open-water propeller, ``K_T``, ``K_Q`` linear in ``J = v_a/(nD)`` (Fossen 2021, sec. 9.3)::

    T = ρ D⁴ (K_T0 n |n|_ε + K_T' (v_a/D) |n|_ε),   Q = ρ D⁵ (K_Q0 n |n|_ε + K_Q' (v_a/D) |n|_ε)

one formula for both signs of ``n`` (smooth; Fossen's ``remus100`` keeps only the ``K_T0``
term in reverse), ``|n|_ε = sqrt(n² + ε_n²)``.

Motor (DC, inductance neglected; paper Sec. II-C)::

    I = Q/K_t + I_0 sgn_ε(n)      (current_model = "torque")
    I = sgn_ε(n) Σ_j a_j |n|_ε^j  (current_model = "measured": least-squares fit of I(n))
    P = R_a I² + K_e (2πn) I      per motor,  sgn_ε(n) = n/|n|_ε,  |n|_ε = sqrt(n² + ε_n²)

References
----------
.. [1] R. F. Roddy, D. E. Hess, W. Faller, NSWCCD-50-TR-2006/004, 2006.
.. [2] T. I. Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed.,
   Wiley 2021, sec. 9.5.
.. [3] A. J. Häusler et al., "Cooperative AUV motion planning using terrain information",
   OCEANS 2013, Sec. II-B, II-C.
"""

from __future__ import annotations

import math
from typing import Final

import casadi as ca
import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.vehicle.params import LinearPropellerParams, MotorParams, Propeller, PropellerParams

#: Radius fraction of the reference blade section [-].
BLADE_RADIUS_FRACTION: Final = 0.7
#: Polynomial degree of the fitted measured current curve ``I(n)`` [-].
CURRENT_FIT_DEGREE: Final = 3


def resolve_order(propeller: Propeller, order: int | None) -> int:
    """Harmonic order actually used: ``order``, else ``propeller.order``, else all.

    An open-water propeller has no harmonics: its order is 0.

    Raises
    ------
    InputError
        If the order is negative or above the tabulated maximum.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> resolve_order(load_vehicle("medusa").propeller, 5)
    5
    """
    chosen = order if order is not None else propeller.order
    if chosen is None:
        return propeller.max_order
    if not 0 <= chosen <= propeller.max_order:
        raise InputError(
            f"propeller order must be in [0, {propeller.max_order}] for "
            f"{propeller.name}, got {chosen!r}"
        )
    return int(chosen)


def fourier_series(
    beta: FloatArray, cos_coefficients: FloatArray, sin_coefficients: FloatArray, order: int
) -> FloatArray:
    """Evaluate ``Σ_{k=0}^{order} a[k] cos kβ + b[k] sin kβ`` (exact trigonometry).

    Parameters
    ----------
    beta : ndarray of any shape
        Advance angle [rad].
    cos_coefficients, sin_coefficients : ndarray of shape (K + 1,)
        Fourier coefficients [-].
    order : int
        Highest harmonic used, ``0 ≤ order ≤ K``.

    Returns
    -------
    ndarray, same shape as ``beta``
        Series value [-].

    Examples
    --------
    >>> float(fourier_series(np.array(0.0), np.array([1.0, 2.0]), np.zeros(2), 1))
    3.0
    """
    beta = np.asarray(beta, dtype=np.float64)
    k = np.arange(order + 1, dtype=np.float64)
    angles = beta[..., np.newaxis] * k
    value = (
        np.cos(angles) @ cos_coefficients[: order + 1]
        + np.sin(angles) @ sin_coefficients[: order + 1]
    )
    return np.asarray(value, dtype=np.float64)


def thrust_coefficient(
    beta: FloatArray, propeller: PropellerParams, *, order: int | None = None
) -> FloatArray:
    """``C_T*(β)`` of the Fourier series (exact, numpy) [-].

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> round(float(thrust_coefficient(np.array(0.0), load_vehicle("medusa").propeller)), 4)
    0.3125
    """
    k = resolve_order(propeller, order)
    return fourier_series(beta, propeller.A_T, propeller.B_T, k)


def torque_coefficient(
    beta: FloatArray, propeller: PropellerParams, *, order: int | None = None
) -> FloatArray:
    """``C_Q*(β)`` of the Fourier series (exact, numpy) [-].

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> round(float(torque_coefficient(np.array(0.0), load_vehicle("medusa").propeller)), 4)
    0.0671
    """
    k = resolve_order(propeller, order)
    return fourier_series(beta, propeller.A_Q, propeller.B_Q, k)


def open_water_thrust_torque(
    advance_speed: FloatArray,
    n: FloatArray,
    propeller: PropellerParams,
    rho: float,
    *,
    order: int | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Thrust and torque of the unsmoothed four-quadrant model (numpy, ``β = atan2``).

    The reference against which the smooth CasADi form is checked.

    Parameters
    ----------
    advance_speed : ndarray
        ``v_a`` [m/s].
    n : ndarray (broadcast with ``advance_speed``)
        Propeller speed [rev/s].
    propeller : PropellerParams
        Series and scaling.
    rho : float
        Water density [kg/m³].
    order : int, optional
        Harmonics used (default: ``propeller.order`` or all).

    Returns
    -------
    thrust : ndarray
        ``T`` [N].
    torque : ndarray
        ``Q`` [N m].

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> vehicle = load_vehicle("medusa")
    >>> thrust, torque = open_water_thrust_torque(
    ...     np.array(0.0), np.array(75.0), vehicle.propeller, vehicle.hull.rho)
    >>> round(float(thrust), 1), round(float(torque), 3)
    (36.1, 0.442)
    """
    v_a = np.asarray(advance_speed, dtype=np.float64)
    v_p = BLADE_RADIUS_FRACTION * math.pi * np.asarray(n, dtype=np.float64) * propeller.diameter
    beta = np.arctan2(v_a, v_p)
    dynamic = 0.5 * rho * (v_a**2 + v_p**2) * propeller.disc_area
    c_t = thrust_coefficient(beta, propeller, order=order)
    c_q = torque_coefficient(beta, propeller, order=order)
    thrust = propeller.c_T * c_t * dynamic
    torque = propeller.c_Q * c_q * dynamic * propeller.diameter
    return np.asarray(thrust, dtype=np.float64), np.asarray(torque, dtype=np.float64)


def smooth_thrust_torque_expression(
    advance_speed: ca.SX,
    n: ca.SX,
    propeller: PropellerParams,
    rho: float,
    *,
    order: int,
    eps_inflow: float,
) -> tuple[ca.SX, ca.SX]:
    """Smooth CasADi expressions of thrust ``T`` [N] and torque ``Q`` [N m] of one propeller.

    See the module docstring for the construction (no atan2; angle-addition recurrence;
    ``V_ε² = v_a² + v_p² + ε_V²``).

    Parameters
    ----------
    advance_speed : casadi.SX
        ``v_a`` [m/s].
    n : casadi.SX
        Propeller speed [rev/s].
    propeller : PropellerParams
        Series and scaling.
    rho : float
        Water density [kg/m³].
    order : int
        Harmonics used, ``0 ≤ order ≤ K``.
    eps_inflow : float
        ``ε_V`` [m/s], > 0.

    Returns
    -------
    thrust, torque : casadi.SX
        Scalar expressions.
    """
    v_p = BLADE_RADIUS_FRACTION * math.pi * propeller.diameter * n
    speed_sq = advance_speed**2 + v_p**2
    inflow_sq = speed_sq + eps_inflow**2
    inflow = ca.sqrt(inflow_sq)
    cos_1 = v_p / inflow
    sin_1 = advance_speed / inflow
    harmonics_t = ca.SX(0.0)
    harmonics_q = ca.SX(0.0)
    cos_k, sin_k = cos_1, sin_1
    for k in range(1, order + 1):
        if k > 1:
            cos_k, sin_k = cos_k * cos_1 - sin_k * sin_1, sin_k * cos_1 + cos_k * sin_1
        harmonics_t += propeller.A_T[k] * cos_k + propeller.B_T[k] * sin_k
        harmonics_q += propeller.A_Q[k] * cos_k + propeller.B_Q[k] * sin_k
    thrust_series = propeller.A_T[0] * speed_sq + inflow_sq * harmonics_t
    torque_series = propeller.A_Q[0] * speed_sq + inflow_sq * harmonics_q
    scale = 0.5 * rho * propeller.disc_area
    thrust = propeller.c_T * scale * thrust_series
    torque = propeller.c_Q * scale * propeller.diameter * torque_series
    return thrust, torque


def linear_propeller_thrust_torque_expression(
    advance_speed: ca.SX,
    n: ca.SX,
    propeller: LinearPropellerParams,
    rho: float,
    *,
    eps_n: float,
) -> tuple[ca.SX, ca.SX]:
    """Smooth CasADi thrust ``T`` [N] and torque ``Q`` [N m] of an open-water propeller.

    ``T = ρD⁴ (K_T0 n |n|_ε + K_T' (v_a/D) |n|_ε)``, ``Q`` likewise with ``ρD⁵``, ``K_Q``
    (module docstring).

    Parameters
    ----------
    advance_speed : casadi.SX
        ``v_a`` [m/s].
    n : casadi.SX
        Propeller speed [rev/s].
    propeller : LinearPropellerParams
        Coefficients and diameter.
    rho : float
        Water density [kg/m³].
    eps_n : float
        ``ε_n`` of ``|n|_ε = sqrt(n² + ε_n²)`` [rev/s], > 0.

    Returns
    -------
    thrust, torque : casadi.SX
        Scalar expressions.
    """
    diameter = propeller.diameter
    abs_n = ca.sqrt(n**2 + eps_n**2)
    inflow = advance_speed / diameter * abs_n
    thrust = rho * diameter**4 * (propeller.K_T0 * n * abs_n + propeller.thrust_slope * inflow)
    torque = rho * diameter**5 * (propeller.K_Q0 * n * abs_n + propeller.torque_slope * inflow)
    return thrust, torque


def thrust_torque_expression(
    advance_speed: ca.SX,
    n: ca.SX,
    propeller: Propeller,
    rho: float,
    *,
    order: int,
    eps_inflow: float,
    eps_n: float,
) -> tuple[ca.SX, ca.SX]:
    """Thrust [N] and torque [N m] of any propeller model (smooth CasADi expressions).

    Dispatches to :func:`smooth_thrust_torque_expression` (four-quadrant series, ``order``
    harmonics, ``eps_inflow``) or :func:`linear_propeller_thrust_torque_expression` (``eps_n``).
    """
    if isinstance(propeller, LinearPropellerParams):
        return linear_propeller_thrust_torque_expression(
            advance_speed, n, propeller, rho, eps_n=eps_n
        )
    return smooth_thrust_torque_expression(
        advance_speed, n, propeller, rho, order=order, eps_inflow=eps_inflow
    )


def fit_current_curve(motor: MotorParams, eps_sign_n: float) -> FloatArray:
    """Least-squares coefficients ``a_j`` of ``I(n) = sgn_ε(n) Σ_j a_j |n|_ε^j``.

    Fitted to the measured table (``n ≥ 0``) with ``|n|_ε = sqrt(n² + ε_n²)``; the degree
    is ``min(CURRENT_FIT_DEGREE, n_points - 1)``. Odd in ``n`` by construction (reverse
    rotation draws the mirrored current) and smooth everywhere.

    Returns
    -------
    ndarray of shape (degree + 1,)
        Coefficients ``a_0 … a_degree`` [A (s/rev)^j].

    Raises
    ------
    InputError
        If the motor has no current curve.

    Examples
    --------
    >>> from auvplan.vehicle.params import MotorParams
    >>> n = np.array([0.0, 25.0, 50.0, 75.0])
    >>> motor = MotorParams(R_a=0.3, K_e=0.045, V_bus=24.0, current_model="measured",
    ...                     current_curve_n=n, current_curve_amps=2e-3 * n**2)
    >>> [round(float(a), 6) + 0.0 for a in fit_current_curve(motor, 1e-3)]
    [0.0, 0.0, 0.002, 0.0]
    """
    if motor.current_curve_n is None or motor.current_curve_amps is None:
        raise InputError("the motor has no measured current curve I(n)")
    speed = np.sqrt(motor.current_curve_n**2 + eps_sign_n**2)
    degree = min(CURRENT_FIT_DEGREE, motor.current_curve_n.size - 1)
    coefficients = np.polynomial.polynomial.polyfit(speed, motor.current_curve_amps, degree)
    return np.asarray(coefficients, dtype=np.float64)


def motor_current_expression(
    torque: ca.SX, n: ca.SX, motor: MotorParams, *, eps_sign_n: float
) -> ca.SX:
    """Smooth CasADi expression of the armature current [A] of one motor.

    ``current_model="torque"``: ``I = Q/K_e + I_0 n/sqrt(n² + ε_n²)``;
    ``"measured"``: the fitted curve of :func:`fit_current_curve`.
    """
    abs_n = ca.sqrt(n**2 + eps_sign_n**2)
    sign_n = n / abs_n
    if motor.current_model == "torque":
        return torque / motor.K_e + motor.I_0 * sign_n
    coefficients = fit_current_curve(motor, eps_sign_n)
    magnitude = ca.SX(0.0)
    for power, coefficient in enumerate(coefficients):
        magnitude += float(coefficient) * abs_n**power
    return sign_n * magnitude


def motor_power_expression(current: ca.SX, n: ca.SX, motor: MotorParams) -> ca.SX:
    """Electrical power [W] of one motor: ``R_a I² + K_e (2πn) I``."""
    return motor.R_a * current**2 + motor.K_e * 2.0 * math.pi * n * current


__all__ = [
    "BLADE_RADIUS_FRACTION",
    "CURRENT_FIT_DEGREE",
    "fit_current_curve",
    "fourier_series",
    "linear_propeller_thrust_torque_expression",
    "motor_current_expression",
    "motor_power_expression",
    "open_water_thrust_torque",
    "resolve_order",
    "smooth_thrust_torque_expression",
    "thrust_coefficient",
    "thrust_torque_expression",
    "torque_coefficient",
]
