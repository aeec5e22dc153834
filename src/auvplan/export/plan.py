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

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError


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
    lat, lon : ndarray of shape (n_t,)
        The same positions in WGS 84 [deg].
    """

    name: str
    time: FloatArray
    north: FloatArray
    east: FloatArray
    lat: FloatArray
    lon: FloatArray

    def __post_init__(self) -> None:
        n_t = np.shape(self.time)
        arrays = (self.north, self.east, self.lat, self.lon)
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
    """A polygonal keep-out zone: vertices ``lat, lon`` [deg], in order, closing edge implied."""

    name: str
    lat: FloatArray
    lon: FloatArray


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
        Constant depth of the plan [m], positive down.
    origin_lat, origin_lon : float
        WGS 84 position [deg] of the local frame's origin (``north = east = 0``).
    capture_radius : float
        Distance [m] at which a vehicle counts a waypoint as reached (the fleet's safety
        radius ``r_c``).
    zones : tuple of CircleZone or PolygonZone
        The mission's obstacles.
    """

    tracks: tuple[VehicleTrack, ...]
    start_time: datetime
    depth: float
    origin_lat: float
    origin_lon: float
    capture_radius: float
    zones: tuple[CircleZone | PolygonZone, ...] = ()

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
