"""Speed and acceleration ranges a vehicle can usefully fly, derived from its model.

These bound the time laws the deconfliction hands to the optimiser (so that the initial guess
is flyable):

- **minimum useful speed** — the slowest steady speed whose electrical energy per metre is at
  most ``USEFUL_ENERGY_FACTOR`` times the optimum cruise's: below it the hotel load ``P_b/u``
  dominates and creeping costs more than waiting still; also the speed at which the propellers
  still have a controllable thrust derivative (``∂T/∂n ∝ |n|`` vanishes at rest);
- **maximum surge acceleration** — ``ACCELERATION_SHARE`` of the bollard thrust of all
  propellers over the surge mass ``m − X_u̇``, keeping the rest for steering and disturbance
  rejection.
"""

from __future__ import annotations

from functools import cache
from typing import Final

from scipy.optimize import brentq

from auvplan.vehicle.dynamics import VehicleModel
from auvplan.vehicle.trim import bollard, energy_per_metre, optimal_cruise_speed, trim_surge

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


def regulator_floor(model: VehicleModel) -> dict[str, float]:
    """Smallest state magnitudes the tracking regulator is designed at, by state name.

    The propeller speeds are floored at the steady-surge trim of the minimum useful speed:
    at rest ``∂T/∂n = 0`` and a regulator designed there would invert a vanishing coupling.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> floor = regulator_floor(build_vehicle_model(load_vehicle("medusa")))
    >>> sorted(floor), 5.0 < floor["n_ps"] < 20.0
    (['n_ps', 'n_sb'], True)
    """
    propeller = trim_surge(model, minimum_useful_speed(model)).n
    return {name: propeller for name, _ in model.state_limits}


@cache
def max_surge_acceleration(model: VehicleModel) -> float:
    """``ACCELERATION_SHARE`` × bollard thrust of both propellers / ``(m − X_u̇)`` [m/s²].

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> 0.5 < max_surge_acceleration(build_vehicle_model(load_vehicle("medusa"))) < 5.0
    True
    """
    n_propellers = len(model.state_limits)  # one limited speed state per propeller
    return ACCELERATION_SHARE * n_propellers * bollard(model).thrust / model.params.hull.m_u


__all__ = [
    "ACCELERATION_SHARE",
    "USEFUL_ENERGY_FACTOR",
    "max_surge_acceleration",
    "minimum_useful_speed",
    "regulator_floor",
]
