"""Link between geographic (lat/lon) coordinates and the local north/east frame.

A transverse Mercator projection (pyproj) centred on the map, with false northing/easting
chosen so that the map origin is ``north = east = 0``. Over a few tens of kilometres its scale
error is below 1e-5, far under the grid resolution.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np
from pyproj import Transformer

from auvplan._typing import FloatArray


@lru_cache(maxsize=32)
def _transformer(lat_0: float, lon_0: float, datum: str) -> Transformer:
    local = (
        f"+proj=tmerc +lat_0={lat_0!r} +lon_0={lon_0!r} +k=1 +x_0=0 +y_0=0 "
        f"+ellps={datum} +units=m +no_defs"
    )
    return Transformer.from_crs(f"+proj=longlat +ellps={datum} +no_defs", local, always_xy=True)


@dataclass(frozen=True)
class LocalProjection:
    """Transverse Mercator about ``(lat_0, lon_0)`` shifted to the map origin.

    Parameters
    ----------
    lat_0, lon_0 : float
        Projection centre [deg] (usually the map centre).
    offset_north, offset_east : float
        Projected coordinates [m] of the local origin; subtracted so the origin is ``(0, 0)``.
    ellipsoid : str
        PROJ ellipsoid name (``"WGS84"``; ``"GRS80"`` for NAD83 differs by < 1 mm here).

    Examples
    --------
    >>> p = LocalProjection(36.8, -121.81)
    >>> north, east = p.to_local(np.array([36.8]), np.array([-121.81]))
    >>> float(abs(north[0])) < 1e-6 and float(abs(east[0])) < 1e-6
    True
    """

    lat_0: float
    lon_0: float
    offset_north: float = 0.0
    offset_east: float = 0.0
    ellipsoid: str = "WGS84"

    def to_local(self, lat: FloatArray, lon: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Geographic ``(lat, lon)`` [deg] to local ``(north, east)`` [m]."""
        t = _transformer(self.lat_0, self.lon_0, self.ellipsoid)
        east, north = t.transform(
            np.asarray(lon, dtype=np.float64), np.asarray(lat, dtype=np.float64)
        )
        return np.asarray(north) - self.offset_north, np.asarray(east) - self.offset_east

    def to_geographic(self, north: FloatArray, east: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Local ``(north, east)`` [m] to geographic ``(lat, lon)`` [deg]."""
        t = _transformer(self.lat_0, self.lon_0, self.ellipsoid)
        lon, lat = t.transform(
            np.asarray(east, dtype=np.float64) + self.offset_east,
            np.asarray(north, dtype=np.float64) + self.offset_north,
            direction="INVERSE",
        )
        return np.asarray(lat), np.asarray(lon)

    def shifted(self, north: float, east: float) -> LocalProjection:
        """The same projection with its origin moved to local ``(north, east)`` [m]."""
        return replace(
            self, offset_north=self.offset_north + north, offset_east=self.offset_east + east
        )
