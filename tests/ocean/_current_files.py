"""Analytic CF-compliant current files (no network data): a field linear in lat, lon and time."""

from __future__ import annotations

from pathlib import Path
from typing import Final

import numpy as np

LAT_0: Final = 36.80
LON_0: Final = -121.81
#: The file's field: v = base + per_lat (lat - LAT_0) + per_lon (lon - LON_0) + per_hour t.
EAST: Final = {"base": 0.20, "per_lat": 8.0, "per_lon": -3.0, "per_hour": 0.01}
NORTH: Final = {"base": -0.10, "per_lat": 2.0, "per_lon": 5.0, "per_hour": -0.02}
#: Multiplier of the field at each depth level (the planner takes the level nearest depth_m).
LEVELS: Final = {0.0: 1.0, 10.0: 0.5, 50.0: 0.1}
START: Final = np.datetime64("2026-05-01T06:00:00")


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


def write_current_file(path: Path, *, names: tuple[str, str] | None = None) -> Path:
    """Write the field on a 0.004 deg lattice around (LAT_0, LON_0), 6 hours, 3 levels.

    ``names`` = ``(east, north)`` variable names without standard names (default: CF standard
    names on ``uo``/``vo``-free names ``east_velocity``/``north_velocity``).
    """
    import xarray as xr

    lat = LAT_0 + 0.004 * np.arange(-8, 9)
    lon = LON_0 + 0.004 * np.arange(-8, 9)
    hours = np.arange(6.0)
    time = START + (hours * 3600).astype("timedelta64[s]")
    depth = np.array(list(LEVELS))
    grid_t, grid_lat, grid_lon = np.meshgrid(hours, lat, lon, indexing="ij")
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
