r"""The depth profile of a constant-altitude plan (``[mission] altitude_m``).

The optimised plan is planar (3-DOF: surge, sway, yaw); a vehicle asked to follow the seabed
at altitude :math:`a` is given, along its optimised track :math:`p(t_i)`, the depth
:math:`z_i` (positive down) closest to the desired

.. math::

    z^d_i = h(p(t_i)) - a

that its type can fly (:class:`~auvplan.vehicle.DepthLimits`: climb rate :math:`c`, dive
rate :math:`d`, minimum altitude :math:`m`), with :math:`h` the seabed depth of the mission's
bathymetry (the bilinear surface of :func:`~auvplan.navigation.depth.depth_at`).

**Constraints.** (i) clearance, hard: :math:`z_i \le H_i - m`, where :math:`H_i` is the
shallowest seabed along the track from :math:`t_{i-1}` to :math:`t_{i+1}`, sampled where it
crosses a row or column of grid nodes (the bilinear surface's kinks) and at least every
quarter cell (:func:`clearance_seabed`), so that the straight line between two samples, flown
as ``depth`` is interpolated, keeps the clearance between them too; (ii) the surface,
:math:`z_i \ge 0`; (iii) the rates, :math:`z_i - z_{i+1} \le c\,\Delta t_i` and
:math:`z_{i+1} - z_i \le d\,\Delta t_i`.

**Construction.** The target :math:`T_i = \max(0, \min(z^d_i, H_i - m))`; the profile is the
greatest sequence :math:`z \le T` satisfying (iii) — the deepest, i.e. nearest :math:`z^d`
from above, since every :math:`z \le T` obeying (iii) lies below it. A backward pass
:math:`B_i = \min(T_i, B_{i+1} + c\,\Delta t_i)` climbs early enough for a rising seabed
ahead; a forward pass :math:`z_{i+1} = \min(B_{i+1}, z_i + d\,\Delta t_i)` limits the dive.
The forward pass keeps the climb limit: where :math:`z_{i+1} = B_{i+1}`,
:math:`z_i \le B_i \le B_{i+1} + c\,\Delta t_i`; where :math:`z_{i+1} = z_i + d\,\Delta t_i`,
the step is a dive. Both passes only lower values, so :math:`z \le T` gives (i)
wherever :math:`H_i \ge m`; a value is lowered only to a non-negative neighbour plus a
non-negative step, so :math:`z \ge 0` (ii). On a flat seabed :math:`T` is constant and
:math:`z = z^d` exactly (no arithmetic touches a sample that needs no lowering).

Where :math:`H_i < m` (a seabed shallower than the minimum altitude) no depth meets (i); the
pre-planner refuses such paths (:func:`auvplan.mission.preplan.check_seabed_clearance`); if
the optimised track still crosses one, the profile stays at the surface there and the plan's
verdict names it (:func:`auvplan.mission.checks.seabed_violations`, exit 3). Where the track
leaves the map, the seabed is that of the nearest sample with one.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.navigation.depth import depth_at
from auvplan.terrain import BathymetryGrid
from auvplan.vehicle import DepthLimits

#: Samples of the seabed between two track samples per grid spacing (the clearance check).
SEABED_SAMPLES_PER_CELL: Final = 4
#: Most seabed samples per track step (a step longer than 256 quarter-cells is rare).
MAX_SEABED_SAMPLES: Final = 256


@dataclass(frozen=True)
class DepthProfile:
    """One vehicle's depth profile on its track's samples.

    ``time`` [s], ``depth`` [m] positive down, ``altitude`` [m] = ``seabed - depth``,
    ``seabed`` [m] the seabed depth under each sample, ``clearance_seabed`` [m] the shallowest
    seabed from the previous sample to the next (:math:`H_i` of the module notes); all of
    shape ``(n_t,)``. ``min_altitude`` [m] is the hard bound the profile was built for.
    """

    time: FloatArray
    depth: FloatArray
    altitude: FloatArray
    seabed: FloatArray
    clearance_seabed: FloatArray
    min_altitude: float

    @property
    def clearance(self) -> FloatArray:
        """Height [m] above the shallowest seabed between neighbouring samples, ``H - z``."""
        return np.asarray(self.clearance_seabed - self.depth, dtype=np.float64)


def rate_limited_depth(
    time: FloatArray, target: FloatArray, *, climb_rate: float, dive_rate: float
) -> FloatArray:
    r"""The greatest depth sequence :math:`z \le` ``target`` within the climb and dive rates.

    Parameters
    ----------
    time : ndarray of shape (n_t,)
        Increasing time [s].
    target : ndarray of shape (n_t,)
        Deepest allowed depth at each sample [m], positive down.
    climb_rate, dive_rate : float
        Largest ascent and descent rates [m/s], > 0.

    Returns
    -------
    ndarray of shape (n_t,)
        :math:`z` with :math:`z_i - z_{i+1} \le c\,\Delta t_i`,
        :math:`z_{i+1} - z_i \le d\,\Delta t_i` and :math:`z \le` ``target``, the greatest such
        (module notes: a backward and a forward pass).

    Examples
    --------
    A 10 m rise of the target at t = 10 s, climbed at 1 m/s from t = 0, dived back at 2 m/s:

    >>> time = np.arange(0.0, 21.0, 5.0)
    >>> rate_limited_depth(time, np.array([20.0, 20.0, 10.0, 20.0, 20.0]),
    ...                    climb_rate=1.0, dive_rate=2.0).tolist()
    [20.0, 15.0, 10.0, 20.0, 20.0]
    """
    climb = climb_rate * np.diff(time)
    dive = dive_rate * np.diff(time)
    depth = np.array(target, dtype=np.float64)
    for i in range(depth.size - 2, -1, -1):  # backward: climb early enough
        depth[i] = min(depth[i], depth[i + 1] + climb[i])
    for i in range(depth.size - 1):  # forward: dive no faster than the dive rate
        depth[i + 1] = min(depth[i + 1], depth[i] + dive[i])
    return depth


def clearance_seabed(bathymetry: BathymetryGrid, north: FloatArray, east: FloatArray) -> FloatArray:
    """The shallowest seabed [m] from each sample's predecessor to its successor.

    The straight segments between the samples ``north``, ``east`` ``(n_t,)`` [m] are
    sampled every quarter of the grid's finer spacing, and at least at
    :data:`SEABED_SAMPLES_PER_CELL` points besides their start (at most
    :data:`MAX_SEABED_SAMPLES`), and where they cross a row or column of grid nodes: there
    the bilinear surface has its kinks, and a crest between two samples would be missed.
    Between those points the surface along a segment is quadratic. NaN where no sample has a
    seabed.
    """
    geometry = bathymetry.geometry
    step = min(geometry.spacing_north, geometry.spacing_east) / SEABED_SAMPLES_PER_CELL
    lengths = np.hypot(np.diff(north), np.diff(east))
    longest = float(np.max(lengths, initial=0.0))
    n_samples = min(max(math.ceil(longest / step), SEABED_SAMPLES_PER_CELL), MAX_SEABED_SAMPLES) + 1
    row, col = geometry.to_fractional_index(north, east)
    fraction = np.concatenate(
        [
            np.broadcast_to(np.linspace(0.0, 1.0, n_samples), (north.size - 1, n_samples)),
            _node_crossings(row),
            _node_crossings(col),
        ],
        axis=1,
    )
    along_north = north[:-1, None] + fraction * np.diff(north)[:, None]
    along_east = east[:-1, None] + fraction * np.diff(east)[:, None]
    seabed = depth_at(bathymetry, along_north, along_east)
    with warnings.catch_warnings():  # a segment wholly off the map: "All-NaN slice"
        warnings.simplefilter("ignore", RuntimeWarning)
        segment = np.nanmin(seabed, axis=1)
    before = np.concatenate([[np.inf], segment])
    after = np.concatenate([segment, [np.inf]])
    shallowest = np.fmin(before, after)
    return np.asarray(np.where(np.isinf(shallowest), np.nan, shallowest), dtype=np.float64)


def _node_crossings(index: FloatArray) -> FloatArray:
    """Where each segment crosses a row or column of grid nodes (an integer fractional index).

    ``index`` ``(n,)`` are the samples' fractional rows (or columns); returns the crossings as
    fractions of each segment in (0, 1), NaN padded, shape ``(n - 1, k)``.
    """
    low, high = np.minimum(index[:-1], index[1:]), np.maximum(index[:-1], index[1:])
    first = np.floor(low) + 1.0
    count = int(np.clip(np.max(np.ceil(high) - first, initial=0.0), 0, MAX_SEABED_SAMPLES))
    nodes = first[:, None] + np.arange(count)[None, :]
    step = np.diff(index)[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        fraction = (nodes - index[:-1, None]) / step
    return np.where((nodes < high[:, None]) & (step != 0.0), fraction, np.nan)


def depth_profile(
    time: FloatArray,
    north: FloatArray,
    east: FloatArray,
    bathymetry: BathymetryGrid,
    *,
    altitude: float,
    limits: DepthLimits,
) -> DepthProfile:
    """The depth profile (module notes) of one track flown at ``altitude`` [m] above the seabed.

    Parameters
    ----------
    time : ndarray of shape (n_t,)
        Increasing time [s].
    north, east : ndarray of shape (n_t,)
        The optimised track [m].
    bathymetry : BathymetryGrid
        The mission's seabed.
    altitude : float
        Desired height above the seabed ``a`` [m] (``mission.altitude_m``).
    limits : DepthLimits
        The vehicle type's climb and dive rates [m/s] and minimum altitude [m].

    Returns
    -------
    DepthProfile

    Raises
    ------
    InputError
        If no sample of the track has a seabed (the track is off the map).

    Examples
    --------
    Over a flat seabed 30 m deep the profile is the desired depth exactly:

    >>> from auvplan.terrain import GridGeometry
    >>> flat = BathymetryGrid(np.full((20, 20), 30.0), GridGeometry(20, 20, 5.0, 5.0))
    >>> time = np.arange(5.0)
    >>> profile = depth_profile(time, 10.0 + time, np.full(5, 40.0), flat, altitude=8.0,
    ...                         limits=DepthLimits(0.3, 0.3, 2.0))
    >>> profile.depth.tolist(), profile.altitude.tolist()
    ([22.0, 22.0, 22.0, 22.0, 22.0], [8.0, 8.0, 8.0, 8.0, 8.0])
    """
    seabed = _filled(time, depth_at(bathymetry, north, east))
    nearest = clearance_seabed(bathymetry, north, east)
    nearest = np.where(np.isnan(nearest), seabed, np.fmin(nearest, seabed))
    target = np.maximum(np.minimum(seabed - altitude, nearest - limits.min_altitude), 0.0)
    depth = rate_limited_depth(
        time, target, climb_rate=limits.climb_rate, dive_rate=limits.dive_rate
    )
    return DepthProfile(time, depth, seabed - depth, seabed, nearest, limits.min_altitude)


def fleet_depth_profiles(
    altitude: float | None,
    bathymetry: BathymetryGrid,
    time: FloatArray,
    tracks: FloatArray,
    limits: tuple[DepthLimits, ...],
) -> tuple[DepthProfile, ...] | None:
    """Each vehicle's :func:`depth_profile` at ``altitude`` [m]; ``None`` without one.

    ``time`` ``(n_t,)`` [s], ``tracks`` ``(n_vehicles, n_t, 2)`` north/east [m], ``limits``
    each vehicle type's :class:`~auvplan.vehicle.DepthLimits`. Without ``altitude``
    (``[mission] depth_m`` or neither) the plan keeps its constant depth: ``None``.
    """
    if altitude is None:
        return None
    return tuple(
        depth_profile(time, track[:, 0], track[:, 1], bathymetry, altitude=altitude, limits=vehicle)
        for track, vehicle in zip(tracks, limits, strict=True)
    )


def _filled(time: FloatArray, seabed: FloatArray) -> FloatArray:
    """``seabed`` with its NaN samples (off the map) given the nearest known sample's depth."""
    known = np.isfinite(seabed)
    if not known.any():
        raise InputError("the track has no seabed under it (it lies off the map)")
    if known.all():
        return seabed
    index = np.flatnonzero(known)
    nearest = index[np.clip(np.searchsorted(time[index], time), 0, index.size - 1)]
    previous = index[np.clip(np.searchsorted(time[index], time) - 1, 0, index.size - 1)]
    closer = np.where(
        np.abs(time[previous] - time) <= np.abs(time[nearest] - time), previous, nearest
    )
    return np.asarray(np.where(known, seabed, seabed[closer]), dtype=np.float64)


__all__ = [
    "DepthProfile",
    "clearance_seabed",
    "depth_profile",
    "fleet_depth_profiles",
    "rate_limited_depth",
]
