"""Gridded bathymetry formats: NetCDF (xarray/netCDF4) and GeoTIFF / ESRI ASCII (rasterio).

Each reader returns the :class:`~auvplan.io._raster.Raster` as stored, with increasing axes,
for the conversion in :mod:`auvplan.io.bathymetry`.
"""

from __future__ import annotations

import warnings
from collections.abc import Hashable
from typing import TYPE_CHECKING

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError
from auvplan.io._raster import Raster, first_line, increasing, looks_geographic
from auvplan.terrain.projection import LocalProjection

if TYPE_CHECKING:
    from pathlib import Path

    import xarray as xr

_LAT_NAMES = ("lat", "latitude", "y")
_LON_NAMES = ("lon", "longitude", "x")
_DATA_NAMES = ("depth", "elevation", "z", "Band1", "topo", "height", "bathymetry", "altitude")


# --- NetCDF --------------------------------------------------------------------------------


def read_netcdf(path: Path) -> Raster:
    import xarray as xr

    try:
        dataset = xr.open_dataset(path, decode_times=False, cache=False)
    except (OSError, ValueError, RuntimeError, TypeError, KeyError) as error:
        raise DataFormatError(f"unreadable NetCDF ({first_line(error)})") from None
    with dataset:
        names = set(dataset.variables)
        if {"north", "east"} <= names:
            lat_name, lon_name, is_geographic = "north", "east", False
        else:
            lat_name = next((n for n in _LAT_NAMES if n in names), "")
            lon_name = next((n for n in _LON_NAMES if n in names), "")
            if not lat_name or not lon_name:
                raise DataFormatError(
                    "no lat/lon (or north/east) coordinate variables; "
                    f"has {sorted(map(str, names))}"
                )
            units = str(dataset[lon_name].attrs.get("units", "")).lower()
            # Without units, variables named lat/lon are geographic; x/y are if they look so.
            is_geographic = "deg" in units or (
                units in ("", "1")
                and (
                    (lat_name, lon_name) != ("y", "x")
                    or looks_geographic(dataset[lat_name].values, dataset[lon_name].values)
                )
            )
        lat_var, lon_var = dataset[lat_name], dataset[lon_name]
        if lat_var.ndim != 1 or lon_var.ndim != 1:
            raise DataFormatError(f"coordinates {lat_name}/{lon_name} must be 1-D")
        lat_dim, lon_dim = lat_var.dims[0], lon_var.dims[0]
        data_name = _pick_data_variable(dataset, lat_dim, lon_dim)
        data = dataset[data_name].squeeze(drop=True)
        if set(data.dims) != {lat_dim, lon_dim}:
            raise DataFormatError(
                f"variable {data_name} has dimensions {data.dims}, not ({lat_dim}, {lon_dim})"
            )
        values = np.asarray(data.transpose(lat_dim, lon_dim).values, dtype=np.float64)
        positive = str(data.attrs.get("positive", "")).lower()
        is_depth: bool | None = (
            True
            if data_name == "depth" or positive == "down"
            else False
            if data_name == "elevation" or positive == "up"
            else None
        )
        attributes = {"variable": str(data_name)}
        for key in ("title", "source", "license"):
            if key in dataset.attrs:
                attributes[key] = first_line(dataset.attrs[key])
        projection = _projection_from_attributes(dict(dataset.attrs)) if not is_geographic else None
        north_axis = np.asarray(lat_var.values, dtype=np.float64)
        east_axis = np.asarray(lon_var.values, dtype=np.float64)
    values, north_axis, east_axis = increasing(values, north_axis, east_axis)
    return Raster(
        values,
        north_axis,
        east_axis,
        is_geographic,
        is_depth,
        projection,
        None if projection is None else projection.to_local,
        attributes,
    )


def _pick_data_variable(dataset: xr.Dataset, lat_dim: Hashable, lon_dim: Hashable) -> str:
    candidates = [
        str(name)
        for name, variable in dataset.data_vars.items()
        if {lat_dim, lon_dim} <= set(variable.dims)
        and variable.size == (dataset.sizes[lat_dim] * dataset.sizes[lon_dim])
    ]
    for name in _DATA_NAMES:
        if name in candidates:
            return name
    if len(candidates) == 1:
        return candidates[0]
    raise DataFormatError(
        f"cannot tell the elevation/depth variable on ({lat_dim}, {lon_dim}) among {candidates}"
    )


def _projection_from_attributes(attributes: dict[str, object]) -> LocalProjection | None:
    """The LocalProjection recorded by :func:`auvplan.io.maps_file.write_maps_netcdf`."""
    keys = (
        "projection_lat_0",
        "projection_lon_0",
        "projection_offset_north",
        "projection_offset_east",
    )
    if not all(key in attributes for key in keys):
        return None
    lat_0, lon_0, offset_north, offset_east = (float(attributes[k]) for k in keys)  # type: ignore[arg-type]
    ellipsoid = str(attributes.get("projection_ellipsoid", "WGS84"))
    return LocalProjection(lat_0, lon_0, offset_north, offset_east, ellipsoid)


# --- GeoTIFF and ESRI ASCII grid -----------------------------------------------------------


def read_rasterio(path: Path) -> Raster:
    import rasterio
    from rasterio.errors import NotGeoreferencedWarning, RasterioIOError

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NotGeoreferencedWarning)
            with rasterio.open(path) as source:
                band = source.read(1, masked=True)
                transform, crs = source.transform, source.crs
    except (RasterioIOError, ValueError, IndexError) as error:
        raise DataFormatError(f"unreadable raster ({first_line(error)})") from None
    values = np.asarray(np.ma.filled(band.astype(np.float64), np.nan))
    if transform.b != 0.0 or transform.d != 0.0:
        raise DataFormatError("rotated rasters are not supported")
    n_rows, n_cols = values.shape
    east_axis = transform.c + transform.a * (np.arange(n_cols) + 0.5)
    north_axis = transform.f + transform.e * (np.arange(n_rows) + 0.5)
    values, north_axis, east_axis = increasing(values, north_axis, east_axis)
    attributes: dict[str, str] = {}
    to_native = None
    if crs is not None:
        attributes["crs"] = crs.to_string()
        is_geographic = bool(crs.is_geographic)
        if not is_geographic:
            from pyproj import Transformer

            transformer = Transformer.from_crs("EPSG:4326", crs, always_xy=True)

            def to_native(lat: FloatArray, lon: FloatArray) -> tuple[FloatArray, FloatArray]:
                east, north = transformer.transform(lon, lat)
                return np.asarray(north), np.asarray(east)
    else:
        is_geographic = looks_geographic(north_axis, east_axis)
    return Raster(values, north_axis, east_axis, is_geographic, None, None, to_native, attributes)
