"""Speed and acceleration ranges a vehicle can usefully fly, derived from its model.

These bound the time laws the deconfliction hands to the optimiser (so that the initial guess
is flyable):

- **minimum useful speed** — the slowest steady speed whose electrical energy per metre is at
  most ``USEFUL_ENERGY_FACTOR`` times the optimum cruise's: below it the hotel load ``P_b/u``
  dominates and creeping costs more than waiting still; also the speed at which the propellers
  still have a controllable thrust derivative (``∂T/∂n ∝ |n|`` vanishes at rest);
- **turning radius** — the tightest steady turn's radius over the useful speeds (the larger of
  those at the minimum useful speed and at the optimum cruise): a rudder-steered vehicle turns
  widest when slow, a differential-thrust one when fast;
- **maximum surge acceleration** — ``ACCELERATION_SHARE`` of the acceleration from rest with
  every forward-pushing propeller at ``n_max`` (their bollard force over the surge mass
  ``m − X_u̇``), keeping the rest for steering and disturbance rejection.
"""

from __future__ import annotations

from functools import cache
from typing import Final

import numpy as np
from scipy.optimize import brentq

from auvplan.vehicle.dynamics import VehicleModel
from auvplan.vehicle.operating import actuator_roles, operating_state
from auvplan.vehicle.trim import (
    energy_per_metre,
    optimal_cruise_speed,
    tightest_turn,
    trim_surge,
)

#: Energy per metre, relative to the optimum cruise, still counted as useful motion.
USEFUL_ENERGY_FACTOR: Final = 2.0
#: Share of the bollard thrust a planned speed change may use.
ACCELERATION_SHARE: Final = 0.5


@cache
def minimum_useful_speed(model: VehicleModel) -> float:
    """Slowest steady speed with ``P(u)/u <= USEFUL_ENERGY_FACTOR`` × the optimum [m/s].

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> round(minimum_useful_speed(build_vehicle_model(load_vehicle("medusa"))), 2)
    0.19
    """
    cruise = optimal_cruise_speed(model)
    limit = USEFUL_ENERGY_FACTOR * cruise.energy_per_metre

    def excess(speed: float) -> float:
        return energy_per_metre(model, speed) - limit

    lowest = 0.01 * cruise.speed
    if excess(lowest) <= 0.0:  # no hotel load: any speed is useful
        return lowest
    return float(brentq(excess, lowest, cruise.speed, xtol=1e-6))


@cache
def turning_radius(model: VehicleModel) -> float:
    """Radius [m] of the tightest steady turn at every useful speed (module notes).

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> round(turning_radius(build_vehicle_model(load_vehicle("medusa"))), 2)
    0.73
    """
    speeds = (minimum_useful_speed(model), optimal_cruise_speed(model).speed)
    return max(tightest_turn(model, speed).radius for speed in speeds)


def regulator_floor(model: VehicleModel) -> dict[str, float]:
    """Smallest state magnitudes the tracking regulator is designed at, by state name.

    The speeds of the forward-pushing propellers are floored at the steady-surge trim of the
    minimum useful speed: at rest ``∂T/∂n = 0`` and a regulator designed there would invert a
    vanishing coupling. Other actuators are not floored.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> floor = regulator_floor(build_vehicle_model(load_vehicle("medusa")))
    >>> sorted(floor), 5.0 < floor["n_ps"] < 20.0
    (['n_ps', 'n_sb'], True)
    """
    propeller = trim_surge(model, minimum_useful_speed(model)).n
    thrusters = model.vehicle.thrusters
    throttle = actuator_roles(model).throttle[: len(thrusters)]
    return {
        thruster.state_name: propeller
        for thruster, driven in zip(thrusters, throttle, strict=True)
        if driven
    }


@cache
def max_surge_acceleration(model: VehicleModel) -> float:
    """``ACCELERATION_SHARE`` × surge acceleration from rest at full throttle [m/s²].

    The acceleration is ``u̇`` of the model at rest with every forward-pushing propeller at
    ``n_max``: their bollard force along x over ``m − X_u̇``.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> 0.5 < max_surge_acceleration(build_vehicle_model(load_vehicle("medusa"))) < 5.0
    True
    """
    state = operating_state(model, throttle=actuator_roles(model).throttle_max)
    xdot = np.asarray(model.dynamics(state, np.zeros(model.n_u)), dtype=np.float64).ravel()
    return ACCELERATION_SHARE * float(xdot[model.index("u")])


__all__ = [
    "ACCELERATION_SHARE",
    "USEFUL_ENERGY_FACTOR",
    "max_surge_acceleration",
    "minimum_useful_speed",
    "regulator_floor",
]
