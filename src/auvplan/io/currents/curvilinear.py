"""Currents on curvilinear (2-D ``lat``/``lon``) or unevenly spaced grids, resampled.

ROMS/CROCO ``lat_rho``/``lon_rho``, RTOFS ``Latitude``/``Longitude`` and lat/lon axes that are
not evenly spaced (Mercator rows) are not a lattice the spline can take. Their nodes are
projected to the local frame and the field is interpolated linearly on their Delaunay
triangulation (:class:`scipy.interpolate.LinearNDInterpolator`, exact for a field linear in
north/east) onto a regular local grid over the map and :data:`MARGIN_CELLS` cells around it.
The grid's spacing is the file's (the median distance between neighbouring nodes), at most
1/16 of the map's larger side and at least 1/400 of it. Where a triangle touches a NaN node
(land) or lies outside the file's nodes, a grid node takes the value of its nearest file node
(NaN over land stays still water, as on a lattice); the map's nodes farther than one file
spacing from every file node are not covered. Longitudes are taken within ±180° of the map's
(0..360 and RTOFS's 74..434 conventions).
"""

from __future__ import annotations

from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.terrain.grid import GridGeometry
from auvplan.terrain.projection import LocalProjection

__all__ = ["MARGIN_CELLS", "crop", "not_covered", "resample", "wrap_longitude"]

#: Grid cells kept around the map (the cubic spline's support is two cells).
MARGIN_CELLS: Final = 3
_MIN_CELLS, _MAX_CELLS = 16, 400


def not_covered(extent: tuple[tuple[float, float], tuple[float, float]]) -> InputError:
    """The error of a file that does not cover the map ``extent`` [m]."""
    (n0, n1), (e0, e1) = extent
    return InputError(
        f"it does not cover the map (north {n0:.0f} … {n1:.0f} m, east {e0:.0f} … {e1:.0f} m "
        "of the local frame)"
    )


def wrap_longitude(lon: FloatArray, centre: float) -> FloatArray:
    """Longitudes [deg] within ±180° of ``centre`` [deg]."""
    return centre + (np.asarray(lon, dtype=np.float64) - centre + 180.0) % 360.0 - 180.0


def crop(
    lat: FloatArray,
    lon: FloatArray,
    projection: LocalProjection,
    extent: tuple[tuple[float, float], tuple[float, float]],
) -> tuple[slice, slice]:
    """Index window of 2-D ``lat, lon`` [deg] nodes around the map, with margin.

    The nodes inside the map's lat/lon box widened by :data:`MARGIN_CELLS` times the largest
    node step, and the rows and columns between them.
    """
    (n0, n1), (e0, e1) = extent
    corner_lat, corner_lon = projection.to_geographic(
        np.array([n0, n0, n1, n1]), np.array([e0, e1, e0, e1])
    )
    lon = wrap_longitude(lon, float(np.mean(corner_lon)))
    steps = [np.abs(np.diff(a, axis=k)) for a in (lat, lon) for k in (0, 1) if a.shape[k] > 1]
    margin = MARGIN_CELLS * max((float(np.nanmedian(s)) for s in steps if s.size), default=0.0)
    widen = margin / max(float(np.cos(np.radians(corner_lat.mean()))), 0.1)  # deg of longitude
    inside = (
        (lat >= corner_lat.min() - margin)
        & (lat <= corner_lat.max() + margin)
        & (lon >= corner_lon.min() - widen)
        & (lon <= corner_lon.max() + widen)
    )
    rows, cols = np.nonzero(inside)
    if rows.size == 0:
        raise not_covered(extent)
    return (
        slice(max(int(rows.min()) - 1, 0), int(rows.max()) + 2),
        slice(max(int(cols.min()) - 1, 0), int(cols.max()) + 2),
    )


def resample(
    lat: FloatArray,
    lon: FloatArray,
    fields: list[FloatArray],
    projection: LocalProjection,
    extent: tuple[tuple[float, float], tuple[float, float]],
) -> tuple[GridGeometry, list[FloatArray]]:
    """``fields`` ``(n_t, n_rows, n_cols)`` on 2-D nodes ``lat, lon`` [deg] on a regular local grid.

    Returns
    -------
    geometry : GridGeometry
        The regular grid on local north/east [m].
    fields : list of ndarray
        Each field as ``(n_t, geometry.n_rows, geometry.n_cols)``.

    Raises
    ------
    InputError
        If the file's nodes do not cover the map (module notes).
    """
    from scipy.interpolate import LinearNDInterpolator
    from scipy.spatial import Delaunay, QhullError, cKDTree
    from threadpoolctl import threadpool_limits

    (n0, n1), (e0, e1) = extent
    centre = projection.to_geographic(np.array([0.5 * (n0 + n1)]), np.array([0.5 * (e0 + e1)]))
    north, east = projection.to_local(lat, wrap_longitude(lon, float(centre[1][0])))
    nodes = np.column_stack([north.ravel(), east.ravel()])
    try:
        triangulation = Delaunay(nodes)
    except (QhullError, ValueError):
        raise DataFormatError("its lat/lon nodes do not span an area") from None
    spacing = _node_spacing(north, east)
    side = max(n1 - n0, e1 - e0, 1.0)
    step = float(np.clip(spacing, side / _MAX_CELLS, side / _MIN_CELLS))
    counts = [int(np.ceil((b - a) / step)) + 1 + 2 * MARGIN_CELLS for a, b in extent]
    origin = (n0 - MARGIN_CELLS * step, e0 - MARGIN_CELLS * step)
    geometry = GridGeometry(counts[0], counts[1], step, step, *origin)
    grid_n, grid_e = (a.ravel() for a in np.meshgrid(geometry.north, geometry.east, indexing="ij"))
    targets = np.column_stack([grid_n, grid_e])
    stacked = np.concatenate([f.reshape(f.shape[0], -1) for f in fields]).T  # (n_nodes, k n_t)
    with threadpool_limits(limits=1, user_api="blas"):  # a tiny LAPACK solve per triangle
        values = LinearNDInterpolator(triangulation, stacked)(targets)
    distance, nearest = cKDTree(nodes).query(targets)
    values = np.where(np.isnan(values), stacked[nearest], values)
    on_map = (grid_n >= n0) & (grid_n <= n1) & (grid_e >= e0) & (grid_e <= e1)
    outside = triangulation.find_simplex(targets) < 0
    if np.any(on_map & outside & (distance > spacing)):
        raise not_covered(extent)
    n_t = fields[0].shape[0]
    shape = (n_t, geometry.n_rows, geometry.n_cols)
    columns = [values[:, k * n_t : (k + 1) * n_t] for k in range(len(fields))]
    return geometry, [c.T.reshape(shape) for c in columns]


def _node_spacing(north: FloatArray, east: FloatArray) -> float:
    """Median distance [m] between neighbouring nodes along either index of a 2-D grid."""
    steps = [
        np.hypot(np.diff(north, axis=k), np.diff(east, axis=k)).ravel()
        for k in (0, 1)
        if north.shape[k] > 1
    ]
    joined = np.concatenate(steps) if steps else np.zeros(0)
    return float(np.median(joined)) if joined.size else 1.0
