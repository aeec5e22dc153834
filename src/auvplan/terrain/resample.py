"""From geographic grids and scattered soundings to regular north/east grids.

Two array-in, grid-out functions used by the bathymetry readers (:mod:`auvplan.io.bathymetry`):

* :func:`project_geographic_grid`: a regular lon/lat grid to a regular metric grid in a
  transverse Mercator frame centred on the map (:class:`LocalProjection`), by bilinear
  interpolation in lon/lat;
* :func:`grid_scattered_points`: scattered ``(north, east, depth)`` soundings to a regular grid
  (Delaunay-linear interpolation, NaN far from any sounding).
"""

from __future__ import annotations

from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.terrain.grid import BathymetryGrid, GridGeometry
from auvplan.terrain.projection import LocalProjection

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
    """Resample a regular lon/lat grid onto a regular grid in the local north/east frame.

    Parameters
    ----------
    depth : ndarray of shape (n_lat, n_lon)
        Depth [m], positive down, NaN = no-go. Row ``i`` is at ``lat[i]``, column ``j`` at
        ``lon[j]``.
    lat, lon : ndarray of shape (n_lat,), (n_lon,)
        Strictly increasing node latitudes and longitudes [deg], at least 2 each.
    name : str
        Source name carried by the result.
    attributes : dict of str to str, optional
        Metadata carried by the result.

    Returns
    -------
    BathymetryGrid
        Depth on a metric grid whose spacing is the native spacing at the map centre [m]
        (north and east may differ), covering the largest north/east-aligned rectangle inside
        the projected source grid. Its origin ``(0, 0)`` is the south-west node, and its
        ``projection`` is a transverse Mercator centred on the map centre, shifted to that
        origin, so lat/lon poses convert exactly.

    Raises
    ------
    InputError
        If the coordinates are not strictly increasing or the grid is smaller than 2 x 2.

    Notes
    -----
    Each metric node is converted to lat/lon and interpolated bilinearly between the four
    surrounding source nodes (fractional indices from the source coordinates, so slightly
    irregular coordinate vectors are honoured). A node is NaN when any source node with a
    non-zero interpolation weight is NaN: no-go cells never shrink.
    """
    lat = np.asarray(lat, dtype=np.float64)
    lon = np.asarray(lon, dtype=np.float64)
    depth = np.asarray(depth, dtype=np.float64)
    if depth.shape != (lat.size, lon.size) or lat.size < 2 or lon.size < 2:
        raise InputError(
            f"geographic grid needs depth of shape (n_lat, n_lon) >= (2, 2) matching its "
            f"coordinates, got {depth.shape} with {lat.size} lat and {lon.size} lon"
        )
    if not (np.all(np.diff(lat) > 0.0) and np.all(np.diff(lon) > 0.0)):
        raise InputError("geographic grid coordinates must be strictly increasing")

    lat_c, lon_c = 0.5 * (lat[0] + lat[-1]), 0.5 * (lon[0] + lon[-1])
    centre = LocalProjection(float(lat_c), float(lon_c))
    spacing_north, spacing_east = _native_spacing(centre, lat, lon)

    # Largest axis-aligned rectangle inside the projected border of the source grid.
    south_north, _ = centre.to_local(np.full(lon.size, lat[0]), lon)
    north_north, _ = centre.to_local(np.full(lon.size, lat[-1]), lon)
    _, west_east = centre.to_local(lat, np.full(lat.size, lon[0]))
    _, east_east = centre.to_local(lat, np.full(lat.size, lon[-1]))
    north_min, north_max = float(south_north.max()), float(north_north.min())
    east_min, east_max = float(west_east.max()), float(east_east.min())
    n_rows = int(np.floor((north_max - north_min) / spacing_north + _EDGE_TOLERANCE_CELLS)) + 1
    n_cols = int(np.floor((east_max - east_min) / spacing_east + _EDGE_TOLERANCE_CELLS)) + 1
    if n_rows < 2 or n_cols < 2:
        raise InputError(f"projected grid is smaller than 2 x 2 nodes ({n_rows} x {n_cols})")
    check_grid_size(n_rows, n_cols, spacing_north, spacing_east)

    geometry = GridGeometry(n_rows, n_cols, spacing_north, spacing_east)
    projection = centre.shifted(north_min, east_min)
    node_north, node_east = np.meshgrid(geometry.north, geometry.east, indexing="ij")
    node_lat, node_lon = projection.to_geographic(node_north, node_east)
    row = np.interp(node_lat, lat, np.arange(lat.size, dtype=np.float64))
    col = np.interp(node_lon, lon, np.arange(lon.size, dtype=np.float64))
    resampled = _bilinear_nan(depth, row, col)
    return BathymetryGrid(resampled, geometry, projection, None, name, dict(attributes or {}))


def _native_spacing(
    centre: LocalProjection, lat: FloatArray, lon: FloatArray
) -> tuple[float, float]:
    """Node spacing [m] (north, east) of a lon/lat grid at the map centre."""
    d_lat = float(lat[-1] - lat[0]) / (lat.size - 1)
    d_lon = float(lon[-1] - lon[0]) / (lon.size - 1)
    lat_c, lon_c = centre.lat_0, centre.lon_0
    north, _ = centre.to_local(
        np.array([lat_c - 0.5 * d_lat, lat_c + 0.5 * d_lat]), np.full(2, lon_c)
    )
    _, east = centre.to_local(
        np.full(2, lat_c), np.array([lon_c - 0.5 * d_lon, lon_c + 0.5 * d_lon])
    )
    return float(north[1] - north[0]), float(east[1] - east[0])


def _bilinear_nan(values: FloatArray, row: FloatArray, col: FloatArray) -> FloatArray:
    """Bilinear interpolation at fractional ``(row, col)``; NaN if a weighted node is NaN."""
    from scipy.ndimage import map_coordinates  # imported here: slow to import, rarely needed

    missing = ~np.isfinite(values)
    filled = np.where(missing, 0.0, values)
    coordinates = np.stack([row.ravel(), col.ravel()])
    interpolated = map_coordinates(filled, coordinates, order=1, mode="nearest", prefilter=False)
    touched = map_coordinates(
        missing.astype(np.float64), coordinates, order=1, mode="nearest", prefilter=False
    )
    interpolated[touched > 1e-9] = np.nan
    return np.asarray(interpolated.reshape(row.shape), dtype=np.float64)


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
