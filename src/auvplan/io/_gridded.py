"""Gridded bathymetry formats: NetCDF (xarray/netCDF4) and GeoTIFF / ESRI ASCII (rasterio).

Each reader returns the :class:`~auvplan.io._raster.Raster` as stored, with increasing axes,
for the conversion in :mod:`auvplan.io.bathymetry`.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import numpy as np
from pyproj import CRS

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError
from auvplan.io._complete import (
    check_ascii_grid_complete,
    check_netcdf_complete,
    check_tiff_complete,
)
from auvplan.io._raster import Raster, first_line, increasing, looks_geographic
from auvplan.terrain.projection import GEOGRAPHIC_CRS

if TYPE_CHECKING:
    from pathlib import Path

    import xarray as xr

#: Preferred names of the elevation/depth variable when a file holds several 2-D variables.
_DATA_NAMES = ("depth", "elevation", "z", "Band1", "topo", "height", "bathymetry", "altitude")

#: Names of auvplan's own local-frame axes (``maps.nc`` and metric grids), known without
#: attributes; any other axis is recognised by cf_xarray (attributes, then names).
_NORTH_NAME, _EAST_NAME = "north", "east"
#: Attribute naming the vertical datum of the depths or elevations (``"NAVD88"``, ``"MSL"``),
#: on the data variable or the file; kept in the grid's attributes and written to ``maps.nc``.
VERTICAL_DATUM = "vertical_datum"


# --- NetCDF --------------------------------------------------------------------------------


def read_netcdf(path: Path) -> Raster:
    """Read the elevation/depth variable of a NetCDF file, its axes and its CRS.

    The variable is the one 2-D variable (after dropping singleton dimensions), or the first
    of :data:`_DATA_NAMES` among several. Its axes are the 1-D variables along its two
    dimensions, told apart by cf_xarray (``axis``, ``standard_name``, ``units``, then names
    such as ``lat``/``lon``/``y``/``x``). The CRS is the CF ``grid_mapping`` of the variable
    (:meth:`pyproj.CRS.from_cf`, which also reads ``crs_wkt`` and GDAL's ``spatial_ref``);
    without one, latitude/longitude axes are WGS 84 and metric axes have no georeference.
    The variable's (else the file's) :data:`VERTICAL_DATUM`, if any, is kept in the
    attributes.
    """
    import xarray as xr

    check_netcdf_complete(path)
    try:
        dataset = xr.open_dataset(path, decode_times=False, cache=False)
    except (OSError, ValueError, RuntimeError, TypeError, KeyError) as error:
        raise DataFormatError(f"unreadable NetCDF ({first_line(error)})") from None
    with dataset:
        data_name = _pick_data_variable(dataset)
        data = dataset[data_name].squeeze(drop=True)
        north_name, east_name, is_latlon = _horizontal_axes(dataset, data, data_name)
        north_var, east_var = dataset.variables[north_name], dataset.variables[east_name]
        values = np.asarray(
            data.transpose(north_var.dims[0], east_var.dims[0]).values, dtype=np.float64
        )
        positive = str(data.attrs.get("positive", "")).lower()
        is_depth: bool | None = (
            True
            if data_name == "depth" or positive == "down"
            else False
            if data_name == "elevation" or positive == "up"
            else None
        )
        attributes = {"variable": data_name}
        for key in ("title", "source", "license"):
            if key in dataset.attrs:
                attributes[key] = first_line(dataset.attrs[key])
        datum = data.attrs.get(VERTICAL_DATUM, dataset.attrs.get(VERTICAL_DATUM))
        if datum is not None:
            attributes[VERTICAL_DATUM] = first_line(datum)
        north_axis = np.asarray(north_var.values, dtype=np.float64)
        east_axis = np.asarray(east_var.values, dtype=np.float64)
        crs = grid_mapping_crs(dataset, data)
        is_local = (north_name, east_name) == (_NORTH_NAME, _EAST_NAME)
        if crs is None and not is_local:
            units = str(east_var.attrs.get("units", "")).lower()
            if _is_geographic(units, is_latlon, north_axis, east_axis):
                crs = CRS(GEOGRAPHIC_CRS)
    values, north_axis, east_axis = increasing(values, north_axis, east_axis)
    return Raster(values, north_axis, east_axis, crs, is_depth, attributes)


def _pick_data_variable(dataset: xr.Dataset) -> str:
    candidates = [
        str(name)
        for name, variable in dataset.data_vars.items()
        if sum(size > 1 for size in variable.shape) == 2
    ]
    for name in _DATA_NAMES:
        if name in candidates:
            return name
    if len(candidates) == 1:
        return candidates[0]
    if not candidates:
        raise DataFormatError(
            "no 2-D elevation/depth variable on lat/lon (or north/east, y/x) coordinate "
            f"variables; has {sorted(map(str, dataset.variables))}"
        )
    raise DataFormatError(f"cannot tell the elevation/depth variable among {candidates}")


def _horizontal_axes(
    dataset: xr.Dataset, data: xr.DataArray, data_name: str
) -> tuple[str, str, bool]:
    """Names of the 1-D (north-like, east-like) axes of ``data``; True if they are lat/lon."""
    import cf_xarray  # noqa: F401  (registers the .cf accessor)
    import xarray as xr

    along = {
        str(name): variable
        for name, variable in dataset.variables.items()
        if variable.ndim == 1 and variable.dims[0] in data.dims
    }
    probe = xr.Dataset(coords=along).cf.guess_coord_axis()
    latitude = probe.cf.coordinates.get("latitude", [])
    longitude = probe.cf.coordinates.get("longitude", [])
    north = [
        *latitude,
        *probe.cf.axes.get("Y", []),
        *([_NORTH_NAME] if _NORTH_NAME in along else []),
    ]
    east = [*longitude, *probe.cf.axes.get("X", []), *([_EAST_NAME] if _EAST_NAME in along else [])]
    pairs = [(n, e) for n in north for e in east if along[n].dims[0] != along[e].dims[0]]
    if not pairs:
        raise DataFormatError(
            f"no lat/lon (or north/east, y/x) coordinate variables along the dimensions "
            f"{data.dims} of {data_name}; has {sorted(map(str, dataset.variables))}"
        )
    north_name, east_name = pairs[0]
    return north_name, east_name, north_name in latitude and east_name in longitude


def grid_mapping_crs(dataset: xr.Dataset, data: xr.DataArray) -> CRS | None:
    """The CRS of the CF ``grid_mapping`` variable of ``data``, if it names one that exists."""
    from pyproj.exceptions import CRSError

    reference = str(data.attrs.get("grid_mapping", data.encoding.get("grid_mapping", "")))
    name = reference.split(":", 1)[0].strip()  # also the extended form "crs: x y"
    if not name or name not in dataset.variables:
        return None
    try:
        return CRS.from_cf(dict(dataset[name].attrs))
    except (CRSError, KeyError, ValueError) as error:
        raise DataFormatError(
            f"grid_mapping variable {name} is not a usable CRS ({first_line(error)})"
        ) from None


def _is_geographic(
    units: str, is_latlon: bool, north_axis: FloatArray, east_axis: FloatArray
) -> bool:
    """Whether axes other than auvplan's ``north``/``east`` are latitude/longitude.

    True when cf_xarray named them latitude/longitude (attributes or names), when the east
    axis ``units`` are degrees, or when unit-less values fit the lat/lon ranges with a step
    below 0.05 (:func:`~auvplan.io._raster.looks_geographic`).
    """
    return (
        is_latlon
        or "deg" in units
        or (units in ("", "1") and looks_geographic(north_axis, east_axis))
    )


# --- GeoTIFF and ESRI ASCII grid -----------------------------------------------------------


def read_rasterio(path: Path) -> Raster:
    """Read band 1 of a GeoTIFF or ESRI ASCII grid (rasterio), its axes and its CRS.

    The file must hold every value its header declares (:mod:`auvplan.io._complete`); GDAL's
    own read errors are reported by their first cause, not by rasterio's summary.
    """
    import rasterio
    from rasterio.errors import NotGeoreferencedWarning, RasterioIOError

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NotGeoreferencedWarning)
            with rasterio.open(path) as source:
                if source.driver == "GTiff":
                    check_tiff_complete(source, path.stat().st_size)
                elif source.driver == "AAIGrid":
                    check_ascii_grid_complete(path, source.height, source.width)
                band = source.read(1, masked=True)
                transform, crs = source.transform, source.crs
    except (RasterioIOError, ValueError, IndexError) as error:
        raise DataFormatError(f"unreadable raster ({first_line(_root_cause(error))})") from None
    values = np.asarray(np.ma.filled(band.astype(np.float64), np.nan))
    if transform.b != 0.0 or transform.d != 0.0:
        raise DataFormatError("rotated rasters are not supported")
    n_rows, n_cols = values.shape
    east_axis = transform.c + transform.a * (np.arange(n_cols) + 0.5)
    north_axis = transform.f + transform.e * (np.arange(n_rows) + 0.5)
    values, north_axis, east_axis = increasing(values, north_axis, east_axis)
    if crs is not None:
        georeference: CRS | None = CRS.from_user_input(crs)
    elif looks_geographic(north_axis, east_axis):
        georeference = CRS(GEOGRAPHIC_CRS)
    else:
        georeference = None
    return Raster(values, north_axis, east_axis, georeference, None)


def _root_cause(error: BaseException) -> BaseException:
    """The first error of a chain: GDAL's own message behind rasterio's "See previous exception"."""
    while (cause := error.__cause__ or error.__context__) is not None:
        error = cause
    return error
