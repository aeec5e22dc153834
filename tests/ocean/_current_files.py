"""Analytic current files in each provider's convention (no network data).

The field is linear in lat, lon and time, times a depth profile: piecewise linear through
:data:`LEVELS` on z-levels, ``1 - depth / 200 m`` on ROMS s-levels, so that linear depth
interpolation reproduces it exactly.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Final

import numpy as np

from auvplan.terrain import LocalProjection

LAT_0: Final = 36.80
LON_0: Final = -121.81
#: The file's field: v = base + per_lat (lat - LAT_0) + per_lon (lon - LON_0) + per_hour t.
EAST: Final = {"base": 0.20, "per_lat": 8.0, "per_lon": -3.0, "per_hour": 0.01}
NORTH: Final = {"base": -0.10, "per_lat": 2.0, "per_lon": 5.0, "per_hour": -0.02}
#: Multiplier of the field at each depth level [m] (linear between them).
LEVELS: Final = {0.0: 1.0, 10.0: 0.5, 50.0: 0.1}
START: Final = np.datetime64("2026-05-01T06:00:00")
#: The local frame centred on (LAT_0, LON_0) with its origin 1 km south-west.
PROJECTION: Final = LocalProjection(LAT_0, LON_0).shifted(-1000.0, -1000.0)
_HOURS: Final = np.arange(6.0)
_STEP_DEG: Final = 0.004


def analytic(
    coefficients: dict[str, float], lat: np.ndarray, lon: np.ndarray, hours: np.ndarray
) -> np.ndarray:
    """The field's component [m/s] at lat/lon [deg] and hours after :data:`START`."""
    return (
        coefficients["base"]
        + coefficients["per_lat"] * (lat - LAT_0)
        + coefficients["per_lon"] * (lon - LON_0)
        + coefficients["per_hour"] * hours
    )


def level_factor(depth: float) -> float:
    """The multiplier of :data:`LEVELS` at ``depth`` [m] (linear between levels)."""
    return float(np.interp(depth, list(LEVELS), list(LEVELS.values())))


def roms_factor(depth: np.ndarray | float) -> np.ndarray:
    """The multiplier of the ROMS files at ``depth`` [m]."""
    return 1.0 - np.asarray(depth, dtype=np.float64) / 200.0


def _time_coordinate(units: str, calendar: str = "standard") -> tuple[np.ndarray, dict[str, str]]:
    import cftime

    start = cftime.datetime(2026, 5, 1, 6, calendar=calendar)
    origin = float(cftime.date2num(start, units, calendar=calendar))
    per_hour = float(cftime.date2num(start + np.timedelta64(1, "h").item(), units, calendar))
    values = origin + (per_hour - origin) * _HOURS
    return values, {"units": units, "calendar": calendar, "standard_name": "time", "axis": "T"}


def write_current_file(path: Path, *, names: tuple[str, str] | None = None) -> Path:
    """Write the field on a 0.004 deg lattice around (LAT_0, LON_0), 6 hours, 3 levels.

    ``names`` = ``(east, north)`` variable names without standard names (default: CF standard
    names on ``uo``/``vo``-free names ``east_velocity``/``north_velocity``).
    """
    import xarray as xr

    lat = LAT_0 + _STEP_DEG * np.arange(-8, 9)
    lon = LON_0 + _STEP_DEG * np.arange(-8, 9)
    time = START + (_HOURS * 3600).astype("timedelta64[s]")
    depth = np.array(list(LEVELS))
    grid_t, grid_lat, grid_lon = np.meshgrid(_HOURS, lat, lon, indexing="ij")
    scale = np.array(list(LEVELS.values()))[None, :, None, None]

    def component(coefficients: dict[str, float]) -> np.ndarray:
        return scale * analytic(coefficients, grid_lat, grid_lon, grid_t)[:, None]

    east_name, north_name = names or ("east_velocity", "north_velocity")
    attributes = {} if names else {"east": "eastward", "north": "northward"}
    variables = {}
    for name, key, coefficients in ((east_name, "east", EAST), (north_name, "north", NORTH)):
        attrs = {"units": "m s-1", "long_name": f"{key}ward sea water velocity"}
        if key in attributes:
            attrs["standard_name"] = f"{attributes[key]}_sea_water_velocity"
        variables[name] = (("time", "depth", "lat", "lon"), component(coefficients), attrs)
    dataset = xr.Dataset(
        variables,
        coords={
            "time": ("time", time, {"standard_name": "time", "axis": "T"}),
            "depth": (
                "depth",
                depth,
                {"standard_name": "depth", "units": "m", "positive": "down", "axis": "Z"},
            ),
            "lat": ("lat", lat, {"standard_name": "latitude", "units": "degrees_north"}),
            "lon": ("lon", lon, {"standard_name": "longitude", "units": "degrees_east"}),
        },
        attrs={
            "Conventions": "CF-1.8",
            "title": "analytic test current",
            "history": "written by the auvplan test suite",
        },
    )
    encoding: dict[str, dict[str, object]] = {
        name: {"_FillValue": None} for name in ("depth", "lat", "lon")
    }
    encoding["time"] = {"_FillValue": None, "dtype": "float64", "units": "hours since 2026-05-01"}
    dataset.to_netcdf(path, encoding=encoding)
    return path


def _z_level_values(
    lat: np.ndarray, lon: np.ndarray, depths: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``(east, north)`` of shape ``(n_t, n_levels, *lat.shape)`` on 1-D or 2-D lat/lon."""
    hours = _HOURS.reshape(-1, *([1] * lat.ndim))
    scale = np.array([level_factor(d) for d in depths]).reshape(1, -1, *([1] * lat.ndim))
    east, north = (analytic(c, lat[None], lon[None], hours)[:, None] for c in (EAST, NORTH))
    return scale * east, scale * north


def write_hycom(path: Path, *, land: tuple[slice, slice] | None = None) -> Path:
    """HYCOM as served by its THREDDS NCSS: ``water_u``/``water_v`` int16 (scale 0.001,
    ``_FillValue`` −30000) on time/depth/lat/lon, longitudes 0..360, time in ``hours since
    2000-01-01 00:00:00``; fill at the ``land`` nodes ``[rows, cols]`` of every level."""
    import xarray as xr

    lat = LAT_0 + _STEP_DEG * np.arange(-8, 9)
    lon = LON_0 + 360.0 + _STEP_DEG * np.arange(-8, 9)
    grid_lat, grid_lon = np.meshgrid(lat, lon - 360.0, indexing="ij")
    east, north = _z_level_values(grid_lat, grid_lon, np.array(list(LEVELS)))
    if land is not None:
        for values in (east, north):
            values[:, :, land[0], land[1]] = np.nan
    time, time_attrs = _time_coordinate("hours since 2000-01-01 00:00:00", "gregorian")
    dims = ("time", "depth", "lat", "lon")
    dataset = xr.Dataset(
        {
            "water_u": (dims, east, {"units": "m/s", "long_name": "Eastward Water Velocity"}),
            "water_v": (dims, north, {"units": "m/s", "long_name": "Northward Water Velocity"}),
        },
        coords={
            "time": ("time", time, time_attrs),
            "depth": ("depth", list(LEVELS), {"units": "m", "positive": "down", "axis": "Z"}),
            "lat": ("lat", lat, {"units": "degrees_north", "axis": "Y"}),
            "lon": ("lon", lon, {"units": "degrees_east", "axis": "X"}),
        },
    )
    packed = {
        "dtype": "int16", "scale_factor": 0.001, "add_offset": 0.0, "_FillValue": -30000,
    }  # fmt: skip
    dataset.to_netcdf(path, encoding={"water_u": packed, "water_v": packed})
    return path


def write_copernicus(path: Path) -> Path:
    """Copernicus Marine GLO PHY: ``uo``/``vo`` on time/depth/latitude/longitude, time in
    ``hours since 1950-01-01``, standard names, first level 0.494 m."""
    import xarray as xr

    lat = LAT_0 + _STEP_DEG * np.arange(-8, 9)
    lon = LON_0 + _STEP_DEG * np.arange(-8, 9)
    depth = np.array([0.494, *list(LEVELS)[1:]])
    east, north = _z_level_values(*np.meshgrid(lat, lon, indexing="ij"), depth)
    time, time_attrs = _time_coordinate("hours since 1950-01-01", "gregorian")
    dims = ("time", "depth", "latitude", "longitude")
    dataset = xr.Dataset(
        {
            "uo": (
                dims,
                east.astype(np.float32),
                {"units": "m s-1", "standard_name": "eastward_sea_water_velocity"},
            ),
            "vo": (
                dims,
                north.astype(np.float32),
                {"units": "m s-1", "standard_name": "northward_sea_water_velocity"},
            ),
        },
        coords={
            "time": ("time", time, time_attrs),
            "depth": ("depth", depth, {"units": "m", "positive": "down", "standard_name": "depth"}),
            "latitude": ("latitude", lat, {"units": "degrees_north", "standard_name": "latitude"}),
            "longitude": (
                "longitude",
                lon,
                {"units": "degrees_east", "standard_name": "longitude"},
            ),
        },
    )
    dataset.to_netcdf(path)
    return path


def write_rtofs(path: Path, *, three_d: bool) -> Path:
    """NOAA RTOFS global: rows evenly spaced in Mercator y (uneven in latitude), 2-D
    ``Latitude``/``Longitude`` (Y, X) with longitudes in its 74..434 convention, index
    coordinates ``X``/``Y``, time ``MT`` in ``days since 1900-12-31``; 2-D files hold
    ``u_velocity``/``v_velocity`` on one ``Layer``, 3-D files ``u``/``v`` on ``Depth``."""
    import xarray as xr

    mercator = np.arcsinh(np.tan(np.radians(LAT_0))) + np.radians(_STEP_DEG) * np.arange(-8, 9)
    lat_1d = np.degrees(np.arctan(np.sinh(mercator)))
    lon_1d = LON_0 + 360.0 + _STEP_DEG * np.arange(-8, 9)
    lat, lon = np.meshgrid(lat_1d, lon_1d, indexing="ij")
    east, north = _z_level_values(lat, lon - 360.0, np.array(list(LEVELS)))
    time, time_attrs = _time_coordinate("days since 1900-12-31 00:00:00")
    time_attrs.pop("standard_name")
    time_attrs.pop("axis")
    if three_d:
        names, level = ("u", "v"), ("Depth", np.array(list(LEVELS)))
        level_attrs = {"units": "m", "positive": "down"}
    else:
        names, level = ("u_velocity", "v_velocity"), ("Layer", np.array([1.0]))
        east, north, level_attrs = east[:, :1], north[:, :1], {"units": "layer"}
    dims = ("MT", level[0], "Y", "X")
    dataset = xr.Dataset(
        {
            names[0]: (
                dims,
                east.astype(np.float32),
                {"units": "m/s", "coordinates": "Longitude Latitude"},
            ),
            names[1]: (
                dims,
                north.astype(np.float32),
                {"units": "m/s", "coordinates": "Longitude Latitude"},
            ),
            "Latitude": (("Y", "X"), lat.astype(np.float32), {"units": "degrees_north"}),
            "Longitude": (("Y", "X"), lon.astype(np.float32), {"units": "degrees_east"}),
        },
        coords={
            "MT": ("MT", time, time_attrs),
            level[0]: (level[0], level[1], level_attrs),
            "Y": ("Y", np.arange(1, lat.shape[0] + 1, dtype=np.int32), {"point_spacing": "even"}),
            "X": ("X", np.arange(1, lat.shape[1] + 1, dtype=np.int32), {"point_spacing": "even"}),
        },
    )
    dataset.to_netcdf(path)
    return path


def write_roms(
    path: Path,
    *,
    angle_deg: float,
    east: dict[str, float] = EAST,
    north: dict[str, float] = NORTH,
    calendar: str = "noleap",
    land: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
) -> Path:
    """ROMS output on a C-grid whose ξ axis points ``angle_deg`` north of east, centred on
    the map: ``u``/``v`` on (ocean_time, s_rho, eta_u, xi_u) / (…, eta_v, xi_v), ten
    s-levels (``Vtransform`` 2, ``Cs_r = -s²``, ``h`` = 100 m, ``hc`` = 10 m), ``lat_rho``,
    ``lon_rho``, ``angle`` [rad], ``ocean_time`` in seconds in ``calendar``. ``land(north,
    east)`` [m] marks ρ cells of land (``mask_*`` = 0 and zero velocity, as ROMS writes)."""
    import xarray as xr

    alpha = np.radians(angle_deg)
    n_eta, n_xi, spacing = 30, 30, 150.0
    s = (np.arange(10) + 0.5) / 10 - 1.0
    stretching = -(s**2)
    h, hc = 100.0, 10.0
    depth = -h * (hc * s + h * stretching) / (hc + h)

    def local(xi: np.ndarray, eta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Local (north, east) [m] of grid indices: ξ along (cos α, sin α) east/north."""
        x, y = (xi - (n_xi - 1) / 2) * spacing, (eta - (n_eta - 1) / 2) * spacing
        north = 1000.0 + x * np.sin(alpha) + y * np.cos(alpha)
        return north, 1000.0 + x * np.cos(alpha) - y * np.sin(alpha)

    def grid_components(xi: np.ndarray, eta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        lat, lon = PROJECTION.to_geographic(*local(xi, eta))
        hours = _HOURS[:, None, None, None]
        factor = roms_factor(depth)[None, :, None, None]
        v_e = factor * analytic(east, lat, lon, hours)
        v_n = factor * analytic(north, lat, lon, hours)
        along_xi = v_e * np.cos(alpha) + v_n * np.sin(alpha)
        return along_xi, -v_e * np.sin(alpha) + v_n * np.cos(alpha)

    eta_rho, xi_rho = np.meshgrid(np.arange(n_eta), np.arange(n_xi), indexing="ij")
    u, _ = grid_components(*np.meshgrid(np.arange(n_xi - 1) + 0.5, np.arange(n_eta)))
    _, v = grid_components(*np.meshgrid(np.arange(n_xi), np.arange(n_eta - 1) + 0.5))
    lat, lon = PROJECTION.to_geographic(*local(xi_rho.astype(float), eta_rho.astype(float)))
    mask = np.ones((n_eta, n_xi))
    if land is not None:
        mask[land(*local(xi_rho.astype(float), eta_rho.astype(float)))] = 0.0
    mask_u, mask_v = mask[:, :-1] * mask[:, 1:], mask[:-1] * mask[1:]
    u, v = u * mask_u, v * mask_v
    time, time_attrs = _time_coordinate("seconds since 2000-01-01 00:00:00", calendar)
    dataset = xr.Dataset(
        {
            "u": (
                ("ocean_time", "s_rho", "eta_u", "xi_u"),
                u,
                {"units": "meter second-1", "standard_name": "sea_water_x_velocity_at_u_location"},
            ),
            "v": (
                ("ocean_time", "s_rho", "eta_v", "xi_v"),
                v,
                {"units": "meter second-1", "standard_name": "sea_water_y_velocity_at_v_location"},
            ),
            "lat_rho": (("eta_rho", "xi_rho"), lat, {"units": "degree_north"}),
            "lon_rho": (("eta_rho", "xi_rho"), lon, {"units": "degree_east"}),
            "angle": (("eta_rho", "xi_rho"), np.full(lat.shape, alpha), {"units": "radians"}),
            "mask_rho": (("eta_rho", "xi_rho"), mask),
            "mask_u": (("eta_u", "xi_u"), mask_u),
            "mask_v": (("eta_v", "xi_v"), mask_v),
            "h": (("eta_rho", "xi_rho"), np.full(lat.shape, h), {"units": "meter"}),
            "hc": ((), hc),
            "Cs_r": (("s_rho",), stretching),
            "Vtransform": ((), 2),
        },
        coords={
            "ocean_time": ("ocean_time", time, time_attrs),
            "s_rho": ("s_rho", s, {"positive": "up", "standard_name": "ocean_s_coordinate_g2"}),
        },
    )
    dataset.to_netcdf(path)
    return path
