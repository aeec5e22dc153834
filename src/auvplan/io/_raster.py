"""The raster every bathymetry reader returns, and the checks all readers share.

A :class:`Raster` is the data as read (values on native coordinate axes), before the
conversion to depth and to the local metric frame in :mod:`auvplan.io.bathymetry`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError

if TYPE_CHECKING:
    from pyproj import CRS

#: A coordinate step below this many units is taken as degrees, not metres, when a file does
#: not say (no CRS / units): 0.05 deg is 5.5 km, and no metric survey has 5 cm spacing.
GEOGRAPHIC_STEP_LIMIT: Final = 0.05

#: Valid latitudes [deg] and longitudes [deg] (either the -180..180 or the 0..360 convention).
LATITUDE_RANGE: Final = (-90.0, 90.0)
LONGITUDE_RANGE: Final = (-180.0, 360.0)


@dataclass(frozen=True)
class Raster:
    """A raster as read, before conversion: rows along ``axis_north``, columns along east.

    ``crs`` is the CRS of the axes: geographic (lat/lon [deg]), projected (northing/easting,
    e.g. UTM [m]), or None for a purely local metric frame without georeference.
    """

    values: FloatArray
    axis_north: FloatArray  # lat [deg] or northing [m], increasing
    axis_east: FloatArray  # lon [deg] or easting [m], increasing
    crs: CRS | None
    is_depth: bool | None  # None: decide from the values
    attributes: dict[str, str] = field(default_factory=dict)

    @property
    def is_geographic(self) -> bool:
        """True when the axes are latitude and longitude [deg]."""
        return self.crs is not None and bool(self.crs.is_geographic)


def looks_geographic(lat: FloatArray, lon: FloatArray) -> bool:
    """True when coordinates without units fit the lat/lon ranges and step by < 0.05."""
    lat, lon = np.asarray(lat, dtype=np.float64), np.asarray(lon, dtype=np.float64)
    if not (_inside(lat, LATITUDE_RANGE) and _inside(lon, LONGITUDE_RANGE)):
        return False
    steps = [np.diff(np.unique(a)) for a in (lat, lon)]
    step = min((float(np.median(s)) for s in steps if s.size), default=np.inf)
    return step < GEOGRAPHIC_STEP_LIMIT


def check_geographic_range(lat: FloatArray, lon: FloatArray) -> None:
    """Raise DataFormatError unless latitudes and longitudes [deg] are on the Earth.

    Longitudes may follow either convention, -180..180 or 0..360, but span at most 360 deg.
    """
    for values, name, bounds in (
        (lat, "latitudes", LATITUDE_RANGE),
        (lon, "longitudes", LONGITUDE_RANGE),
    ):
        if not _inside(values, bounds):
            raise DataFormatError(
                f"{name} {np.min(values):g} … {np.max(values):g} deg are outside "
                f"[{bounds[0]:g}, {bounds[1]:g}] deg"
            )
    if float(np.max(lon) - np.min(lon)) > 360.0:
        raise DataFormatError(f"longitudes span {np.max(lon) - np.min(lon):g} deg (> 360 deg)")


def _inside(values: FloatArray, bounds: tuple[float, float]) -> bool:
    return bool(
        np.all(np.isfinite(values)) and np.all((values >= bounds[0]) & (values <= bounds[1]))
    )


def increasing(
    values: FloatArray, north_axis: FloatArray, east_axis: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Flip rows/columns so both coordinate axes increase (row 0 = south, col 0 = west)."""
    if north_axis.size > 1 and north_axis[1] < north_axis[0]:
        values, north_axis = values[::-1], north_axis[::-1]
    if east_axis.size > 1 and east_axis[1] < east_axis[0]:
        values, east_axis = values[:, ::-1], east_axis[::-1]
    for axis, name in ((north_axis, "north/lat"), (east_axis, "east/lon")):
        if axis.size > 1 and not np.all(np.diff(axis) > 0.0):
            raise DataFormatError(f"{name} coordinates are not monotonic")
    return np.ascontiguousarray(values), north_axis.copy(), east_axis.copy()


def first_line(value: object) -> str:
    """The first line of ``str(value)`` (library messages can run over dozens of lines)."""
    lines = str(value).strip().splitlines()
    return lines[0] if lines else type(value).__name__
