"""Operating points: the actuator settings of straight motion and turns, from the actuator list.

Every steady manoeuvre the library solves for (trim, top speed, bollard pull, turns) sets
the actuators through two numbers:

- the **throttle** ``n`` [rev/s], the common speed of the thrusters that push forward
  (``cos α > 0``);
- the **steering** ``s`` [-], a fraction of full steering: each control surface at
  ``s δ_max`` (signed so that ``s > 0`` turns the bow to starboard); a vehicle without
  control surfaces steers by differential thrust, each thruster with a yaw arm adding
  ``±s n_max``.

For MEDUSA (two thrusters at ``y = ∓l``) this gives ``n_ps = n + s n_max``,
``n_sb = n - s n_max``; for a torpedo AUV with one propeller and a rudder, ``n_prop = n``,
``δ = s δ_max``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.vehicle.dynamics import BODY_STATE_NAMES, VehicleModel

#: Position of the first actuator state in every state vector.
FIRST_ACTUATOR: int = len(BODY_STATE_NAMES)
#: Shares and arms below this are rounding (e.g. ``cos 90°`` = 6e-17) [-, m].
_NEGLIGIBLE: float = 1e-9


@dataclass(frozen=True)
class ActuatorRoles:
    """How the throttle and the steering set each actuator state (module notes)."""

    throttle: FloatArray
    """1 for thrusters driven by the throttle, else 0; shape ``(n_actuators,)`` [-]."""
    steering: FloatArray
    """Actuator state at full starboard steering, shape ``(n_actuators,)`` [rev/s or rad]."""
    thrust_steering: bool
    """Whether the vehicle steers by differential thrust (it has no control surface)."""
    throttle_max: float
    """Largest throttle every throttle thruster can follow: their smallest ``n_max`` [rev/s]."""

    @property
    def can_steer(self) -> bool:
        """Whether any actuator steers."""
        return bool(np.any(self.steering != 0.0))


@cache
def actuator_roles(model: VehicleModel) -> ActuatorRoles:
    """The throttle and steering roles of a model's actuators (cached per model).

    Raises
    ------
    InputError
        If no thruster pushes forward (no throttle: no straight motion to trim).

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> roles = actuator_roles(build_vehicle_model(load_vehicle("medusa")))
    >>> roles.throttle.tolist(), roles.steering.tolist(), roles.thrust_steering
    ([1.0, 1.0], [75.0, -75.0], True)
    """
    thrusters, surfaces = model.vehicle.thrusters, model.vehicle.surfaces
    throttle = [1.0 if thruster.surge_share > _NEGLIGIBLE else 0.0 for thruster in thrusters]
    if not any(throttle):
        raise InputError(f"vehicle {model.vehicle.name!r} has no thruster pushing forward")
    thrust_steering = not surfaces
    steering = [
        math.copysign(thruster.n_max, thruster.yaw_arm)
        if thrust_steering and abs(thruster.yaw_arm) > _NEGLIGIBLE
        else 0.0
        for thruster in thrusters
    ] + [
        math.copysign(surface.delta_max, surface.yaw_arm)
        if abs(surface.yaw_arm) > _NEGLIGIBLE
        else 0.0
        for surface in surfaces
    ]
    limits = [thruster.n_max for thruster, on in zip(thrusters, throttle, strict=True) if on]
    return ActuatorRoles(
        throttle=np.array(throttle + [0.0] * len(surfaces)),
        steering=np.array(steering),
        thrust_steering=thrust_steering,
        throttle_max=min(limits),
    )


def operating_state(
    model: VehicleModel,
    *,
    u: float = 0.0,
    v: float = 0.0,
    r: float = 0.0,
    throttle: float = 0.0,
    steer: float = 0.0,
) -> FloatArray:
    """State at the origin, heading north, with body velocities and actuators as given.

    Parameters
    ----------
    model : VehicleModel
        Model.
    u, v, r : float
        Surge [m/s], sway [m/s] and yaw rate [rad/s].
    throttle : float
        Speed of the forward-pushing thrusters [rev/s].
    steer : float
        Fraction of full starboard steering [-] (module notes).

    Returns
    -------
    ndarray of shape (n_x,)

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> model = build_vehicle_model(load_vehicle("medusa"))
    >>> operating_state(model, u=1.0, throttle=50.0, steer=0.1).tolist()
    [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 57.5, 42.5]
    """
    roles = actuator_roles(model)
    state = np.zeros(model.n_x)
    state[3:FIRST_ACTUATOR] = u, v, r
    state[FIRST_ACTUATOR:] = throttle * roles.throttle + steer * roles.steering
    return state


def steer_fraction(model: VehicleModel, actuators: FloatArray) -> float:
    """Least-squares steering fraction of actuator states, shape ``(n_actuators,)`` [-].

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> steer_fraction(build_vehicle_model(load_vehicle("medusa")), np.array([75.0, -75.0]))
    1.0
    """
    steering = actuator_roles(model).steering
    norm = float(steering @ steering)
    return float(np.asarray(actuators) @ steering) / norm if norm > 0.0 else 0.0


def mean_throttle(model: VehicleModel, actuators: FloatArray) -> float:
    """Mean of actuator states over the throttle thrusters [rev/s].

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> mean_throttle(build_vehicle_model(load_vehicle("medusa")), np.array([60.0, 40.0]))
    50.0
    """
    mask = actuator_roles(model).throttle
    return float(np.asarray(actuators) @ mask / mask.sum())


__all__ = [
    "FIRST_ACTUATOR",
    "ActuatorRoles",
    "actuator_roles",
    "mean_throttle",
    "operating_state",
    "steer_fraction",
]
