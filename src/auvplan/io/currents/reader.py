"""Read a current file onto the mission's local frame (:func:`read_current`).

The steps, one module each: the velocity variables (:mod:`.variables`), the mission's time
slices (:mod:`.times`), the mission depth (:mod:`.levels`), the ROMS/CROCO C-grid
(:mod:`.roms`), and the horizontal grid: a regular lattice of the file's axes
(:mod:`.lattice`) or a curvilinear grid resampled onto a regular local one
(:mod:`.curvilinear`). Scale factors, offsets and fill values (HYCOM's int16) are decoded by
xarray; fill values are NaN, read as still water over land.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import AuvplanError, DataFormatError, InputError
from auvplan.io._gridded import _horizontal_axes
from auvplan.io._raster import first_line
from auvplan.io.currents import curvilinear, lattice
from auvplan.io.currents.levels import at_depth, vertical_dimension
from auvplan.io.currents.roms import rho_currents
from auvplan.io.currents.times import time_dimension, time_window
from auvplan.io.currents.variables import (
    Components,
    find_components,
    finite_values,
    velocity_values,
)
from auvplan.ocean import GriddedCurrent
from auvplan.terrain.grid import GridGeometry
from auvplan.terrain.spline import SplineSurface

if TYPE_CHECKING:
    from datetime import datetime
    from pathlib import Path

    import xarray as xr

    from auvplan.terrain.projection import LocalProjection

__all__ = ["read_current"]

#: ``(north_min, north_max), (east_min, east_max)`` [m] of the map.
Extent = tuple[tuple[float, float], tuple[float, float]]
#: The time dimension and the slices kept (None: no time axis).
TimeSlices = tuple[str, slice] | None


def read_current(
    path: Path,
    *,
    projection: LocalProjection | None,
    extent: Extent,
    start_time: datetime | None,
    depth: float,
    water: tuple[FloatArray, FloatArray] | None = None,
    horizon: float | None = None,
) -> GriddedCurrent:
    """Read a current file onto the mission's local frame (module notes).

    Parameters
    ----------
    path : Path
        NetCDF file.
    projection : LocalProjection or None
        The mission's local frame (None: the terrain has no geographic reference, and the file
        must be on the local ``north``/``east`` axes in metres).
    extent : ((float, float), (float, float))
        ``(north_min, north_max), (east_min, east_max)`` [m] of the map, which the file must cover.
    start_time : datetime or None
        UTC time of mission time 0 (None: the file's first time).
    depth : float
        Depth of the plan [m], interpolated linearly between the levels bracketing it.
    water : (ndarray, ndarray), optional
        ``north, east`` [m] of the map's water cells. The file's nodes nearest to them must
        hold values at every time: ocean models leave land NaN, which is read as still water
        (there is no vehicle there), but NaN over the map's water would plan a current that
        is not known as still water.
    horizon : float, optional
        Mission duration [s]: only the time slices around ``[0, horizon]`` are read (None:
        every slice from the start on).

    Returns
    -------
    GriddedCurrent

    Raises
    ------
    DataFormatError
        Unreadable file, no current variables, unknown units or calendar, irregular axes, no
        valid values, NaN over the map's water (naming the variable, the count and the first
        place).
    InputError
        The file does not cover the map or the mission's start time, or is georeferenced
        while the terrain is not.
    """
    import xarray as xr

    if not path.is_file():
        raise DataFormatError(f"current file {path}: not found")
    try:
        dataset = xr.open_dataset(path, decode_times=False, cache=False)
    except (OSError, ValueError, RuntimeError, TypeError, KeyError) as error:
        raise DataFormatError(f"current file {path}: unreadable ({first_line(error)})") from None
    try:
        with dataset:
            return _convert(dataset, projection, extent, start_time, depth, water, horizon)
    except AuvplanError as error:
        raise type(error)(f"current file {path.name}: {error}") from None
    except (
        ValueError,
        KeyError,
        TypeError,
        IndexError,
        OSError,
        RuntimeError,
        OverflowError,
    ) as error:
        raise DataFormatError(
            f"current file {path.name}: malformed ({first_line(error)})"
        ) from None


def _convert(
    dataset: xr.Dataset,
    projection: LocalProjection | None,
    extent: Extent,
    start_time: datetime | None,
    depth: float,
    water: tuple[FloatArray, FloatArray] | None,
    horizon: float | None,
) -> GriddedCurrent:
    components = find_components(dataset)
    time_dim = time_dimension(dataset, dataset[components.north])
    window = time_window(dataset, time_dim, start_time, horizon)
    time = None if window is None or time_dim is None else (time_dim, window.indices)
    if components.staggered:
        if projection is None:
            raise InputError("it is on lat/lon but the terrain has no lat/lon reference")
        slices, lat, lon = rho_currents(dataset, components, time, depth)
        geometry, slices = curvilinear.resample(lat, lon, slices, projection, extent)
        to_axes = lattice.IDENTITY
    else:
        geometry, slices, to_axes = _on_nodes(dataset, components, time, depth, projection, extent)
    names = (components.north, components.east)
    if not all(np.any(np.isfinite(s)) for s in slices):
        raise DataFormatError(f"{'/'.join(names)} hold no valid values over the map")
    if water is not None:
        for name, values in zip(names, slices, strict=True):
            lattice.check_water_values(name, values, geometry, to_axes, water)
    return GriddedCurrent(
        north_component=tuple(SplineSurface.fit(geometry, s) for s in slices[0]),
        east_component=tuple(SplineSurface.fit(geometry, s) for s in slices[1]),
        time_step=1.0 if window is None else window.time_step,
        start_offset=0.0 if window is None else window.start_offset,
        to_axes=to_axes,
    )


def _on_nodes(
    dataset: xr.Dataset,
    components: Components,
    time: TimeSlices,
    depth: float,
    projection: LocalProjection | None,
    extent: Extent,
) -> tuple[GridGeometry, list[FloatArray], FloatArray]:
    """Both components at ``depth`` on a regular grid, and its map from the local frame."""
    data = [dataset[components.north], dataset[components.east]]
    latlon = _curvilinear_coordinates(dataset, data[0])
    if latlon is not None:
        if projection is None:
            raise InputError("it is on lat/lon but the terrain has no lat/lon reference")
        lat, lon = (finite_values(dataset, name) for name in latlon)
        window = curvilinear.crop(lat, lon, projection, extent)
        row_dim, col_dim = map(str, dataset[latlon[0]].dims)
        slices = [_load(dataset, d, time, depth, (row_dim, col_dim), window) for d in data]
        lat, lon = lat[window], lon[window]
        return (*curvilinear.resample(lat, lon, slices, projection, extent), lattice.IDENTITY)
    row_name, col_name, is_latlon = _horizontal_axes(dataset, data[0], components.north)
    rows, cols = finite_values(dataset, row_name), finite_values(dataset, col_name)
    crs = lattice.file_crs(dataset, data[0], is_latlon, rows, cols, row_name)
    if crs is not None and crs.is_geographic:
        cols = np.unwrap(cols, period=360.0)  # a 0..360 subset across the prime meridian
    to_axes = lattice.affine(crs, projection, extent, cols)
    corner_rows, corner_cols = lattice.map_corners(to_axes, extent)
    window = (
        lattice.crop_axis(rows, corner_rows.min(), corner_rows.max()),
        lattice.crop_axis(cols, corner_cols.min(), corner_cols.max()),
    )
    rows, cols = rows[window[0]], cols[window[1]]
    if rows.size == 0 or cols.size == 0:
        raise curvilinear.not_covered(extent)
    dims = (str(dataset[row_name].dims[0]), str(dataset[col_name].dims[0]))
    slices = [_load(dataset, d, time, depth, dims, window) for d in data]
    try:
        geometry, slices = lattice.lattice(rows, cols, slices)
    except DataFormatError:
        if crs is None or not crs.is_geographic or projection is None:
            raise
        lat, lon = np.meshgrid(rows, cols, indexing="ij")  # uneven lat/lon axes (Mercator)
        return (*curvilinear.resample(lat, lon, slices, projection, extent), lattice.IDENTITY)
    lattice.check_coverage(to_axes, geometry, extent)
    return geometry, slices, to_axes


def _curvilinear_coordinates(dataset: xr.Dataset, data: xr.DataArray) -> tuple[str, str] | None:
    """Names of 2-D latitude/longitude variables on two of the dimensions of ``data``."""
    import cf_xarray  # noqa: F401  (registers the .cf accessor)
    import xarray as xr

    along = {
        str(name): variable
        for name, variable in dataset.variables.items()
        if variable.ndim == 2 and all(dim in data.dims for dim in variable.dims)
    }
    probe = xr.Dataset(coords=along).cf.guess_coord_axis()
    pairs = [
        (lat, lon)
        for lat in probe.cf.coordinates.get("latitude", [])
        for lon in probe.cf.coordinates.get("longitude", [])
        if along[lat].dims == along[lon].dims
    ]
    return pairs[0] if pairs else None


def _load(
    dataset: xr.Dataset,
    data: xr.DataArray,
    time: TimeSlices,
    depth: float,
    horizontal: tuple[str, str],
    window: tuple[slice, slice],
) -> FloatArray:
    """``data`` [m/s] at ``depth`` as ``(n_t, rows, cols)`` over the kept times and ``window``.

    Raises
    ------
    DataFormatError
        Unknown units, absurd values (:func:`~.variables.velocity_values`), or dimensions
        other than time, depth, the two horizontal ones and singletons.
    """
    if time is not None:
        data = data.isel({time[0]: time[1]})
    data = data.isel(dict(zip(horizontal, window, strict=True)))
    kept = {*horizontal, *([time[0]] if time else [])}
    level = vertical_dimension(dataset, data, kept)
    extra = [d for d in map(str, data.dims) if d not in kept and d != level and data.sizes[d] > 1]
    if extra:
        raise DataFormatError(f"{data.name} has unexpected dimensions {extra}")
    order = [d for d in (level, time[0] if time else None, *horizontal) if d]
    data = data.squeeze([d for d in data.dims if d not in order]).transpose(*order)
    values = velocity_values(data, data.values)
    if time is None:
        values = values[:, None] if level else values[None]
    if level is None:
        return values
    depths = np.abs(np.asarray(dataset[level].values, dtype=np.float64))
    increasing = np.argsort(depths)
    return at_depth(values[increasing], depths[increasing, None, None, None], depth)
