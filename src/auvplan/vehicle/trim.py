"""Steady states of the vehicle: straight-line trim, steady turns, limits, energy-optimal cruise.

All equilibria solve ``ν̇ = 0`` of the full (smooth) model of
:func:`auvplan.vehicle.dynamics.build_vehicle_model` with the actuator states held constant
(``c = 0``), so they are consistent with what the optimiser sees. The actuators are set by a
throttle and a steering fraction (:mod:`auvplan.vehicle.operating`), so every function works
for any actuator layout.
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from auvplan._typing import FloatArray
from auvplan.errors import InfeasibleError, InputError, SolverError
from auvplan.vehicle._steady import (
    CHARACTERISTIC_UNITS,
    BollardPull,
    CruiseOptimum,
    SteadyMotion,
    SteadyTurn,
    SurgeTrim,
    TurnTrim,
    VehicleCharacteristics,
    nu_dot,
    solve_equilibrium,
    steady_power,
)
from auvplan.vehicle.dynamics import VehicleModel
from auvplan.vehicle.operating import (
    FIRST_ACTUATOR,
    ActuatorRoles,
    actuator_roles,
    mean_throttle,
    operating_state,
    steer_fraction,
)

_MIN_CRUISE_SPEED = 0.05  # m/s, lower end of the cruise-speed search


def trim_surge(model: VehicleModel, speed: float) -> SurgeTrim:
    """Propeller speed and electrical power of steady straight motion at surge ``speed``.

    Solves ``u̇(u, v=0, r=0, throttle n) = 0`` for ``n`` (Brent's method).

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
        return SurgeTrim(0.0, steady_power(model, operating_state(model)))

    def surge_acceleration(n: float) -> float:
        return float(nu_dot(model, operating_state(model, u=speed, throttle=n))[0])

    limit = 4.0 * actuator_roles(model).throttle_max * math.copysign(1.0, speed)
    if surge_acceleration(limit) * surge_acceleration(0.0) > 0.0:
        raise InfeasibleError(
            f"no propeller speed within ±{abs(limit):.0f} rev/s holds surge speed {speed} m/s"
        )
    n = float(brentq(surge_acceleration, 0.0, limit, xtol=1e-10, rtol=1e-12))
    return SurgeTrim(n, steady_power(model, operating_state(model, u=speed, throttle=n)))


def steady_motion(model: VehicleModel, *actuators: float) -> SteadyMotion:
    """Steady body velocities ``(u, v, r)`` with every actuator state held fixed.

    Solved from a few starting points (the first equilibrium found is returned; with an
    unstable hull there can be more than one, e.g. an unstable straight-ish motion and a
    stable tight turn).

    Parameters
    ----------
    model : VehicleModel
        Model.
    *actuators : float
        The actuator states in the model's order: propeller speeds [rev/s], then control-
        surface deflections [rad] (MEDUSA: ``n_ps, n_sb``).

    Returns
    -------
    SteadyMotion

    Raises
    ------
    InputError
        If the number of actuator states is wrong.
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
    settings = np.asarray(actuators, dtype=np.float64)
    if settings.shape != (model.n_x - FIRST_ACTUATOR,):
        raise InputError(
            f"steady_motion needs {model.n_x - FIRST_ACTUATOR} actuator states "
            f"{model.state_names[FIRST_ACTUATOR:]}, got {settings.size}"
        )

    def state_of(nu: FloatArray) -> FloatArray:
        return np.concatenate([np.zeros(3), nu, settings])

    guess_u = top_speed(model) * mean_throttle(model, settings) / actuator_roles(model).throttle_max
    guess_r = steer_fraction(model, settings)
    turn = math.copysign(1.0, guess_r) if guess_r != 0.0 else 1.0
    # multi-start: with DSOR's MEDUSA hull (m_v > m_u) straight motion is directionally
    # unstable above ~0.7 m/s and a small differential gives a tight steady turn
    guesses = [
        (guess_u, 0.0, r0) for r0 in (guess_r, *(k * turn for k in (0.1, 0.3, 0.6, 1.0, -0.3)))
    ]
    u, v, r = (
        float(value)
        for value in solve_equilibrium(
            model, state_of, guesses, f"steady motion for actuators {settings.tolist()}"
        )
    )
    return SteadyMotion(u, v, r)


def steady_turn(model: VehicleModel, speed: float, yaw_rate: float) -> SteadyTurn:
    """Steady turn at surge ``speed`` and ``yaw_rate``: throttle, steering and sway solved.

    Solves ``ν̇ = 0`` for the throttle, the steering fraction and ``v`` with ``u`` and ``r``
    fixed (:mod:`auvplan.vehicle.operating`); the steering may exceed full deflection when
    the turn is tighter than the vehicle can fly.

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
    SteadyTurn

    Raises
    ------
    InputError
        If the vehicle has no steering actuator.
    SolverError
        If the nonlinear solve does not converge.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> round(steady_turn(build_vehicle_model(load_vehicle("medusa")), 0.5, 0.1).radius, 2)
    5.02
    """
    _check_steering(model)

    def state_of(z: FloatArray) -> FloatArray:
        return operating_state(model, u=speed, v=z[2], r=yaw_rate, throttle=z[0], steer=z[1])

    throttle = trim_surge(model, speed).n if speed != 0.0 else 1.0
    turn = math.copysign(1.0, yaw_rate) if yaw_rate != 0.0 else 1.0
    first = yaw_rate / max_yaw_rate(model)
    guesses = [(throttle, s0, 0.0) for s0 in (first, *(k * turn for k in (0.05, 0.2, 0.5, 1.0)))]
    solution = solve_equilibrium(
        model, state_of, guesses, f"steady turn at u = {speed} m/s, r = {yaw_rate} rad/s"
    )
    state = state_of(solution)
    return SteadyTurn(state, steady_power(model, state))


def trim_turn(model: VehicleModel, speed: float, yaw_rate: float) -> TurnTrim:
    """Propeller speeds, sway and power of a twin-thruster vehicle's steady turn.

    :func:`steady_turn` reported as ``(n_ps, n_sb, v, power)``.

    Raises
    ------
    InputError
        If the vehicle's actuators are not the twin thrusters ``n_ps``, ``n_sb``.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> turn = trim_turn(build_vehicle_model(load_vehicle("medusa")), 0.5, 0.1)
    >>> turn.n_ps > turn.n_sb
    True
    """
    if model.state_names[FIRST_ACTUATOR:] != ("n_ps", "n_sb"):
        raise InputError(
            f"trim_turn reports twin thrusters n_ps, n_sb; vehicle {model.vehicle.name!r} has "
            f"{model.state_names[FIRST_ACTUATOR:]} (use steady_turn)"
        )
    turn = steady_turn(model, speed, yaw_rate)
    n_ps, n_sb = (float(value) for value in turn.state[FIRST_ACTUATOR:])
    return TurnTrim(n_ps, n_sb, float(turn.state[4]), turn.power)


def tightest_turn(model: VehicleModel, speed: float) -> SteadyTurn:
    """Steady turn at surge ``speed`` with full steering to starboard.

    Control surfaces at full deflection, the throttle holding ``speed``; a vehicle steering
    by differential thrust keeps its outer thrusters at ``n_max`` (steering fraction
    ``1 - n/n_max``). Its :attr:`SteadyTurn.radius` is the turning radius at that speed.

    Raises
    ------
    InputError
        If the vehicle has no steering actuator.
    SolverError
        If the nonlinear solve does not converge.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> round(tightest_turn(build_vehicle_model(load_vehicle("medusa")), 0.5).radius, 2)
    0.65
    """
    roles = _check_steering(model)

    def state_of(z: FloatArray) -> FloatArray:
        steer = 1.0 - z[0] / roles.throttle_max if roles.thrust_steering else 1.0
        return operating_state(model, u=speed, v=z[1], r=z[2], throttle=z[0], steer=steer)

    throttle = trim_surge(model, speed).n
    guesses = [(throttle, 0.0, r0) for r0 in (0.1, 0.3, 0.6, 1.0, 2.0)]
    solution = solve_equilibrium(model, state_of, guesses, f"full-steering turn at u = {speed} m/s")
    state = state_of(solution)
    return SteadyTurn(state, steady_power(model, state))


def _check_steering(model: VehicleModel) -> ActuatorRoles:
    roles = actuator_roles(model)
    if not roles.can_steer:
        raise InputError(f"vehicle {model.vehicle.name!r} has no steering actuator")
    return roles


@cache
def top_speed(model: VehicleModel) -> float:
    """Steady straight-line speed with the forward propellers at ``n_max`` [m/s] (cached).

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> round(top_speed(build_vehicle_model(load_vehicle("medusa"))), 2)
    1.48
    """
    n_max = actuator_roles(model).throttle_max

    def surge_acceleration(u: float) -> float:
        return float(nu_dot(model, operating_state(model, u=u, throttle=n_max))[0])

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
    roles = actuator_roles(model)
    state = operating_state(model, throttle=roles.throttle_max)
    outputs = [float(value) for value in model.thrust_torque(state)]
    first = int(np.argmax(roles.throttle))
    n_thrusters = len(model.vehicle.thrusters)
    return BollardPull(outputs[first], outputs[n_thrusters + first], steady_power(model, state))


@cache
def max_yaw_rate(model: VehicleModel) -> float:
    """Steady yaw rate at full steering to starboard [rad/s] (cached per model).

    Differential-thrust vehicles turn on the spot (steering thrusters at ``±n_max``, MEDUSA:
    port ``+n_max``, starboard ``-n_max``); vehicles with control surfaces turn at full
    deflection with the propellers at ``n_max``. The full steady state ``(u, v, r)`` is
    solved (the four-quadrant model gives less reverse than forward thrust, so MEDUSA also
    creeps ahead).

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> 0.8 < max_yaw_rate(build_vehicle_model(load_vehicle("medusa"))) < 1.1
    True
    """
    roles = _check_steering(model)
    throttle = 0.0 if roles.thrust_steering else roles.throttle_max
    state = operating_state(model, throttle=throttle, steer=1.0)
    return steady_motion(model, *state[FIRST_ACTUATOR:]).r


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
            f"vehicle {model.vehicle.name!r} tops out at {upper:.3g} m/s, below the "
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
    battery = model.vehicle.battery_capacity
    return VehicleCharacteristics(
        name=model.vehicle.name,
        propeller_order=model.propeller_order,
        n_max=actuator_roles(model).throttle_max,
        bollard_thrust=pull.thrust,
        bollard_torque=pull.torque,
        bollard_power=pull.power,
        top_speed=top_speed(model),
        cruise_speed=cruise.speed,
        cruise_energy_per_metre=cruise.energy_per_metre,
        hotel_power=model.vehicle.hotel_power,
        power_at_0_5=slow.power,
        power_at_1_0=fast.power,
        n_at_0_5=slow.n,
        n_at_1_0=fast.n,
        max_yaw_rate=max_yaw_rate(model),
        turning_radius=tightest_turn(model, cruise.speed).radius,
        climb_rate=model.vehicle.depth_limits.climb_rate,
        dive_rate=model.vehicle.depth_limits.dive_rate,
        min_altitude=model.vehicle.depth_limits.min_altitude,
        battery_capacity=battery,
        cruise_range=None if battery is None else battery / cruise.energy_per_metre,
    )


__all__ = [
    "CHARACTERISTIC_UNITS",
    "BollardPull",
    "CruiseOptimum",
    "SteadyMotion",
    "SteadyTurn",
    "SurgeTrim",
    "TurnTrim",
    "VehicleCharacteristics",
    "bollard",
    "energy_per_metre",
    "max_yaw_rate",
    "optimal_cruise_speed",
    "steady_motion",
    "steady_turn",
    "tightest_turn",
    "top_speed",
    "trim_surge",
    "trim_turn",
    "vehicle_characteristics",
]
