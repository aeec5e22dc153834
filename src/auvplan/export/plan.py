"""What every export format is written from: the fleet's timed tracks and keep-out zones.

An :class:`ExportPlan` holds the optimised trajectories of a finished plan in geographic and
local coordinates (made from an output folder's record by :func:`auvplan.record.export_plan`);
the format modules write it after thinning each track to waypoints
(:mod:`auvplan.export.waypoints`).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from typing import TYPE_CHECKING

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError

if TYPE_CHECKING:
    from auvplan.export.waypoints import Waypoints


@dataclass(frozen=True)
class VehicleTrack:
    """One vehicle's trajectory on the solver's time grid.

    Parameters
    ----------
    name : str
        Vehicle name.
    time : ndarray of shape (n_t,)
        Time since the plan's start time [s], increasing.
    north, east : ndarray of shape (n_t,)
        Position in the local frame [m].
    lat, lon : ndarray of shape (n_t,) or None
        The same positions in WGS 84 [deg]; ``None`` on terrain without geographic reference
        (the synthetic bank).
    depth : ndarray of shape (n_t,), optional
        Depth [m], positive down, along a depth profile (``[mission] altitude_m``); ``None``:
        the plan's constant depth.
    """

    name: str
    time: FloatArray
    north: FloatArray
    east: FloatArray
    lat: FloatArray | None
    lon: FloatArray | None
    depth: FloatArray | None = None

    def __post_init__(self) -> None:
        n_t = np.shape(self.time)
        if (self.lat is None) != (self.lon is None):
            raise InputError(f"track {self.name}: give both lat and lon, or neither")
        optional = (self.lat, self.lon, self.depth)
        arrays = (self.north, self.east, *(a for a in optional if a is not None))
        if len(n_t) != 1 or n_t[0] < 2 or any(np.shape(a) != n_t for a in arrays):
            raise InputError(f"track {self.name}: time and positions need one common length >= 2")
        if not np.all(np.diff(self.time) > 0.0):
            raise InputError(f"track {self.name}: times must increase")


@dataclass(frozen=True)
class CircleZone:
    """A circular keep-out zone: centre ``lat, lon`` [deg], ``radius`` [m]."""

    name: str
    lat: float
    lon: float
    radius: float


@dataclass(frozen=True)
class PolygonZone:
    """A polygonal keep-out zone: vertices ``lat, lon`` [deg], in order, closing edge implied.

    ``holes`` are the ``(lat, lon)`` rings of free water inside it (GeoJSON and KML write
    them; a format without holes, such as a QGroundControl fence, keeps out of them too).
    """

    name: str
    lat: FloatArray
    lon: FloatArray
    holes: tuple[tuple[FloatArray, FloatArray], ...] = ()


@dataclass(frozen=True)
class ExportPlan:
    """A finished plan, ready to export.

    Parameters
    ----------
    tracks : tuple of VehicleTrack
        One per vehicle, in mission order.
    start_time : datetime
        UTC time of ``t = 0`` (time-zone aware).
    depth : float
        Constant depth of the plan [m], positive down (used where a track has no depth
        profile).
    origin_lat, origin_lon : float or None
        WGS 84 position [deg] of the local frame's origin (``north = east = 0``); ``None``
        on terrain without geographic reference, whose tracks have no lat/lon either.
    capture_radius : float
        Distance [m] at which a vehicle counts a waypoint as reached (the fleet's safety
        radius ``r_c``).
    zones : tuple of CircleZone or PolygonZone
        The mission's obstacles (none without geographic reference: only the formats that
        need lat/lon draw them).
    """

    tracks: tuple[VehicleTrack, ...]
    start_time: datetime
    depth: float
    origin_lat: float | None
    origin_lon: float | None
    capture_radius: float
    zones: tuple[CircleZone | PolygonZone, ...] = ()

    @property
    def is_georeferenced(self) -> bool:
        """Whether the plan has lat/lon (its origin and every track)."""
        return (
            self.origin_lat is not None
            and self.origin_lon is not None
            and all(track.lat is not None for track in self.tracks)
        )

    @property
    def has_profile(self) -> bool:
        """Whether the tracks carry a depth profile (``[mission] altitude_m``)."""
        return any(track.depth is not None for track in self.tracks)

    def waypoint_depths(self, waypoints: Waypoints) -> FloatArray:
        """Depth [m], positive down, at each waypoint: its track's profile, else ``depth``."""
        if waypoints.depth is not None:
            return waypoints.depth
        return np.full(waypoints.time.shape, float(self.depth))

    def timestamp(self, seconds: float) -> datetime:
        """The UTC time ``seconds`` [s] after the start."""
        return self.start_time + timedelta(seconds=float(seconds))


def utc_text(moment: datetime) -> str:
    """ISO 8601 UTC text with a ``Z`` and only the digits needed (GPX, KML, GeoJSON).

    Examples
    --------
    >>> utc_text(datetime(2026, 5, 1, 8, 0, 2, 500000, tzinfo=UTC))
    '2026-05-01T08:00:02.5Z'
    """
    text = moment.astimezone(UTC).strftime("%Y-%m-%dT%H:%M:%S.%f").rstrip("0").rstrip(".")
    return f"{text}Z"


def file_stems(names: Sequence[str]) -> tuple[str, ...]:
    """File-name stems for vehicle names: safe characters only, unique.

    Examples
    --------
    >>> file_stems(["blue", "auv 2", "auv/2"])
    ('blue', 'auv_2', 'auv_2-2')
    """
    stems: list[str] = []
    for name in names:
        stem = re.sub(r"[^A-Za-z0-9_.-]", "_", name).lstrip(".") or "vehicle"
        candidate, count = stem, 1
        while candidate in stems:
            count += 1
            candidate = f"{stem}-{count}"
        stems.append(candidate)
    return tuple(stems)


__all__ = [
    "CircleZone",
    "ExportPlan",
    "PolygonZone",
    "VehicleTrack",
    "file_stems",
    "utc_text",
]
