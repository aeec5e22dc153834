r"""Speeds along a path in a current: ground speed from through-water speed, and back.

On a path with unit tangent ``t̂`` in a current ``v_c``, a vehicle moving at speed ``U_w``
through the water and keeping to the path has the ground speed

.. math::

    s = v_c · t̂ + \sqrt{U_w^2 - (v_c × t̂)^2},

which exists only when the cross-path current ``|v_c × t̂| = |v_{c,N} t_E - v_{c,E} t_N|`` is
at most ``U_w`` (otherwise the current sweeps the vehicle off the path). Conversely a ground
velocity ``ṗ`` needs the through-water velocity ``v_w = ṗ - v_c``: the surge ``|v_w|`` and the
heading ``atan2(v_{w,E}, v_{w,N})`` that crabs into the current.
"""

from __future__ import annotations

import numpy as np

from auvplan._typing import FloatArray

__all__ = ["ground_speed", "through_water"]


def ground_speed(
    water_speed: FloatArray | float, current: FloatArray, tangent: FloatArray
) -> FloatArray:
    """Ground speed along a path at a through-water speed (module equation).

    Parameters
    ----------
    water_speed : ndarray of shape (K,) or float
        Speed through the water ``U_w`` [m/s].
    current : ndarray of shape (K, 2)
        Current ``(v_N, v_E)`` [m/s].
    tangent : ndarray of shape (K, 2)
        Unit tangent ``(t_N, t_E)`` of the path [-].

    Returns
    -------
    ndarray of shape (K,)
        Ground speed [m/s]; NaN where the cross-path current exceeds ``U_w``, and values
        ``<= 0`` where the along-path current holds the vehicle back.

    Examples
    --------
    >>> ground_speed(1.0, np.array([[0.0, 0.6]]), np.array([[1.0, 0.0]])).round(6).tolist()
    [0.8]
    """
    current = np.asarray(current, dtype=np.float64).reshape(-1, 2)
    tangent = np.asarray(tangent, dtype=np.float64).reshape(-1, 2)
    along = np.sum(current * tangent, axis=1)
    across = current[:, 0] * tangent[:, 1] - current[:, 1] * tangent[:, 0]
    margin = np.asarray(water_speed, dtype=np.float64) ** 2 - across**2
    with np.errstate(invalid="ignore"):
        return np.where(margin >= 0.0, along + np.sqrt(np.maximum(margin, 0.0)), np.nan)


def through_water(
    ground_velocity: FloatArray, current: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Speed through the water and the heading that crabs into the current.

    Parameters
    ----------
    ground_velocity : ndarray of shape (K, 2)
        ``ṗ = (ṅ, ė)`` [m/s].
    current : ndarray of shape (K, 2)
        ``(v_N, v_E)`` [m/s].

    Returns
    -------
    speed : ndarray of shape (K,)
        ``|ṗ - v_c|`` [m/s].
    heading : ndarray of shape (K,)
        ``atan2(v_{w,E}, v_{w,N})`` [rad] (0 where the vehicle drifts with the water).

    Examples
    --------
    >>> speed, heading = through_water(np.array([[1.0, 0.0]]), np.array([[0.0, -1.0]]))
    >>> round(float(speed[0]), 6), round(float(np.degrees(heading[0])), 6)
    (1.414214, 45.0)
    """
    water = np.asarray(ground_velocity, dtype=np.float64) - np.asarray(current, dtype=np.float64)
    return np.hypot(water[:, 0], water[:, 1]), np.arctan2(water[:, 1], water[:, 0])
