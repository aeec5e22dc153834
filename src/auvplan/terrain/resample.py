"""From grids in any CRS and from scattered soundings to regular north/east grids.

Array-in, grid-out functions used by the bathymetry readers (:mod:`auvplan.io.bathymetry`):

* :func:`project_grid`: a regular grid in a geographic or projected CRS (lon/lat, UTM, ...)
  to a regular metric grid in the local frame, a transverse Mercator centred on the map
  (:class:`LocalProjection`), by GDAL's bilinear warp (rioxarray);
  :func:`project_geographic_grid` is the same for WGS 84 lon/lat;
* :func:`grid_scattered_points`: scattered ``(north, east, depth)`` soundings to a regular grid
  (Delaunay-linear interpolation, NaN far from any sounding).
"""

from __future__ import annotations

from typing import Final

import numpy as np
from pyproj import CRS, Transformer

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.terrain.grid import BathymetryGrid, GridGeometry
from auvplan.terrain.projection import GEOGRAPHIC_CRS, LocalProjection

#: Grid nodes may lie this far (in cells) outside the source data and still be interpolated
#: (clamped to the border): absorbs the sub-millimetre curvature of lon/lat lines in the
#: projection so that a grid does not lose a row to round-off.
_EDGE_TOLERANCE_CELLS = 0.01

#: A node of a gridded point cloud is NaN when no sounding lies within this many spacings.
_MAX_GAP_SPACINGS = 2.0

#: Largest grid (nodes) either function builds: 25 M nodes are 200 MB per float64 map, and the
#: terrain maps, A* and the figures hold several such arrays. Checked before any allocation.
MAX_GRID_NODES: Final = 25_000_000


def check_grid_size(n_rows: int, n_cols: int, spacing_north: float, spacing_east: float) -> None:
    """Raise InputError if a grid of ``n_rows x n_cols`` nodes exceeds :data:`MAX_GRID_NODES`.

    Parameters
    ----------
    n_rows, n_cols : int
        Planned grid shape.
    spacing_north, spacing_east : float
        Planned node spacing [m], named in the message with the extent it implies.

    Raises
    ------
    InputError
        Naming the shape, spacing and extent, and what to change.

    Examples
    --------
    >>> check_grid_size(100_000, 100_000, 1.0, 1.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    auvplan.errors.InputError: the grid would need 100000 x 100000 nodes at 1 m x 1 m spacing ...
    """
    n_nodes = n_rows * n_cols
    if n_nodes > MAX_GRID_NODES:
        raise InputError(
            f"the grid would need {n_rows} x {n_cols} nodes at {spacing_north:.3g} m x "
            f"{spacing_east:.3g} m spacing ({n_nodes:.3g} nodes over "
            f"{n_rows * spacing_north / 1e3:.4g} km x {n_cols * spacing_east / 1e3:.4g} km; "
            f"at most {MAX_GRID_NODES:.3g}): remove stray positions far from the data, "
            "or split or crop the file"
        )


def project_geographic_grid(
    depth: FloatArray,
    lat: FloatArray,
    lon: FloatArray,
    *,
    name: str = "",
    attributes: dict[str, str] | None = None,
) -> BathymetryGrid:
    """Resample a regular lon/lat grid (WGS 84) onto the local north/east frame.

    :func:`project_grid` with ``crs = "EPSG:4326"``: ``lat`` and ``lon`` [deg] are the
    strictly increasing node coordinates, ``depth`` of shape ``(n_lat, n_lon)``.

    Examples
    --------
    >>> lat, lon = 38.6 + 0.001 * np.arange(4), -9.3 + 0.00125 * np.arange(5)
    >>> grid = project_geographic_grid(np.full((4, 5), 30.0), lat, lon)
    >>> spacing = (grid.geometry.spacing_north, grid.geometry.spacing_east)
    >>> grid.geometry.shape, [round(s, 1) for s in spacing]
    ((4, 5), [111.0, 108.9])
    """
    return project_grid(depth, lat, lon, GEOGRAPHIC_CRS, name=name, attributes=attributes)


def project_grid(
    depth: FloatArray,
    axis_north: FloatArray,
    axis_east: FloatArray,
    crs: CRS | str,
    *,
    name: str = "",
    attributes: dict[str, str] | None = None,
) -> BathymetryGrid:
    """Resample a regular grid in any CRS onto a regular grid in the local north/east frame.

    Parameters
    ----------
    depth : ndarray of shape (n_rows, n_cols)
        Depth [m], positive down, NaN = no-go. Row ``i`` is at ``axis_north[i]``, column
        ``j`` at ``axis_east[j]``.
    axis_north, axis_east : ndarray of shape (n_rows,), (n_cols,)
        Strictly increasing, evenly spaced node coordinates along the CRS's northing (or
        latitude) and easting (or longitude) axes, at least 2 each.
    crs : pyproj.CRS or str
        The grid's CRS, geographic (degrees) or projected (e.g. UTM).
    name : str
        Source name carried by the result.
    attributes : dict of str to str, optional
        Metadata carried by the result.

    Returns
    -------
    BathymetryGrid
        Depth on a metric grid whose spacing is the source node spacing measured in the local
        frame at the map centre [m] (north and east may differ), covering the largest
        north/east-aligned rectangle inside the projected source grid. Its origin ``(0, 0)``
        is the south-west node, and its ``projection`` is a transverse Mercator (WGS 84)
        centred on the map centre, shifted to that origin, so lat/lon poses convert exactly.

    Raises
    ------
    InputError
        If the coordinates are not strictly increasing, the grid is smaller than 2 x 2, or
        the result would exceed :data:`MAX_GRID_NODES`.

    Notes
    -----
    The resampling is GDAL's bilinear warp (:func:`rasterio.warp.reproject`, resampling
    factor fixed at 1 so that the kernel is the plain 2 x 2 one), with
    its approximate transformer (position error at most 1/8 of a source cell, about 1/200 of
    a cell on maps of a few kilometres). A node is NaN when any source node with a non-zero
    interpolation weight is NaN (the NaN indicator is warped alongside): no-go cells never
    shrink. A source in another datum than WGS 84 is converted by the transformation PROJ
    selects.
    """
    crs = CRS(crs)
    axis_north = np.asarray(axis_north, dtype=np.float64)
    axis_east = np.asarray(axis_east, dtype=np.float64)
    depth = np.asarray(depth, dtype=np.float64)
    if depth.shape != (axis_north.size, axis_east.size) or min(depth.shape) < 2:
        raise InputError(
            f"gridded data need values of shape (n_rows, n_cols) >= (2, 2) matching their "
            f"coordinates, got {depth.shape} with {axis_north.size} x {axis_east.size} nodes"
        )
    if not (np.all(np.diff(axis_north) > 0.0) and np.all(np.diff(axis_east) > 0.0)):
        raise InputError("grid coordinates must be strictly increasing")

    centre = _centre_projection(axis_north, axis_east, crs)
    to_centre = Transformer.from_crs(crs, centre.crs, always_xy=True)
    spacing_north, spacing_east = _native_spacing(to_centre, axis_north, axis_east)

    # Largest axis-aligned rectangle inside the projected border of the source grid.
    _, south_north = to_centre.transform(axis_east, np.full(axis_east.size, axis_north[0]))
    _, north_north = to_centre.transform(axis_east, np.full(axis_east.size, axis_north[-1]))
    west_east, _ = to_centre.transform(np.full(axis_north.size, axis_east[0]), axis_north)
    east_east, _ = to_centre.transform(np.full(axis_north.size, axis_east[-1]), axis_north)
    north_min, north_max = float(np.max(south_north)), float(np.min(north_north))
    east_min, east_max = float(np.max(west_east)), float(np.min(east_east))
    n_rows = int(np.floor((north_max - north_min) / spacing_north + _EDGE_TOLERANCE_CELLS)) + 1
    n_cols = int(np.floor((east_max - east_min) / spacing_east + _EDGE_TOLERANCE_CELLS)) + 1
    if n_rows < 2 or n_cols < 2:
        raise InputError(f"projected grid is smaller than 2 x 2 nodes ({n_rows} x {n_cols})")
    check_grid_size(n_rows, n_cols, spacing_north, spacing_east)

    geometry = GridGeometry(n_rows, n_cols, spacing_north, spacing_east)
    projection = centre.shifted(north_min, east_min)
    resampled = _warp_bilinear(depth, axis_north, axis_east, crs, geometry, projection.crs)
    return BathymetryGrid(resampled, geometry, projection, None, name, dict(attributes or {}))


def _centre_projection(axis_north: FloatArray, axis_east: FloatArray, crs: CRS) -> LocalProjection:
    """The local frame centred on the middle of the grid's extent (WGS 84)."""
    to_geographic = Transformer.from_crs(crs, GEOGRAPHIC_CRS, always_xy=True)
    lon_c, lat_c = to_geographic.transform(
        0.5 * (axis_east[0] + axis_east[-1]), 0.5 * (axis_north[0] + axis_north[-1])
    )
    return LocalProjection(float(lat_c), float(lon_c))


def _native_spacing(
    to_centre: Transformer, axis_north: FloatArray, axis_east: FloatArray
) -> tuple[float, float]:
    """Node spacing [m] (north, east) of the source grid, measured at the map centre."""
    step_north = float(axis_north[-1] - axis_north[0]) / (axis_north.size - 1)
    step_east = float(axis_east[-1] - axis_east[0]) / (axis_east.size - 1)
    y_c, x_c = 0.5 * (axis_north[0] + axis_north[-1]), 0.5 * (axis_east[0] + axis_east[-1])
    east, north = to_centre.transform(
        np.array([x_c, x_c, x_c - 0.5 * step_east, x_c + 0.5 * step_east]),
        np.array([y_c - 0.5 * step_north, y_c + 0.5 * step_north, y_c, y_c]),
    )
    return (
        float(np.hypot(east[1] - east[0], north[1] - north[0])),
        float(np.hypot(east[3] - east[2], north[3] - north[2])),
    )


def _warp_bilinear(
    depth: FloatArray,
    axis_north: FloatArray,
    axis_east: FloatArray,
    crs: CRS,
    geometry: GridGeometry,
    local_crs: CRS,
) -> FloatArray:
    """Bilinear warp (GDAL) of ``depth`` onto ``geometry`` in ``local_crs``; NaN spreads."""
    from affine import Affine
    from rasterio.enums import Resampling
    from rasterio.warp import reproject

    missing = ~np.isfinite(depth)
    bands = np.stack([np.where(missing, 0.0, depth), missing.astype(np.float64)])
    step_north = float(axis_north[-1] - axis_north[0]) / (axis_north.size - 1)
    step_east = float(axis_east[-1] - axis_east[0]) / (axis_east.size - 1)
    south_up = Affine(
        step_east,
        0.0,
        axis_east[0] - 0.5 * step_east,
        0.0,
        step_north,
        axis_north[0] - 0.5 * step_north,
    )
    north_up = Affine(
        geometry.spacing_east,
        0.0,
        geometry.east_bounds[0],
        0.0,
        -geometry.spacing_north,
        geometry.north_bounds[1],
    )
    warped = np.full((2, *geometry.shape), np.nan)
    reproject(
        bands,
        warped,
        src_transform=south_up,
        src_crs=crs,
        dst_transform=north_up,
        dst_crs=local_crs,
        dst_nodata=np.nan,
        resampling=Resampling.bilinear,
        XSCALE=1,
        YSCALE=1,
    )
    values, touched = warped[:, ::-1, :]
    values[~(touched <= 1e-9)] = np.nan  # also where the warp left no data (NaN)
    return np.ascontiguousarray(values)


def grid_scattered_points(
    north: FloatArray,
    east: FloatArray,
    depth: FloatArray,
    *,
    spacing: float | None = None,
    projection: LocalProjection | None = None,
    name: str = "",
    attributes: dict[str, str] | None = None,
) -> BathymetryGrid:
    """Grid scattered soundings onto a regular north/east grid.

    Parameters
    ----------
    north, east : ndarray of shape (n_points,)
        Sounding positions [m] in a local frame.
    depth : ndarray of shape (n_points,)
        Depth [m], positive down (NaN soundings are dropped).
    spacing : float, optional
        Node spacing [m] (both axes). Default: the median distance from each sounding to its
        nearest neighbour.
    projection : LocalProjection, optional
        Projection of the frame of ``north``/``east``; it is shifted to the new origin.
    name : str
        Source name carried by the result.
    attributes : dict of str to str, optional
        Metadata carried by the result.

    Returns
    -------
    BathymetryGrid
        Grid with origin ``(0, 0)`` at the south-west node ``(min north, min east)``. Values
        are linear interpolation on the Delaunay triangulation of the soundings
        (:func:`scipy.interpolate.griddata`); nodes farther than two spacings from every
        sounding, or outside their convex hull, are NaN. (With the default spacing, a random
        cloud has about 6 % of such gaps: P(no sounding within 2 s) = 2^-4 for a Poisson cloud.)

    Raises
    ------
    InputError
        If fewer than 3 distinct finite soundings remain, they span no area (all on one line),
        the spacing is not positive, or the grid would exceed :data:`MAX_GRID_NODES`.
    """
    from scipy.interpolate import griddata  # imported here: slow to import, rarely needed
    from scipy.spatial import QhullError, cKDTree

    north = np.asarray(north, dtype=np.float64)
    east = np.asarray(east, dtype=np.float64)
    depth = np.asarray(depth, dtype=np.float64)
    keep = np.isfinite(north) & np.isfinite(east) & np.isfinite(depth)
    north, east, depth = north[keep], east[keep], depth[keep]
    points = np.column_stack([north, east])
    if np.unique(points, axis=0).shape[0] < 3:
        raise InputError(f"need at least 3 distinct finite soundings, got {points.shape[0]}")
    tree = cKDTree(points)
    if spacing is None:
        distances, _ = tree.query(points, k=2)
        nearest = distances[:, 1]
        spacing = float(np.median(nearest[nearest > 0.0]))
    if not spacing > 0.0:
        raise InputError(f"grid spacing must be positive, got {spacing}")
    north_min, east_min = float(north.min()), float(east.min())
    n_rows = int(np.floor((north.max() - north_min) / spacing + _EDGE_TOLERANCE_CELLS)) + 1
    n_cols = int(np.floor((east.max() - east_min) / spacing + _EDGE_TOLERANCE_CELLS)) + 1
    if n_rows < 2 or n_cols < 2:
        raise InputError(
            f"soundings span fewer than 2 x 2 nodes at {spacing:g} m spacing ({n_rows} x {n_cols})"
        )
    check_grid_size(n_rows, n_cols, spacing, spacing)
    geometry = GridGeometry(n_rows, n_cols, spacing, spacing)
    node_north, node_east = np.meshgrid(
        north_min + geometry.north, east_min + geometry.east, indexing="ij"
    )
    try:
        values = griddata(points, depth, (node_north, node_east), method="linear")
    except QhullError:
        raise InputError(
            f"the {points.shape[0]} soundings lie on one line (no area to interpolate over)"
        ) from None
    gap, _ = tree.query(np.column_stack([node_north.ravel(), node_east.ravel()]))
    values[(gap > _MAX_GAP_SPACINGS * spacing).reshape(values.shape)] = np.nan
    shifted = None if projection is None else projection.shifted(north_min, east_min)
    return BathymetryGrid(
        np.asarray(values, dtype=np.float64), geometry, shifted, None, name, dict(attributes or {})
    )
