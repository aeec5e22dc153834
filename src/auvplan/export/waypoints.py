r"""Thinning a timed track to waypoints that keep its geometry and its time law.

Vehicles and ground stations want a few waypoints, not one per solver step. A waypoint list
flown leg by leg at constant speed (leg length / leg duration) puts the vehicle at

.. math:: q(t) = p_a + \frac{t - t_a}{t_b - t_a} (p_b - p_a), \qquad t_a \le t \le t_b

between consecutive waypoints :math:`a, b`. :func:`thin_track` keeps a subset of the track's
samples such that, at every sample time :math:`t_k`,

.. math:: \lVert q(t_k) - p_k \rVert \le \text{tolerance}

(the synchronised Euclidean distance of Meratnia & de By, 2004). Both the path and the timing
are then within ``tolerance``: between samples both :math:`q` and the sampled track are linear
in time, so their distance is a convex function of :math:`t` and never exceeds its value at the
samples; in particular the waypoint path and the track are within ``tolerance`` of each other
(Hausdorff distance).

Two steps: Douglas–Peucker on the local ``(east, north)`` polyline (shapely's ``simplify``,
GEOS) picks the corners of the path; then every leg whose time law departs from constant speed
by more than ``tolerance`` is split at its worst sample, until none does (a vehicle that
slows down or waits on a straight stretch keeps the waypoints that say so).

References
----------
N. Meratnia and R. A. de By, "Spatiotemporal compression techniques for moving point objects",
EDBT 2004 (the synchronised Euclidean distance).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np

from auvplan._typing import BoolArray, FloatArray, IntArray
from auvplan.errors import InputError
from auvplan.export.plan import VehicleTrack, file_stems

#: Legs slower than this [m/s] are waits: formats fly them as a hold, not as a leg.
STOP_SPEED: Final = 0.01


@dataclass(frozen=True)
class Waypoints:
    """The kept samples of a track: every array has shape ``(n_waypoints,)``.

    ``index`` are their positions in the track; ``time`` [s since the start], ``north``,
    ``east`` [m], ``lat``, ``lon`` [deg] (``None`` without geographic reference) and
    ``depth`` [m] (``None`` without a depth profile) are the track's values there.
    """

    name: str
    index: IntArray
    time: FloatArray
    north: FloatArray
    east: FloatArray
    lat: FloatArray | None
    lon: FloatArray | None
    depth: FloatArray | None = None

    def geographic(self) -> tuple[FloatArray, FloatArray]:
        """``(lat, lon)`` [deg] of the waypoints.

        Raises
        ------
        InputError
            If the plan has no geographic reference (see
            :func:`auvplan.export.check_georeference`, which refuses such formats first).
        """
        if self.lat is None or self.lon is None:
            raise InputError(f"vehicle {self.name}: the plan has no lat/lon")
        return self.lat, self.lon

    @property
    def leg_lengths(self) -> FloatArray:
        """Length [m] of each leg, shape ``(n_waypoints - 1,)``."""
        return np.hypot(np.diff(self.north), np.diff(self.east))

    @property
    def leg_durations(self) -> FloatArray:
        """Duration [s] of each leg, shape ``(n_waypoints - 1,)``."""
        return np.diff(self.time)

    @property
    def leg_speeds(self) -> FloatArray:
        """Constant speed [m/s] that flies each leg in its duration."""
        return self.leg_lengths / self.leg_durations

    @property
    def waits(self) -> BoolArray:
        """Whether each leg is a wait (slower than :data:`STOP_SPEED`)."""
        return self.leg_speeds < STOP_SPEED

    @property
    def mean_speed(self) -> float:
        """Waypoint-path length over the track's duration [m/s]."""
        return float(np.sum(self.leg_lengths) / (self.time[-1] - self.time[0]))


def synchronized_distances(
    time: FloatArray, points: FloatArray, kept: IntArray
) -> tuple[FloatArray, IntArray]:
    r"""Distance [m] of every sample from the constant-speed legs between ``kept`` samples.

    Parameters
    ----------
    time : ndarray of shape (n_t,)
        Sample times [s], increasing.
    points : ndarray of shape (n_t, 2)
        Sample positions [m].
    kept : ndarray of int, shape (n_kept,)
        Increasing sample indices, first ``0`` and last ``n_t - 1``.

    Returns
    -------
    distances : ndarray of shape (n_t,)
        :math:`\lVert q(t_k) - p_k \rVert` (0 at kept samples).
    leg : ndarray of int, shape (n_t,)
        The leg (index into ``kept[:-1]``) each sample lies on.
    """
    leg = np.clip(np.searchsorted(kept, np.arange(time.size), side="right") - 1, 0, kept.size - 2)
    start, end = kept[leg], kept[leg + 1]
    fraction = (time - time[start]) / (time[end] - time[start])
    interpolated = points[start] + fraction[:, None] * (points[end] - points[start])
    distances = np.hypot(*(interpolated - points).T)
    distances[kept] = 0.0  # exactly: the last sample's interpolation may round
    return distances, leg


def thin_track(track: VehicleTrack, tolerance: float) -> Waypoints:
    """Few samples of ``track`` that keep its path and its time law within ``tolerance``.

    Parameters
    ----------
    track : VehicleTrack
        The full track.
    tolerance : float
        Largest allowed distance [m] between the waypoint plan flown at constant leg speeds
        and the track, at every sample time (see the module notes); ``0`` keeps every sample
        that is not exactly on a constant-speed leg.

    Returns
    -------
    Waypoints
        Includes the first and last samples; times strictly increase.

    Raises
    ------
    InputError
        If ``tolerance`` is negative or not finite, or a time or position of the track is not
        finite (NaN or inf: the thinning's distances would never fall within ``tolerance``).

    Examples
    --------
    >>> t = np.arange(5.0)
    >>> straight = VehicleTrack("a", t, 2.0 * t, 0.0 * t, t, t)  # north at 2 m/s
    >>> thin_track(straight, 0.1).index.tolist()
    [0, 4]
    >>> waits = VehicleTrack("b", t, np.array([0.0, 0.0, 0.0, 2.0, 4.0]), 0.0 * t, t, t)
    >>> thin_track(waits, 0.1).index.tolist()
    [0, 2, 4]
    """
    if not (np.isfinite(tolerance) and tolerance >= 0.0):
        raise InputError(f"tolerance_m must be >= 0 m, got {tolerance!r}")
    _check_finite(track)
    from shapely import LineString

    points = np.column_stack([track.north, track.east])
    path = LineString(points[:, ::-1])  # shapely's x, y = east, north
    corners = np.asarray(path.simplify(tolerance, preserve_topology=False).coords)
    kept = _sample_indices(points[:, ::-1], corners)
    while True:
        distances, leg = synchronized_distances(track.time, points, kept)
        if distances.max() <= tolerance:
            break
        order = np.lexsort((distances, leg))  # by leg, then distance: a leg's last is its worst
        is_worst = np.append(leg[order][1:] != leg[order][:-1], True)
        worst = order[is_worst]
        kept = np.union1d(kept, worst[distances[worst] > tolerance])
    return Waypoints(
        name=track.name,
        index=kept,
        time=track.time[kept],
        north=track.north[kept],
        east=track.east[kept],
        lat=None if track.lat is None else track.lat[kept],
        lon=None if track.lon is None else track.lon[kept],
        depth=None if track.depth is None else track.depth[kept],
    )


def by_file_stem(fleet: Sequence[Waypoints]) -> list[tuple[str, Waypoints]]:
    """Each vehicle's waypoints with the stem of its file names (:func:`.file_stems`)."""
    return list(zip(file_stems([waypoints.name for waypoints in fleet]), fleet, strict=True))


def _check_finite(track: VehicleTrack) -> None:
    """Raise InputError naming the vehicle, column and first sample that is not finite."""
    for column in ("time", "north", "east", "lat", "lon"):
        values = getattr(track, column)
        if values is None:  # no geographic reference
            continue
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise InputError(
                f"track {track.name}: {column} is {values[bad[0]]} at sample {bad[0]} "
                f"({bad.size} non-finite of {values.size}); a track holds finite numbers only"
            )


def _sample_indices(samples: FloatArray, vertices: FloatArray) -> IntArray:
    """Indices of the simplified line's vertices among the samples (a subsequence of them).

    GEOS returns input vertices unchanged; one not found would only leave its leg to the
    time-law refinement, which restores the tolerance.
    """
    indices = [0]
    for vertex in vertices[1:-1]:
        start = indices[-1] + 1
        matches = np.flatnonzero(np.all(samples[start:] == vertex, axis=1))
        if matches.size:
            indices.append(start + int(matches[0]))
    indices.append(samples.shape[0] - 1)
    return np.unique(np.asarray(indices, dtype=np.intp))


__all__ = ["Waypoints", "by_file_stem", "synchronized_distances", "thin_track"]
