"""Ocean current files (NetCDF) as a :class:`~auvplan.ocean.GriddedCurrent` in the local frame.

The two components are found by CF standard name (``eastward_sea_water_velocity`` /
``northward_sea_water_velocity``), else by the common variable names (Copernicus Marine
``uo``/``vo``, HYCOM ``water_u``/``water_v``, plain ``u``/``v``). Their horizontal axes are
recognised as for bathymetry (:mod:`auvplan.io._gridded`: cf_xarray, then names; a CF
``grid_mapping`` gives a projected CRS), an optional time axis (CF ``T``) is taken relative to
the mission's start time (or to the file's first time), and of an optional depth axis (CF ``Z``)
the level nearest the mission depth. The file's axes map to the local frame by the affine
approximation of the PROJ transformation at the map centre (its error over a few kilometres is
far below a current grid's cell); east and north are taken as the local frame's axes (the
meridian convergence is below 0.1 deg on such maps).
"""

from __future__ import annotations

from datetime import datetime
from typing import TYPE_CHECKING, Final

import numpy as np
from pyproj import CRS, Transformer

from auvplan._typing import FloatArray
from auvplan.errors import AuvplanError, DataFormatError, InputError
from auvplan.io._gridded import _horizontal_axes, _is_geographic, grid_mapping_crs
from auvplan.io._raster import first_line
from auvplan.ocean import GriddedCurrent
from auvplan.terrain.grid import GridGeometry
from auvplan.terrain.projection import GEOGRAPHIC_CRS, LocalProjection
from auvplan.terrain.spline import SplineSurface

if TYPE_CHECKING:
    from pathlib import Path

    import xarray as xr

__all__ = ["CURRENT_NAMES", "read_current"]

#: ``(east, north)`` names tried in order after the CF standard names.
CURRENT_NAMES: Final = (("uo", "vo"), ("water_u", "water_v"), ("u", "v"))
_STANDARD_NAMES: Final = ("eastward_sea_water_velocity", "northward_sea_water_velocity")
#: Velocity units understood, with their factor to m/s.
_UNITS: Final = {
    "m s-1": 1.0, "m/s": 1.0, "m s**-1": 1.0, "m.s-1": 1.0, "meter second-1": 1.0,
    "meters/second": 1.0, "meter/second": 1.0, "cm s-1": 0.01, "cm/s": 0.01,
}  # fmt: skip
#: Step [m] of the finite differences of the PROJ transformation at the map centre.
_JACOBIAN_STEP_M: Final = 100.0


def read_current(
    path: Path,
    *,
    projection: LocalProjection | None,
    extent: tuple[tuple[float, float], tuple[float, float]],
    start_time: datetime | None,
    depth: float,
    water: tuple[FloatArray, FloatArray] | None = None,
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
        Depth of the plan [m]; the level nearest it is taken.
    water : (ndarray, ndarray), optional
        ``north, east`` [m] of the map's water cells. The file's nodes nearest to them must
        hold values at every time: ocean models leave land NaN, which is read as still water
        (there is no vehicle there), but NaN over the map's water would plan a current that
        is not known as still water.

    Returns
    -------
    GriddedCurrent

    Raises
    ------
    DataFormatError
        Unreadable file, no current variables, unknown units, irregular axes, no valid values,
        NaN over the map's water (naming the variable, the count and the first place).
    InputError
        The file does not cover the map or the mission's start time, or is georeferenced
        while the terrain is not.
    """
    import xarray as xr

    if not path.is_file():
        raise DataFormatError(f"current file {path}: not found")
    try:
        dataset = xr.open_dataset(path, cache=False)
    except (OSError, ValueError, RuntimeError, TypeError, KeyError) as error:
        raise DataFormatError(f"current file {path}: unreadable ({first_line(error)})") from None
    try:
        with dataset:
            return _convert(dataset, projection, extent, start_time, depth, water)
    except AuvplanError as error:
        raise type(error)(f"current file {path.name}: {error}") from None
    except (ValueError, KeyError, TypeError, IndexError) as error:
        raise DataFormatError(
            f"current file {path.name}: malformed ({first_line(error)})"
        ) from None


def _component_names(dataset: xr.Dataset) -> tuple[str, str]:
    by_standard = {
        str(variable.attrs.get("standard_name", "")): str(name)
        for name, variable in dataset.data_vars.items()
    }
    if all(name in by_standard for name in _STANDARD_NAMES):
        return by_standard[_STANDARD_NAMES[0]], by_standard[_STANDARD_NAMES[1]]
    for east, north in CURRENT_NAMES:
        if east in dataset.data_vars and north in dataset.data_vars:
            return east, north
    raise DataFormatError(
        f"no current variables (standard_name {' / '.join(_STANDARD_NAMES)}, or "
        f"{', '.join('/'.join(pair) for pair in CURRENT_NAMES)}); has "
        f"{sorted(map(str, dataset.data_vars))}"
    )


def _select(data: xr.DataArray, depth: float) -> tuple[xr.DataArray, str | None]:
    """The level nearest ``depth`` [m] (CF ``Z`` axis) and the time dimension (CF ``T``)."""
    for name in data.cf.axes.get("Z", []):
        if data[name].ndim == 1 and data.sizes[data[name].dims[0]] > 1:
            levels = np.abs(np.asarray(data[name].values, dtype=np.float64))
            data = data.isel({data[name].dims[0]: int(np.argmin(np.abs(levels - depth)))})
    times = [str(data[name].dims[0]) for name in data.cf.axes.get("T", []) if data[name].ndim == 1]
    return data, times[0] if times else None


def _convert(
    dataset: xr.Dataset,
    projection: LocalProjection | None,
    extent: tuple[tuple[float, float], tuple[float, float]],
    start_time: datetime | None,
    depth: float,
    water: tuple[FloatArray, FloatArray] | None,
) -> GriddedCurrent:
    import cf_xarray  # noqa: F401  (registers the .cf accessor)

    east_name, north_name = _component_names(dataset)
    dataset = dataset.cf.guess_coord_axis()
    components = []
    time_dim: str | None = None
    for name in (north_name, east_name):
        data, time_dim = _select(dataset[name], depth)
        units = str(data.attrs.get("units", "m s-1")).strip()
        if units not in _UNITS:
            raise DataFormatError(f"{name} has units {units!r}, not a velocity (m s-1)")
        components.append((data, _UNITS[units]))
    data = components[0][0]
    row_name, col_name, is_latlon = _horizontal_axes(dataset, data, north_name)
    rows = np.asarray(dataset[row_name].values, dtype=np.float64)
    cols = np.asarray(dataset[col_name].values, dtype=np.float64)
    kept = {dataset[row_name].dims[0], dataset[col_name].dims[0], *([time_dim] if time_dim else [])}
    extra = [dim for dim in data.dims if dim not in kept and data.sizes[dim] > 1]
    if extra:
        raise DataFormatError(f"{north_name} has unexpected dimensions {extra}")
    order = [d for d in (time_dim, dataset[row_name].dims[0], dataset[col_name].dims[0]) if d]
    slices = [
        factor * np.asarray(c.squeeze(drop=True).transpose(*order).values, dtype=np.float64)
        for c, factor in components
    ]
    if time_dim is None:
        slices = [s[None] for s in slices]
    if not np.any(np.isfinite(slices[0])) or not np.any(np.isfinite(slices[1])):
        raise DataFormatError(f"{north_name}/{east_name} hold no valid values")
    time_step, offset = _time_axis(dataset, time_dim, start_time)
    geometry, slices = _lattice(rows, cols, slices)
    to_axes = _affine(dataset, data, projection, extent, is_latlon, rows, cols, row_name)
    _check_coverage(to_axes, geometry, extent)
    if water is not None:
        for name, values in ((north_name, slices[0]), (east_name, slices[1])):
            _check_water_values(name, values, geometry, to_axes, water)
    return GriddedCurrent(
        north_component=tuple(SplineSurface.fit(geometry, s) for s in slices[0]),
        east_component=tuple(SplineSurface.fit(geometry, s) for s in slices[1]),
        time_step=time_step,
        start_offset=offset,
        to_axes=to_axes,
    )


def _regular_step(axis: FloatArray, label: str) -> float:
    steps = np.diff(axis)
    step = float(steps.mean()) if steps.size else 1.0
    if steps.size and (step <= 0.0 or np.max(np.abs(steps - step)) > 1e-3 * abs(step)):
        raise DataFormatError(f"{label} axis is not evenly spaced and increasing")
    return step


def _time_axis(
    dataset: xr.Dataset, time_dim: str | None, start_time: datetime | None
) -> tuple[float, float]:
    """Slice interval [s] and the mission time [s] of the first slice."""
    if time_dim is None:
        return 1.0, 0.0
    values = np.asarray(dataset[time_dim].values)
    if not np.issubdtype(values.dtype, np.datetime64):
        raise DataFormatError(f"time axis {time_dim} has no CF time units")
    seconds = (values - values[0]) / np.timedelta64(1, "s")
    step = (
        _regular_step(np.asarray(seconds, dtype=np.float64), time_dim) if values.size > 1 else 1.0
    )
    if start_time is None:
        return step, 0.0
    start = np.datetime64(start_time.replace(tzinfo=None), "s")
    offset = float((values[0] - start) / np.timedelta64(1, "s"))
    if not offset <= 0.0 <= offset + float(seconds[-1]):
        raise InputError(
            f"mission.start_time {start_time.isoformat()} is outside the file's times "
            f"{values[0]} … {values[-1]}"
        )
    return step, offset


def _lattice(
    rows: FloatArray, cols: FloatArray, slices: list[FloatArray]
) -> tuple[GridGeometry, list[FloatArray]]:
    """Increasing axes and their geometry (spacings in the axes' own units)."""
    if rows[0] > rows[-1]:
        rows, slices = rows[::-1], [s[:, ::-1] for s in slices]
    if cols[0] > cols[-1]:
        cols, slices = cols[::-1], [s[:, :, ::-1] for s in slices]
    step_rows, step_cols = _regular_step(rows, "row"), _regular_step(cols, "column")
    geometry = GridGeometry(rows.size, cols.size, step_rows, step_cols, rows[0], cols[0])
    return geometry, slices


def _affine(
    dataset: xr.Dataset,
    data: xr.DataArray,
    projection: LocalProjection | None,
    extent: tuple[tuple[float, float], tuple[float, float]],
    is_latlon: bool,
    rows: FloatArray,
    cols: FloatArray,
    row_name: str,
) -> FloatArray:
    """``(2, 3)`` map from local ``(north, east, 1)`` to the file's ``(row, col)`` axes."""
    crs = grid_mapping_crs(dataset, data)
    units = str(dataset[row_name].attrs.get("units", "")).lower()
    if crs is None and _is_geographic(units, is_latlon, rows, cols):
        crs = CRS(GEOGRAPHIC_CRS)
    if crs is None:
        return np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    if projection is None:
        raise InputError("it is georeferenced but the terrain has no lat/lon reference")
    to_file = Transformer.from_crs(projection.crs, crs, always_xy=True)
    (n0, n1), (e0, e1) = extent
    north = 0.5 * (n0 + n1) + np.array([0.0, 0.0, _JACOBIAN_STEP_M])
    east = 0.5 * (e0 + e1) + np.array([0.0, _JACOBIAN_STEP_M, 0.0])
    x, y = (np.asarray(a, dtype=np.float64) for a in to_file.transform(east, north))
    if crs.is_geographic:  # longitudes in the file's convention (-180..180 or 0..360)
        x += 360.0 * np.round((cols.mean() - x) / 360.0)
    jacobian = np.array([[y[2] - y[0], y[1] - y[0]], [x[2] - x[0], x[1] - x[0]]]) / _JACOBIAN_STEP_M
    origin = np.array([y[0], x[0]]) - jacobian @ np.array([north[0], east[0]])
    return np.column_stack([jacobian, origin])


def _check_water_values(
    name: str,
    values: FloatArray,
    geometry: GridGeometry,
    to_axes: FloatArray,
    water: tuple[FloatArray, FloatArray],
) -> None:
    """Raise DataFormatError if the node nearest a water point is NaN at some time.

    ``values`` has shape ``(n_times, n_rows, n_cols)`` on ``geometry`` (the file's axes);
    ``to_axes`` maps local ``(north, east, 1)`` [m] to them; ``water`` is ``(north, east)`` [m].
    """
    north, east = (np.ravel(axis) for axis in water)
    rows, cols = geometry.to_index(*(to_axes @ np.vstack([north, east, np.ones_like(north)])))
    rows, cols = np.clip(rows, 0, geometry.n_rows - 1), np.clip(cols, 0, geometry.n_cols - 1)
    is_nan = np.isnan(values[:, rows, cols])  # (n_times, n_water)
    if not is_nan.any():
        return
    time, first = (int(i[0]) for i in np.nonzero(is_nan))
    n_cells = int(np.count_nonzero(is_nan.any(axis=0)))
    when = f" in time slice {time} of {values.shape[0]}" if values.shape[0] > 1 else ""
    raise DataFormatError(
        f"{name} is NaN over the map's water: at {n_cells} of its {north.size} water cells, "
        f"first north {north[first]:.0f} m, east {east[first]:.0f} m{when} (NaN is read as "
        "still water only over land; fill the gaps over water)"
    )


def _check_coverage(
    to_axes: FloatArray,
    geometry: GridGeometry,
    extent: tuple[tuple[float, float], tuple[float, float]],
) -> None:
    (n0, n1), (e0, e1) = extent
    corners = np.array([[n0, n0, n1, n1], [e0, e1, e0, e1], [1.0] * 4])
    rows, cols = to_axes @ corners
    tolerance = 0.5
    inside = (
        np.all(rows >= geometry.origin_north - tolerance * geometry.spacing_north)
        and np.all(
            rows
            <= geometry.origin_north + (geometry.n_rows - 1 + tolerance) * geometry.spacing_north
        )
        and np.all(cols >= geometry.origin_east - tolerance * geometry.spacing_east)
        and np.all(
            cols <= geometry.origin_east + (geometry.n_cols - 1 + tolerance) * geometry.spacing_east
        )
    )
    if not inside:
        raise InputError(
            f"it does not cover the map (north {n0:.0f} … {n1:.0f} m, east {e0:.0f} … {e1:.0f} m "
            "of the local frame)"
        )
