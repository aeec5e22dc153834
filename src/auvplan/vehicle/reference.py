"""Reference states of a vehicle moving along a timed path (the desired trajectory of stage 2).

A timed path gives the pose ``(north, east, ψ)``, the surge speed ``u`` and the yaw rate
``r`` at each instant. The matching state assumes no sway, the forward propellers at the speed
that holds ``u`` in steady straight motion (:func:`auvplan.vehicle.trim.trim_surge`),
interpolated in a table of ``TRIM_SAMPLES`` speeds from rest to top speed, and every other
actuator (steering) at zero, through :func:`auvplan.vehicle.operating.operating_state`.
"""

from __future__ import annotations

from functools import cache
from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.vehicle.dynamics import VehicleModel
from auvplan.vehicle.operating import FIRST_ACTUATOR, operating_state
from auvplan.vehicle.trim import top_speed, trim_surge

#: Samples of the steady-surge trim table (propeller speed against surge speed).
TRIM_SAMPLES: Final = 40


@cache
def surge_trim_table(model: VehicleModel) -> tuple[FloatArray, FloatArray]:
    """Steady-surge propeller speed (throttle) [rev/s] against surge speed [m/s], rest to top.

    Cached per model object.
    """
    speeds = np.linspace(0.0, top_speed(model), TRIM_SAMPLES)
    revolutions = np.array([trim_surge(model, float(speed)).n for speed in speeds])
    return speeds, revolutions


def reference_states(
    model: VehicleModel,
    pose: FloatArray,
    surge: FloatArray,
    yaw_rate: FloatArray,
) -> FloatArray:
    """States ``(north, east, ψ, u, 0, r, actuators…)`` along a timed path (module notes).

    Parameters
    ----------
    model : VehicleModel
        The vehicle.
    pose : ndarray of shape (n_t, 3)
        ``north, east`` [m] and heading ``ψ`` [rad].
    surge : ndarray of shape (n_t,)
        Surge speed [m/s] (clipped to the trim table's range for the propeller speeds).
    yaw_rate : ndarray of shape (n_t,)
        Yaw rate [rad/s].

    Returns
    -------
    ndarray of shape (n_t, n_x)
        The reference states.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> model = build_vehicle_model(load_vehicle("medusa"))
    >>> state = reference_states(model, np.zeros((1, 3)), np.array([1.0]), np.zeros(1))
    >>> state.shape, round(float(state[0, model.index("n_ps")]), 1)
    ((1, 8), 50.6)
    """
    pose = np.asarray(pose, dtype=np.float64).reshape(-1, 3)
    states = np.zeros((pose.shape[0], model.n_x))
    for k, name in enumerate(("north", "east", "psi")):
        states[:, model.index(name)] = pose[:, k]
    states[:, model.index("u")] = surge
    states[:, model.index("r")] = yaw_rate
    speeds, revolutions = surge_trim_table(model)
    unit_throttle = operating_state(model, throttle=1.0)[FIRST_ACTUATOR:]
    throttle = np.interp(surge, speeds, revolutions)
    states[:, FIRST_ACTUATOR:] = np.multiply.outer(throttle, unit_throttle)
    return states


def positions(model: VehicleModel, states: FloatArray) -> FloatArray:
    """``north, east`` [m] of states of shape ``(..., n_x)``, shape ``(..., 2)``."""
    return np.asarray(states)[..., [model.index("north"), model.index("east")]]


def headings(model: VehicleModel, states: FloatArray) -> FloatArray:
    """Heading ``ψ`` [rad] of states of shape ``(..., n_x)``, shape ``(...)``."""
    return np.asarray(states)[..., model.index("psi")]


__all__ = ["TRIM_SAMPLES", "headings", "positions", "reference_states", "surge_trim_table"]
