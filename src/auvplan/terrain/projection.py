"""The local north/east frame as a real coordinate reference system (pyproj).

The local frame is a transverse Mercator projection with scale factor 1, centred on the map
``(lat_0, lon_0)``, whose false easting and northing put the map origin at ``north = east = 0``
(SPEC §0: a proper projection, not a flat-earth formula). Over a few tens of kilometres its
scale error is below 1e-5 and the meridian convergence at the map edge below 0.1 deg, far
under the grid resolution, so ``north`` is true north to that accuracy.

:attr:`LocalProjection.crs` is that frame as a :class:`pyproj.CRS`: every writer can put it into
a file (``crs.to_cf()``, ``crs.to_wkt()``), and :meth:`LocalProjection.from_crs` recognises it
when read back.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Final

import numpy as np
from pyproj import CRS, Transformer, get_ellps_map

from auvplan._typing import FloatArray
from auvplan.errors import InputError

#: The geographic CRS of every latitude and longitude auvplan reads or writes (mission poses,
#: windows, GeoJSON): WGS 84, longitude first (``always_xy``).
GEOGRAPHIC_CRS: Final = "EPSG:4326"

#: Name of the projected CRS of the local frame (in WKT and CF ``projected_crs_name``).
LOCAL_CRS_NAME: Final = "auvplan local frame"


@lru_cache(maxsize=8)
def _geodetic_crs(ellipsoid: str) -> CRS:
    """WGS 84 for ``"WGS84"``, else an unnamed datum on the PROJ ellipsoid ``ellipsoid``."""
    if ellipsoid == "WGS84":
        return CRS(GEOGRAPHIC_CRS)
    if ellipsoid not in get_ellps_map():
        raise InputError(f"unknown ellipsoid {ellipsoid!r} (a PROJ name such as 'WGS84')")
    return CRS.from_proj4(f"+proj=longlat +ellps={ellipsoid} +no_defs")


@lru_cache(maxsize=64)
def _local_crs(
    lat_0: float, lon_0: float, offset_north: float, offset_east: float, ellipsoid: str
) -> CRS:
    from pyproj.crs import ProjectedCRS
    from pyproj.crs.coordinate_operation import TransverseMercatorConversion

    conversion = TransverseMercatorConversion(
        latitude_natural_origin=lat_0,
        longitude_natural_origin=lon_0,
        false_easting=-offset_east,
        false_northing=-offset_north,
        scale_factor_natural_origin=1.0,
    )
    return CRS(ProjectedCRS(conversion, LOCAL_CRS_NAME, geodetic_crs=_geodetic_crs(ellipsoid)))


@lru_cache(maxsize=64)
def _transformer(crs: CRS) -> Transformer:
    """Geographic (lon, lat) [deg] of the frame's own datum to local (east, north) [m]."""
    return Transformer.from_crs(crs.geodetic_crs, crs, always_xy=True)


@dataclass(frozen=True)
class LocalProjection:
    """Transverse Mercator about ``(lat_0, lon_0)`` shifted to the map origin.

    Parameters
    ----------
    lat_0, lon_0 : float
        Projection centre [deg] (usually the map centre).
    offset_north, offset_east : float
        Projected coordinates [m] of the local origin; subtracted so the origin is ``(0, 0)``
        (they are the negated false northing and easting of :attr:`crs`).
    ellipsoid : str
        PROJ ellipsoid name. ``"WGS84"`` (default) makes the frame's datum WGS 84
        (EPSG:4326); another name (``"GRS80"``) an unnamed datum on that ellipsoid.

    Examples
    --------
    >>> p = LocalProjection(36.8, -121.81)
    >>> north, east = p.to_local(np.array([36.8]), np.array([-121.81]))
    >>> float(abs(north[0])) < 1e-6 and float(abs(east[0])) < 1e-6
    True
    >>> p.crs.to_cf()["grid_mapping_name"]
    'transverse_mercator'
    >>> LocalProjection.from_crs(p.shifted(10.0, 20.0).crs) == p.shifted(10.0, 20.0)
    True
    """

    lat_0: float
    lon_0: float
    offset_north: float = 0.0
    offset_east: float = 0.0
    ellipsoid: str = "WGS84"

    def __post_init__(self) -> None:
        # The CRS is the one owner of the frame: the fields take the values it holds (PROJ keeps
        # 15 significant digits, a sub-nanometre change), so that from_crs(p.crs) == p.
        parameters = _frame_parameters(self.crs)
        assert parameters is not None  # a transverse Mercator with k = 1 by construction
        for name, value in zip(_PARAMETER_NAMES, parameters, strict=True):
            object.__setattr__(self, name, value)

    @property
    def crs(self) -> CRS:
        """The local frame as a projected CRS: x = east [m], y = north [m] from the origin."""
        return _local_crs(
            self.lat_0, self.lon_0, self.offset_north, self.offset_east, self.ellipsoid
        )

    def to_local(self, lat: FloatArray, lon: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Geographic ``(lat, lon)`` [deg] to local ``(north, east)`` [m]."""
        east, north = _transformer(self.crs).transform(
            np.asarray(lon, dtype=np.float64), np.asarray(lat, dtype=np.float64)
        )
        return np.asarray(north, dtype=np.float64), np.asarray(east, dtype=np.float64)

    def to_geographic(self, north: FloatArray, east: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Local ``(north, east)`` [m] to geographic ``(lat, lon)`` [deg]."""
        lon, lat = _transformer(self.crs).transform(
            np.asarray(east, dtype=np.float64),
            np.asarray(north, dtype=np.float64),
            direction="INVERSE",
        )
        return np.asarray(lat, dtype=np.float64), np.asarray(lon, dtype=np.float64)

    def shifted(self, north: float, east: float) -> LocalProjection:
        """The same projection with its origin moved to local ``(north, east)`` [m]."""
        return replace(
            self, offset_north=self.offset_north + north, offset_east=self.offset_east + east
        )

    @classmethod
    def from_crs(cls, crs: CRS) -> LocalProjection | None:
        """The local frame that ``crs`` is, or None if it is not one.

        ``crs`` is a local frame when it is equivalent (PROJ) to the :attr:`crs` of some
        LocalProjection: a transverse Mercator with scale factor 1 whose datum is WGS 84 (or
        an unnamed datum on a PROJ ellipsoid), e.g. read back from a CF ``grid_mapping``. A
        transverse Mercator on another datum (ETRS89, a Gauss-Krüger zone on DHDN) is not one:
        taking it as one would drop its datum shift to WGS 84.

        Examples
        --------
        >>> LocalProjection.from_crs(CRS("EPSG:31467")) is None  # DHDN / 3-degree GK zone 3
        True
        """
        parameters = _frame_parameters(crs)
        ellipsoid = _ellipsoid_name(crs)
        if parameters is None or ellipsoid is None:
            return None
        candidate = cls(*parameters, ellipsoid)
        return candidate if candidate.crs.equals(crs, ignore_axis_order=True) else None


_PARAMETER_NAMES: Final = ("lat_0", "lon_0", "offset_north", "offset_east")


@lru_cache(maxsize=64)
def _frame_parameters(crs: CRS) -> tuple[float, float, float, float] | None:
    """``(lat_0, lon_0, offset_north, offset_east)`` of a transverse Mercator with k = 1."""
    cf = crs.to_cf()
    if (
        cf.get("grid_mapping_name") != "transverse_mercator"
        or cf.get("scale_factor_at_central_meridian") != 1.0
    ):
        return None
    return (
        float(cf["latitude_of_projection_origin"]),
        float(cf["longitude_of_central_meridian"]),
        0.0 - float(cf["false_northing"]),
        0.0 - float(cf["false_easting"]),
    )


def _ellipsoid_name(crs: CRS) -> str | None:
    """PROJ name of the ellipsoid of ``crs`` (``"WGS84"`` for WGS 84), None if unknown."""
    ellipsoid = crs.ellipsoid
    if ellipsoid is None:
        return None
    known = get_ellps_map()
    for name in ("WGS84", *sorted(known)):
        a, rf = known[name]["a"], known[name].get("rf")
        if a == ellipsoid.semi_major_metre and rf == ellipsoid.inverse_flattening:
            return name
    return None
