"""Accuracy of the model's approximations: low-order propeller series and smoothing.

Two deliberate approximations make the model cheap and twice differentiable:

* **Truncation** of the Fourier series of ``C_T*``, ``C_Q*`` at order ``K``. The Fourier basis
  is orthogonal on ``[-π, π]``, so truncation is the least-squares optimal order-``K``
  approximation; :func:`approximation_error_table` measures its error and its effect on
  bollard thrust/torque and on steady propulsion power.
* **Smoothing** (``ε_V`` in the inflow speed, smooth ``|·|`` and ``sgn``);
  :func:`smoothing_effect` compares the smoothed model with the same model at negligible
  smoothing (all ε = 1e-9) at bollard and at cruise.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np

from auvplan.errors import InputError
from auvplan.vehicle.actuators import ActuatedVehicleParams
from auvplan.vehicle.dynamics import VehicleModel, build_vehicle_model
from auvplan.vehicle.operating import actuator_roles, operating_state
from auvplan.vehicle.params import PropellerParams, VehicleParams
from auvplan.vehicle.propulsion import thrust_coefficient, torque_coefficient
from auvplan.vehicle.trim import bollard, trim_surge

#: Orders tabulated by default.
DEFAULT_ORDERS: Final = (1, 3, 5, 10, 20)
#: Cruise speeds at which the effect on steady power is measured [m/s].
CRUISE_SPEEDS: Final = (0.5, 1.0)
#: Smoothing small enough to be negligible at the checked operating points.
_NEGLIGIBLE_EPS: Final = 1e-9


@dataclass(frozen=True)
class ApproximationError:
    """Error of the order-``K`` truncated series against the full series."""

    order: int
    """Harmonics kept, ``K`` [-]."""
    rms_thrust_coefficient: float
    """RMS of ``ΔC_T*`` over ``β ∈ [-π, π)`` [-]."""
    max_thrust_coefficient: float
    """Maximum ``|ΔC_T*|`` over ``β`` [-]."""
    rms_torque_coefficient: float
    """RMS of ``ΔC_Q*`` [-]."""
    max_torque_coefficient: float
    """Maximum ``|ΔC_Q*|`` [-]."""
    bollard_thrust: float
    """Relative change of bollard thrust at ``n_max`` [-]."""
    bollard_torque: float
    """Relative change of bollard torque at ``n_max`` [-]."""
    propulsion_power: tuple[float, ...]
    """Relative change of steady propulsion power (electrical, without hotel load) at
    :data:`CRUISE_SPEEDS` [-]."""


@dataclass(frozen=True)
class SmoothingEffect:
    """Relative change caused by the smoothing at one operating point."""

    condition: str
    """``"bollard"`` or ``"cruise u m/s"``."""
    thrust: float
    """Relative change of thrust per propeller [-]."""
    torque: float
    """Relative change of torque per propeller [-]."""
    power: float
    """Relative change of electrical propulsion power (without hotel load) [-]."""


def _propulsion_power(model: VehicleModel, speed: float) -> float:
    return trim_surge(model, speed).power - model.vehicle.hotel_power


def approximation_error_table(
    params: VehicleParams | ActuatedVehicleParams,
    orders: Sequence[int] = DEFAULT_ORDERS,
    *,
    n_beta: int = 7200,
) -> tuple[ApproximationError, ...]:
    """Tabulate the error of truncated propeller series against the full series.

    Parameters
    ----------
    params : VehicleParams or ActuatedVehicleParams
        Vehicle (its first propeller's four-quadrant table is the reference at full order).
    orders : sequence of int
        Orders ``K`` to tabulate.
    n_beta : int
        Number of equally spaced advance angles in ``[-π, π)``.

    Returns
    -------
    tuple of ApproximationError
        One row per order.

    Raises
    ------
    InputError
        If the first propeller has no four-quadrant series.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> row = approximation_error_table(load_vehicle("medusa"), [1])[0]
    >>> round(row.rms_thrust_coefficient, 3), round(row.max_thrust_coefficient, 3)
    (0.093, 0.253)
    """
    propeller = params.propeller
    if not isinstance(propeller, PropellerParams):
        raise InputError(f"propeller {propeller.name!r} has no four-quadrant series to truncate")
    beta = np.linspace(-np.pi, np.pi, n_beta, endpoint=False)
    full_order = propeller.max_order
    reference_t = thrust_coefficient(beta, propeller, order=full_order)
    reference_q = torque_coefficient(beta, propeller, order=full_order)
    reference_model = build_vehicle_model(params, propeller_order=full_order)
    reference_pull = bollard(reference_model)
    reference_power = [_propulsion_power(reference_model, u) for u in CRUISE_SPEEDS]
    rows = []
    for order in orders:
        delta_t = thrust_coefficient(beta, propeller, order=order) - reference_t
        delta_q = torque_coefficient(beta, propeller, order=order) - reference_q
        model = build_vehicle_model(params, propeller_order=order)
        pull = bollard(model)
        power = [_propulsion_power(model, u) for u in CRUISE_SPEEDS]
        rows.append(
            ApproximationError(
                order=int(order),
                rms_thrust_coefficient=float(np.sqrt(np.mean(delta_t**2))),
                max_thrust_coefficient=float(np.max(np.abs(delta_t))),
                rms_torque_coefficient=float(np.sqrt(np.mean(delta_q**2))),
                max_torque_coefficient=float(np.max(np.abs(delta_q))),
                bollard_thrust=pull.thrust / reference_pull.thrust - 1.0,
                bollard_torque=pull.torque / reference_pull.torque - 1.0,
                propulsion_power=tuple(
                    p / p0 - 1.0 for p, p0 in zip(power, reference_power, strict=True)
                ),
            )
        )
    return tuple(rows)


def smoothing_effect(params: VehicleParams | ActuatedVehicleParams) -> tuple[SmoothingEffect, ...]:
    """Relative effect of the smoothing constants at bollard and at the cruise speeds.

    Compares the model built from ``params`` with the same model whose four smoothing
    constants are 1e-9 (the unsmoothed model at these operating points, which are away from
    ``v_a = v_p = 0``).

    Returns
    -------
    tuple of SmoothingEffect
        Rows for bollard and each of :data:`CRUISE_SPEEDS`.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> rows = smoothing_effect(load_vehicle("medusa"))
    >>> all(abs(row.thrust) < 1e-3 and abs(row.power) < 1e-3 for row in rows)
    True
    """
    sharp = dataclasses.replace(
        params,
        eps_inflow=_NEGLIGIBLE_EPS,
        eps_abs_speed=_NEGLIGIBLE_EPS,
        eps_abs_rate=_NEGLIGIBLE_EPS,
        eps_sign_n=_NEGLIGIBLE_EPS,
    )
    smooth_model = build_vehicle_model(params)
    sharp_model = build_vehicle_model(sharp)
    bollard_state = operating_state(
        smooth_model, throttle=actuator_roles(smooth_model).throttle_max
    )
    rows = [_effect_at("bollard", bollard_state, smooth_model, sharp_model)]
    for speed in CRUISE_SPEEDS:
        # same state (the sharp model's trim) for thrust/torque; each model's own trim for power
        n = trim_surge(sharp_model, speed).n
        state = operating_state(smooth_model, u=speed, throttle=n)
        row = _effect_at(f"cruise {speed} m/s", state, smooth_model, sharp_model)
        power = _propulsion_power(smooth_model, speed) / _propulsion_power(sharp_model, speed)
        rows.append(dataclasses.replace(row, power=power - 1.0))
    return tuple(rows)


def _effect_at(
    condition: str, state: np.ndarray, smooth: VehicleModel, sharp: VehicleModel
) -> SmoothingEffect:
    first_torque = len(smooth.vehicle.thrusters)  # outputs: thrusts, then torques
    smooth_out = [float(v) for v in smooth.thrust_torque(state)]
    sharp_out = [float(v) for v in sharp.thrust_torque(state)]
    t_smooth, q_smooth = smooth_out[0], smooth_out[first_torque]
    t_sharp, q_sharp = sharp_out[0], sharp_out[first_torque]
    zero = np.zeros(smooth.n_u)
    hotel = smooth.vehicle.hotel_power
    p_smooth = float(smooth.power(state, zero)) - hotel
    p_sharp = float(sharp.power(state, zero)) - hotel
    return SmoothingEffect(
        condition=condition,
        thrust=t_smooth / t_sharp - 1.0,
        torque=q_smooth / q_sharp - 1.0,
        power=p_smooth / p_sharp - 1.0,
    )


__all__ = [
    "CRUISE_SPEEDS",
    "DEFAULT_ORDERS",
    "ApproximationError",
    "SmoothingEffect",
    "approximation_error_table",
    "smoothing_effect",
]
