"""Currents on a regular lattice of the file's own axes, and the checks every grid shares.

A file on evenly spaced 1-D axes (latitude/longitude, a projected CRS's northing/easting, or
the local ``north``/``east``) keeps its lattice: its axes map to the local frame by the affine
approximation of the PROJ transformation at the map centre (its error over a few kilometres is
far below a current grid's cell); east and north are taken as the local frame's axes (the
meridian convergence is below 0.1 deg on such maps). Only the nodes over the map and
:data:`~auvplan.io.currents.curvilinear.MARGIN_CELLS` around it are read.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Final

import numpy as np
from pyproj import CRS, Transformer

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.io._gridded import _is_geographic, grid_mapping_crs
from auvplan.io.currents.curvilinear import MARGIN_CELLS, not_covered
from auvplan.io.currents.times import regular_step
from auvplan.terrain.grid import GridGeometry
from auvplan.terrain.projection import GEOGRAPHIC_CRS, LocalProjection

if TYPE_CHECKING:
    import xarray as xr

__all__ = [
    "IDENTITY",
    "affine",
    "check_coverage",
    "check_water_values",
    "crop_axis",
    "file_crs",
    "lattice",
    "map_corners",
]

#: The affine map of a file on the local frame's own axes.
IDENTITY: Final = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
#: Step [m] of the finite differences of the PROJ transformation at the map centre.
_JACOBIAN_STEP_M: Final = 100.0


def file_crs(
    dataset: xr.Dataset,
    data: xr.DataArray,
    is_latlon: bool,
    rows: FloatArray,
    cols: FloatArray,
    row_name: str,
) -> CRS | None:
    """The CRS of the axes: the CF ``grid_mapping``, WGS 84 for lat/lon, None for local axes."""
    crs = grid_mapping_crs(dataset, data)
    units = str(dataset[row_name].attrs.get("units", "")).lower()
    if crs is None and _is_geographic(units, is_latlon, rows, cols):
        crs = CRS(GEOGRAPHIC_CRS)
    return crs


def affine(
    crs: CRS | None,
    projection: LocalProjection | None,
    extent: tuple[tuple[float, float], tuple[float, float]],
    cols: FloatArray,
) -> FloatArray:
    """``(2, 3)`` map from local ``(north, east, 1)`` to the file's ``(row, col)`` axes.

    Longitudes come in the convention of the file's column axis ``cols`` (-180..180, 0..360).

    Raises
    ------
    InputError
        If the file is georeferenced and ``projection`` is None.
    """
    if crs is None:
        return IDENTITY
    if projection is None:
        raise InputError("it is georeferenced but the terrain has no lat/lon reference")
    to_file = Transformer.from_crs(projection.crs, crs, always_xy=True)
    (n0, n1), (e0, e1) = extent
    north = 0.5 * (n0 + n1) + np.array([0.0, 0.0, _JACOBIAN_STEP_M])
    east = 0.5 * (e0 + e1) + np.array([0.0, _JACOBIAN_STEP_M, 0.0])
    x, y = (np.asarray(a, dtype=np.float64) for a in to_file.transform(east, north))
    if crs.is_geographic:
        x += 360.0 * np.round((cols.mean() - x) / 360.0)
    jacobian = np.array([[y[2] - y[0], y[1] - y[0]], [x[2] - x[0], x[1] - x[0]]]) / _JACOBIAN_STEP_M
    origin = np.array([y[0], x[0]]) - jacobian @ np.array([north[0], east[0]])
    return np.column_stack([jacobian, origin])


def map_corners(
    to_axes: FloatArray, extent: tuple[tuple[float, float], tuple[float, float]]
) -> FloatArray:
    """The map's four corners on the file's axes, ``(2, 4)`` rows then columns."""
    (n0, n1), (e0, e1) = extent
    corners: FloatArray = to_axes @ np.array([[n0, n0, n1, n1], [e0, e1, e0, e1], [1.0] * 4])
    return corners


def crop_axis(axis: FloatArray, low: float, high: float) -> slice:
    """Index window of the nodes of ``axis`` within ``[low, high]`` and ``MARGIN_CELLS`` beyond."""
    step = float(np.median(np.abs(np.diff(axis)))) if axis.size > 1 else 0.0
    inside = np.nonzero((axis >= low - MARGIN_CELLS * step) & (axis <= high + MARGIN_CELLS * step))[
        0
    ]
    if inside.size == 0:
        return slice(0, 0)
    return slice(int(inside.min()), int(inside.max()) + 1)


def lattice(
    rows: FloatArray, cols: FloatArray, slices: list[FloatArray]
) -> tuple[GridGeometry, list[FloatArray]]:
    """Increasing axes and their geometry (spacings in the axes' own units).

    Raises
    ------
    DataFormatError
        If an axis is not evenly spaced.
    """
    if rows.size > 1 and rows[0] > rows[-1]:
        rows, slices = rows[::-1], [s[:, ::-1] for s in slices]
    if cols.size > 1 and cols[0] > cols[-1]:
        cols, slices = cols[::-1], [s[:, :, ::-1] for s in slices]
    step_rows, step_cols = regular_step(rows, "row"), regular_step(cols, "column")
    geometry = GridGeometry(rows.size, cols.size, step_rows, step_cols, rows[0], cols[0])
    return geometry, slices


def check_coverage(
    to_axes: FloatArray,
    geometry: GridGeometry,
    extent: tuple[tuple[float, float], tuple[float, float]],
) -> None:
    """Raise InputError unless the map lies within the lattice and half a cell around it."""
    rows, cols = map_corners(to_axes, extent)
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
        raise not_covered(extent)


def check_water_values(
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
