"""Steady states of the vehicle: straight-line trim, steady turns, limits, energy-optimal cruise.

All equilibria solve ``ν̇ = 0`` of the full (smooth) model of
:func:`auvplan.vehicle.dynamics.build_vehicle_model` with the propeller speeds held constant
(``c = 0``), so they are consistent with what the optimiser sees.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from functools import cache
from typing import NamedTuple

import casadi as ca
import numpy as np
from scipy.optimize import brentq, minimize_scalar, root

from auvplan._typing import FloatArray
from auvplan.errors import InfeasibleError, InputError, SolverError
from auvplan.vehicle.dynamics import VehicleModel

_NU = slice(3, 6)
_MIN_CRUISE_SPEED = 0.05  # m/s, lower end of the cruise-speed search


class SurgeTrim(NamedTuple):
    """Straight-line trim: both propellers at ``n``."""

    n: float
    """Propeller speed (both) [rev/s]; may exceed ``n_max`` above the top speed."""
    power: float
    """Electrical power including the hotel load [W]."""


class TurnTrim(NamedTuple):
    """Steady turn at a given surge speed and yaw rate."""

    n_ps: float
    """Port propeller speed [rev/s]."""
    n_sb: float
    """Starboard propeller speed [rev/s]."""
    v: float
    """Steady sway speed [m/s]."""
    power: float
    """Electrical power including the hotel load [W]."""


class SteadyMotion(NamedTuple):
    """Steady body velocities for fixed propeller speeds."""

    u: float
    """Surge speed [m/s]."""
    v: float
    """Sway speed [m/s]."""
    r: float
    """Yaw rate [rad/s]."""


class BollardPull(NamedTuple):
    """Thrust and torque of one propeller at ``n_max`` with the vehicle held at rest."""

    thrust: float
    """Thrust per propeller [N]."""
    torque: float
    """Shaft torque per propeller [N m]."""
    power: float
    """Electrical power of the vehicle, both motors at ``n_max`` plus hotel load [W]."""


class CruiseOptimum(NamedTuple):
    """Energy-optimal straight-line cruise."""

    speed: float
    """Surge speed minimising energy per metre [m/s]."""
    energy_per_metre: float
    """``P(u)/u`` at that speed [J/m]."""


def _state(u: float, v: float, r: float, n_ps: float, n_sb: float) -> FloatArray:
    return np.array([0.0, 0.0, 0.0, u, v, r, n_ps, n_sb])


def _nu_dot(model: VehicleModel, state: FloatArray) -> FloatArray:
    return np.asarray(model.dynamics(state, np.zeros(model.n_u)), dtype=np.float64).ravel()[_NU]


def _power(model: VehicleModel, state: FloatArray) -> float:
    return float(model.power(state, np.zeros(model.n_u)))


def _jacobian(model: VehicleModel) -> ca.Function:
    x = ca.SX.sym("x", model.n_x)
    xdot = model.dynamics(x, ca.SX.zeros(model.n_u))
    return ca.Function("f_x", [x], [ca.jacobian(xdot, x)])


def trim_surge(model: VehicleModel, speed: float) -> SurgeTrim:
    """Propeller speed and electrical power of steady straight motion at surge ``speed``.

    Solves ``u̇(u, v=0, r=0, n, n) = 0`` for ``n`` (Brent's method).

    Parameters
    ----------
    model : VehicleModel
        Model.
    speed : float
        Surge speed [m/s] (negative: astern).

    Returns
    -------
    SurgeTrim
        ``(n, power)`` [rev/s, W].

    Raises
    ------
    InfeasibleError
        If no propeller speed up to ``4 n_max`` holds that speed.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> n, power = trim_surge(build_vehicle_model(load_vehicle("medusa")), 1.0)
    >>> round(n, 1), round(power)
    (50.6, 158)
    """
    if not math.isfinite(speed):
        raise InputError(f"speed must be finite, got {speed!r}")
    if speed == 0.0:
        return SurgeTrim(0.0, _power(model, _state(0.0, 0.0, 0.0, 0.0, 0.0)))

    def surge_acceleration(n: float) -> float:
        return float(_nu_dot(model, _state(speed, 0.0, 0.0, n, n))[0])

    limit = 4.0 * model.params.n_max * math.copysign(1.0, speed)
    if surge_acceleration(limit) * surge_acceleration(0.0) > 0.0:
        raise InfeasibleError(
            f"no propeller speed within ±{abs(limit):.0f} rev/s holds surge speed {speed} m/s"
        )
    n = float(brentq(surge_acceleration, 0.0, limit, xtol=1e-10, rtol=1e-12))
    return SurgeTrim(n, _power(model, _state(speed, 0.0, 0.0, n, n)))


def steady_motion(model: VehicleModel, n_ps: float, n_sb: float) -> SteadyMotion:
    """Steady body velocities ``(u, v, r)`` with both propeller speeds held fixed.

    Solved from a few starting points (the first equilibrium found is returned; with an
    unstable hull there can be more than one, e.g. an unstable straight-ish motion and a
    stable tight turn).

    Parameters
    ----------
    model : VehicleModel
        Model.
    n_ps, n_sb : float
        Port and starboard propeller speeds [rev/s].

    Returns
    -------
    SteadyMotion

    Raises
    ------
    SolverError
        If the nonlinear solve does not converge.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> motion = steady_motion(build_vehicle_model(load_vehicle("medusa")), 50.0, 50.0)
    >>> round(motion.u, 3), round(motion.r, 6)
    (0.989, 0.0)
    """
    jacobian = _jacobian(model)

    def residual(nu: FloatArray) -> FloatArray:
        return _nu_dot(model, _state(nu[0], nu[1], nu[2], n_ps, n_sb))

    def residual_jacobian(nu: FloatArray) -> FloatArray:
        full = np.asarray(jacobian(_state(nu[0], nu[1], nu[2], n_ps, n_sb)), dtype=np.float64)
        return full[_NU, _NU]

    mean_n = 0.5 * (n_ps + n_sb)
    guess_u = math.copysign(1.0, mean_n) * min(abs(mean_n) / 50.0, 1.5)
    guess_r = (n_ps - n_sb) / (2.0 * model.params.n_max)
    turn = math.copysign(1.0, guess_r) if guess_r != 0.0 else 1.0
    # multi-start: with DSOR's MEDUSA hull (m_v > m_u) straight motion is directionally
    # unstable above ~0.7 m/s and a small differential gives a tight steady turn
    message = ""
    for r0 in (guess_r, 0.1 * turn, 0.3 * turn, 0.6 * turn, 1.0 * turn, -0.3 * turn):
        solution = root(residual, np.array([guess_u, 0.0, r0]), jac=residual_jacobian, tol=1e-12)
        if solution.success and np.max(np.abs(residual(solution.x))) <= 1e-8:
            u, v, r = (float(value) for value in solution.x)
            return SteadyMotion(u, v, r)
        message = str(solution.message)
    raise SolverError(f"steady motion for n = ({n_ps}, {n_sb}) rev/s did not converge: {message}")


def trim_turn(model: VehicleModel, speed: float, yaw_rate: float) -> TurnTrim:
    """Propeller speeds, sway and power of a steady turn at surge ``speed`` and ``yaw_rate``.

    Solves ``ν̇ = 0`` for ``(n_ps, n_sb, v)`` with ``u`` and ``r`` fixed.

    Parameters
    ----------
    model : VehicleModel
        Model.
    speed : float
        Surge speed [m/s].
    yaw_rate : float
        Yaw rate [rad/s] (> 0 turns to starboard).

    Returns
    -------
    TurnTrim

    Raises
    ------
    SolverError
        If the nonlinear solve does not converge.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> turn = trim_turn(build_vehicle_model(load_vehicle("medusa")), 0.5, 0.1)
    >>> turn.n_ps > turn.n_sb
    True
    """
    jacobian = _jacobian(model)
    columns = [6, 7, 4]  # n_ps, n_sb, v

    def residual(z: FloatArray) -> FloatArray:
        return _nu_dot(model, _state(speed, z[2], yaw_rate, z[0], z[1]))

    def residual_jacobian(z: FloatArray) -> FloatArray:
        full = np.asarray(jacobian(_state(speed, z[2], yaw_rate, z[0], z[1])), dtype=np.float64)
        return full[_NU][:, columns]

    n_straight = trim_surge(model, speed).n if speed != 0.0 else 1.0
    guess = np.array([n_straight + 5.0 * yaw_rate, n_straight - 5.0 * yaw_rate, 0.0])
    solution = root(residual, guess, jac=residual_jacobian, tol=1e-12)
    if not solution.success or np.max(np.abs(residual(solution.x))) > 1e-8:
        raise SolverError(
            f"steady turn at u = {speed} m/s, r = {yaw_rate} rad/s did not converge: "
            f"{solution.message}"
        )
    n_ps, n_sb, v = (float(value) for value in solution.x)
    return TurnTrim(n_ps, n_sb, v, _power(model, _state(speed, v, yaw_rate, n_ps, n_sb)))


@cache
def top_speed(model: VehicleModel) -> float:
    """Steady straight-line speed with both propellers at ``n_max`` [m/s] (cached per model).

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> round(top_speed(build_vehicle_model(load_vehicle("medusa"))), 2)
    1.48
    """
    n_max = model.params.n_max

    def surge_acceleration(u: float) -> float:
        return float(_nu_dot(model, _state(u, 0.0, 0.0, n_max, n_max))[0])

    upper = 1.0
    while surge_acceleration(upper) > 0.0:
        upper *= 2.0
        if upper > 1e3:
            raise SolverError("top speed search diverged (no drag?)")
    return float(brentq(surge_acceleration, 0.0, upper, xtol=1e-12, rtol=1e-12))


def bollard(model: VehicleModel) -> BollardPull:
    """Thrust and torque per propeller at ``n_max`` with the vehicle at rest.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> pull = bollard(build_vehicle_model(load_vehicle("medusa")))
    >>> round(pull.thrust, 1), round(pull.torque, 3)
    (36.1, 0.442)
    """
    n_max = model.params.n_max
    state = _state(0.0, 0.0, 0.0, n_max, n_max)
    thrust, _, torque, _ = model.thrust_torque(state)
    return BollardPull(float(thrust), float(torque), _power(model, state))


def max_yaw_rate(model: VehicleModel) -> float:
    """Steady yaw rate turning on the spot: port at ``+n_max``, starboard at ``-n_max`` [rad/s].

    The full steady state ``(u, v, r)`` is solved (the four-quadrant model gives less
    reverse than forward thrust, so the vehicle also creeps ahead).

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> 0.8 < max_yaw_rate(build_vehicle_model(load_vehicle("medusa"))) < 1.1
    True
    """
    n_max = model.params.n_max
    return steady_motion(model, n_max, -n_max).r


def energy_per_metre(model: VehicleModel, speed: float) -> float:
    """Electrical energy per metre ``P(u)/u`` of steady straight motion [J/m].

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> round(energy_per_metre(build_vehicle_model(load_vehicle("medusa")), 1.0))
    158
    """
    if not speed > 0.0:
        raise InputError(f"speed must be > 0 for energy per metre, got {speed!r}")
    return trim_surge(model, speed).power / speed


def optimal_cruise_speed(model: VehicleModel) -> CruiseOptimum:
    """Surge speed that minimises electrical energy per metre, ``min_u P(u)/u``.

    The hotel load makes the optimum finite: ``P_b/u`` dominates at low speed and the
    propulsion power (∝ u³) at high speed. Searched on ``[0.05 m/s, top speed]``.

    Returns
    -------
    CruiseOptimum
        ``(speed [m/s], energy_per_metre [J/m])``.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> speed, cost = optimal_cruise_speed(build_vehicle_model(load_vehicle("medusa")))
    >>> 0.5 < speed < 1.0
    True
    """
    upper = top_speed(model)
    if upper <= _MIN_CRUISE_SPEED:
        raise InputError(
            f"vehicle {model.params.name!r} tops out at {upper:.3g} m/s, below the "
            f"{_MIN_CRUISE_SPEED:g} m/s a cruise speed is searched from; check its thrust and drag"
        )
    result = minimize_scalar(
        lambda u: energy_per_metre(model, float(u)),
        bounds=(_MIN_CRUISE_SPEED, upper),
        method="bounded",
        options={"xatol": 1e-6},
    )
    speed = float(result.x)
    return CruiseOptimum(speed, energy_per_metre(model, speed))


@dataclass(frozen=True)
class VehicleCharacteristics:
    """Headline numbers of a vehicle type (what ``auvplan vehicle`` prints)."""

    name: str
    """Vehicle type."""
    propeller_order: int
    """Harmonics of the propeller series used [-]."""
    n_max: float
    """Maximum propeller speed [rev/s]."""
    bollard_thrust: float
    """Thrust per propeller at ``n_max``, vehicle at rest [N]."""
    bollard_torque: float
    """Torque per propeller at ``n_max``, vehicle at rest [N m]."""
    bollard_power: float
    """Electrical power at bollard, both motors plus hotel load [W]."""
    top_speed: float
    """Straight-line speed at ``n_max`` [m/s]."""
    cruise_speed: float
    """Energy-optimal cruise speed [m/s]."""
    cruise_energy_per_metre: float
    """Energy per metre at the cruise speed [J/m]."""
    hotel_power: float
    """Hotel load included in every power [W]."""
    power_at_0_5: float
    """Steady electrical power at 0.5 m/s (with hotel load) [W]."""
    power_at_1_0: float
    """Steady electrical power at 1.0 m/s (with hotel load) [W]."""
    n_at_0_5: float
    """Propeller speed at 0.5 m/s [rev/s]."""
    n_at_1_0: float
    """Propeller speed at 1.0 m/s [rev/s]."""
    max_yaw_rate: float
    """Steady yaw rate turning on the spot at ``±n_max`` [rad/s]."""

    def to_dict(self) -> dict[str, float | int | str]:
        """Plain dictionary (JSON-ready), SI units as documented per field.

        Examples
        --------
        >>> from auvplan.io.vehicles import load_vehicle
        >>> from auvplan.vehicle.dynamics import build_vehicle_model
        >>> table = vehicle_characteristics(build_vehicle_model(load_vehicle("medusa"))).to_dict()
        >>> table["name"], round(float(table["top_speed"]), 2)
        ('medusa', 1.48)
        """
        return dict(asdict(self))


def vehicle_characteristics(model: VehicleModel) -> VehicleCharacteristics:
    """Compute all headline numbers of a vehicle model.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> vehicle_characteristics(build_vehicle_model(load_vehicle("medusa"))).name
    'medusa'
    """
    pull = bollard(model)
    cruise = optimal_cruise_speed(model)
    slow = trim_surge(model, 0.5)
    fast = trim_surge(model, 1.0)
    return VehicleCharacteristics(
        name=model.params.name,
        propeller_order=model.propeller_order,
        n_max=model.params.n_max,
        bollard_thrust=pull.thrust,
        bollard_torque=pull.torque,
        bollard_power=pull.power,
        top_speed=top_speed(model),
        cruise_speed=cruise.speed,
        cruise_energy_per_metre=cruise.energy_per_metre,
        hotel_power=model.params.hotel_power,
        power_at_0_5=slow.power,
        power_at_1_0=fast.power,
        n_at_0_5=slow.n,
        n_at_1_0=fast.n,
        max_yaw_rate=max_yaw_rate(model),
    )


__all__ = [
    "BollardPull",
    "CruiseOptimum",
    "SteadyMotion",
    "SurgeTrim",
    "TurnTrim",
    "VehicleCharacteristics",
    "bollard",
    "energy_per_metre",
    "max_yaw_rate",
    "optimal_cruise_speed",
    "steady_motion",
    "top_speed",
    "trim_surge",
    "trim_turn",
    "vehicle_characteristics",
]
