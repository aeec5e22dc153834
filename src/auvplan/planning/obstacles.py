r"""Obstacles in world coordinates and their rasterisation onto a grid (no-go cells).

A cell is the rectangle :math:`[n_c - \Delta_n/2, n_c + \Delta_n/2] \times [e_c - \Delta_e/2,
e_c + \Delta_e/2]` around its centre. :func:`obstacle_mask` blocks every cell whose rectangle
comes within ``clearance`` of an obstacle:

* circle (centre :math:`p`, radius :math:`R`): :math:`d(p, \text{cell}) < R + \text{clearance}`;
* polygon :math:`P` (holes are not part of it): :math:`d(P, \text{cell}) < \text{clearance}`,
  or the cell intersects :math:`P` (distance 0);
* operating area :math:`A` (the no-go region is its outside): the cell is not inside
  :math:`A`, or :math:`d(\partial A, \text{cell}) < \text{clearance}`.

So a vehicle that stays in unblocked cells keeps at least ``clearance`` from every obstacle
at every point of those cells. All computations are vectorised over the cells of the
obstacle's (dilated) bounding box (every cell for an area); a polygon's edges are indexed in
an STR-tree (shapely), so that a GIS boundary of thousands of vertices costs about ``log n``
per cell or point.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any, TypeAlias

import numpy as np

from auvplan._typing import BoolArray, FloatArray
from auvplan.errors import InputError
from auvplan.terrain.grid import GridGeometry


@dataclass(frozen=True)
class CircleObstacle:
    """A disc in the horizontal plane.

    Parameters
    ----------
    north, east : float
        Centre [m].
    radius : float
        Radius [m], ``> 0``.

    Examples
    --------
    >>> CircleObstacle(10.0, 20.0, 5.0).radius
    5.0
    """

    north: float
    east: float
    radius: float

    def __post_init__(self) -> None:
        if not (np.isfinite(self.north) and np.isfinite(self.east)):
            raise InputError(f"circle centre must be finite, got ({self.north}, {self.east}) m")
        if not (np.isfinite(self.radius) and self.radius > 0.0):
            raise InputError(f"circle radius must be finite and > 0, got {self.radius!r} m")


@dataclass(frozen=True, eq=False)
class PolygonObstacle:
    """A polygon in the horizontal plane, possibly with holes (which are free water).

    Parameters
    ----------
    vertices : ndarray of shape (n_vertices, 2)
        ``[north, east]`` [m] of the exterior ring's vertices in order (closing edge implied),
        ``n >= 3``, finite, with non-zero area.
    holes : tuple of ndarray of shape (n_k, 2)
        Rings of the holes, each like ``vertices``, inside the exterior and apart from each
        other (a valid polygon: :func:`shapely.validation.explain_validity` is the judge
        upstream).

    Examples
    --------
    >>> square = PolygonObstacle(np.array([[0.0, 0.0], [0.0, 2.0], [2.0, 2.0], [2.0, 0.0]]))
    >>> square.vertices.shape
    (4, 2)
    """

    vertices: FloatArray
    holes: tuple[FloatArray, ...] = ()
    # shapely, in (east, north): the prepared polygon, its edges and their STR-tree
    _shape: Any = field(init=False, repr=False)
    _edges: Any = field(init=False, repr=False)
    _edge_tree: Any = field(init=False, repr=False)

    def __post_init__(self) -> None:
        import shapely

        object.__setattr__(self, "vertices", _ring(self.vertices, "polygon"))
        object.__setattr__(self, "holes", tuple(_ring(hole, "polygon hole") for hole in self.holes))
        shape = shapely.Polygon(self.vertices[:, ::-1], [hole[:, ::-1] for hole in self.holes])
        shapely.prepare(shape)
        ends = [np.stack((r, np.roll(r, -1, axis=0)), axis=1)[..., ::-1] for r in self.rings]
        edges = shapely.linestrings(np.concatenate(ends))
        object.__setattr__(self, "_shape", shape)
        object.__setattr__(self, "_edges", edges)
        object.__setattr__(self, "_edge_tree", shapely.STRtree(edges))

    @property
    def rings(self) -> tuple[FloatArray, ...]:
        """The exterior ring, then the holes' (each ``(n_k, 2)`` north/east [m])."""
        return (self.vertices, *self.holes)

    def contains(self, north: FloatArray, east: FloatArray) -> BoolArray:
        """Whether each point [m] (same shape) lies inside the exterior and in no hole.

        Points on the boundary may go either way (their distance to the boundary is 0).
        """
        import shapely

        return np.asarray(shapely.contains_xy(self._shape, east, north), dtype=np.bool_)

    def boundary_distance(self, north: FloatArray, east: FloatArray) -> FloatArray:
        """Distance [m] from each point (same shape) to the nearest edge of any ring.

        The nearest edge is found in an STR-tree of the edges (shapely), so that a boundary of
        thousands of vertices costs about ``log n`` per point.
        """
        import shapely

        points = shapely.points(np.ravel(east), np.ravel(north))
        pairs, distance = self._edge_tree.query_nearest(points, return_distance=True)
        nearest = np.full(points.shape, np.inf)
        np.minimum.at(nearest, pairs[0], distance)  # ties give several edges per point
        return nearest.reshape(np.shape(north))

    def cell_distance(
        self,
        centre_north: FloatArray,
        centre_east: FloatArray,
        half: tuple[float, float],
        reach: float,
    ) -> FloatArray:
        """Distance [m] between the boundary (every ring) and each cell rectangle.

        The rectangles are centred on ``centre_north, centre_east`` [m] with half-sizes
        ``half = (north, east)`` [m]. Exact where at most ``reach`` [m] (0 where an edge meets
        the rectangle), ``inf`` beyond: the edges within ``reach`` of each rectangle come from
        the STR-tree and their distance to it from GEOS. A rectangle that meets no edge lies
        wholly inside or wholly outside the polygon (its centre tells which).
        """
        import shapely

        north, east = np.broadcast_arrays(centre_north, centre_east)
        boxes = shapely.box(
            (east - half[1]).ravel(),
            (north - half[0]).ravel(),
            (east + half[1]).ravel(),
            (north + half[0]).ravel(),
        )
        cells, edges = self._edge_tree.query(boxes, predicate="dwithin", distance=reach)
        distance = np.full(boxes.shape, np.inf)
        np.minimum.at(distance, cells, shapely.distance(boxes[cells], self._edges[edges]))
        return distance.reshape(north.shape)


def _ring(vertices: FloatArray, what: str) -> FloatArray:
    """``vertices`` as a float array ``(n >= 3, 2)`` of finite values enclosing an area."""
    ring = np.asarray(vertices, dtype=np.float64)
    if ring.ndim != 2 or ring.shape[1] != 2 or ring.shape[0] < 3:
        raise InputError(f"{what} vertices must have shape (n >= 3, 2), got {np.shape(vertices)}")
    if not np.all(np.isfinite(ring)):
        raise InputError(f"{what} vertices must be finite")
    # the shoelace area relative to the square of the ring's extent (at least 1 m), on
    # coordinates scaled by that extent: no overflow for vertices as far out as 1e300 m
    scaled = (ring - ring.min(axis=0)) / max(1.0, float(np.ptp(ring)))
    north, east = scaled[:, 0], scaled[:, 1]
    area = 0.5 * (np.dot(north, np.roll(east, -1)) - np.dot(east, np.roll(north, -1)))
    if abs(area) <= 1e-12:
        raise InputError(f"{what} has zero area (vertices {ring.tolist()})")
    return ring


@dataclass(frozen=True, eq=False)
class OperatingArea:
    """The outside of an operating area: every vehicle stays inside ``region``.

    As an obstacle its no-go region is the complement of ``region`` (a hole of ``region``
    is an island of the area, no-go too), so its distance from a point inside the area is
    the distance to the area's boundary, and negative outside.

    Examples
    --------
    >>> area = OperatingArea(
    ...     PolygonObstacle(np.array([[0.0, 0.0], [0.0, 9.0], [9.0, 9.0], [9.0, 0.0]])))
    >>> distance_to_obstacle(area, np.array([3.0, 10.0]), np.array([4.0, 4.0])).tolist()
    [3.0, -1.0]
    """

    region: PolygonObstacle


#: Any obstacle (annotate mixed lists as ``list[Obstacle]``).
Obstacle: TypeAlias = CircleObstacle | PolygonObstacle | OperatingArea


def distance_to_obstacle(obstacle: Obstacle, north: FloatArray, east: FloatArray) -> FloatArray:
    r"""Signed distance [m] from points to an obstacle's boundary (negative inside).

    Parameters
    ----------
    obstacle : CircleObstacle, PolygonObstacle or OperatingArea
        The obstacle.
    north, east : ndarray
        Point coordinates [m] (broadcast together).

    Returns
    -------
    ndarray
        :math:`\|p - c\| - R` for a circle; for a polygon the distance to the nearest edge
        of any of its rings, negated inside (outside the holes); for an operating area the
        distance to its boundary, negated outside the area.

    Examples
    --------
    >>> distance_to_obstacle(CircleObstacle(0.0, 0.0, 1.0), np.array([3.0]), np.array([4.0]))
    array([4.])
    """
    north, east = np.broadcast_arrays(
        np.asarray(north, dtype=np.float64), np.asarray(east, dtype=np.float64)
    )
    if isinstance(obstacle, CircleObstacle):
        return np.asarray(np.hypot(north - obstacle.north, east - obstacle.east) - obstacle.radius)
    if isinstance(obstacle, OperatingArea):
        return -distance_to_obstacle(obstacle.region, north, east)
    distance = obstacle.boundary_distance(north, east)
    return np.asarray(np.where(obstacle.contains(north, east), -distance, distance))


def obstacle_mask(
    geometry: GridGeometry, obstacles: Iterable[Obstacle], *, clearance: float = 0.0
) -> BoolArray:
    """Cells of ``geometry`` that come within ``clearance`` of any obstacle.

    Parameters
    ----------
    geometry : GridGeometry
        The grid.
    obstacles : iterable of CircleObstacle, PolygonObstacle or OperatingArea
        Obstacles in the grid's world frame.
    clearance : float
        Extra distance [m] to keep from every obstacle, ``>= 0``.

    Returns
    -------
    ndarray of bool, shape (n_rows, n_cols)
        True on blocked cells.

    Examples
    --------
    >>> grid = GridGeometry(3, 3, 1.0, 1.0)
    >>> obstacle_mask(grid, [CircleObstacle(1.0, 1.0, 0.4)]).astype(int)
    array([[0, 0, 0],
           [0, 1, 0],
           [0, 0, 0]])
    >>> obstacle_mask(grid, [CircleObstacle(1.0, 1.0, 0.4)], clearance=0.2).astype(int)
    array([[0, 1, 0],
           [1, 1, 1],
           [0, 1, 0]])
    """
    if not (np.isfinite(clearance) and clearance >= 0.0):
        raise InputError(f"clearance must be finite and >= 0, got {clearance!r} m")
    mask = np.zeros(geometry.shape, dtype=np.bool_)
    half_north, half_east = 0.5 * geometry.spacing_north, 0.5 * geometry.spacing_east
    for obstacle in obstacles:
        if isinstance(obstacle, OperatingArea):  # every cell: the no-go region is unbounded
            north, east = np.meshgrid(geometry.north, geometry.east, indexing="ij")
            rim = obstacle.region.cell_distance(north, east, (half_north, half_east), clearance)
            mask |= ~obstacle.region.contains(north, east) | (rim < clearance) | (rim == 0.0)
            continue
        if isinstance(obstacle, CircleObstacle):
            low = np.array([obstacle.north, obstacle.east]) - obstacle.radius
            high = np.array([obstacle.north, obstacle.east]) + obstacle.radius
        elif isinstance(obstacle, PolygonObstacle):
            low, high = obstacle.vertices.min(axis=0), obstacle.vertices.max(axis=0)
        else:
            raise InputError(f"unknown obstacle type {type(obstacle).__name__}")
        rows = _overlapping(
            geometry.north, 0.5 * geometry.spacing_north, low[0], high[0], clearance
        )
        cols = _overlapping(geometry.east, 0.5 * geometry.spacing_east, low[1], high[1], clearance)
        if rows.stop <= rows.start or cols.stop <= cols.start:
            continue
        north = geometry.north[rows][:, np.newaxis]
        east = geometry.east[cols][np.newaxis, :]
        if isinstance(obstacle, CircleObstacle):
            gap_north = np.maximum(np.abs(north - obstacle.north) - half_north, 0.0)
            gap_east = np.maximum(np.abs(east - obstacle.east) - half_east, 0.0)
            hit = np.hypot(gap_north, gap_east) < obstacle.radius + clearance
        else:
            north, east = np.broadcast_arrays(north, east)
            distance = obstacle.cell_distance(north, east, (half_north, half_east), clearance)
            distance[obstacle.contains(north, east)] = 0.0
            hit = (distance < clearance) | (distance == 0.0)
        mask[rows, cols] |= hit
    return mask


def _overlapping(
    centres: FloatArray, half: float, low: float, high: float, clearance: float
) -> slice:
    """Slice of the (sorted) cell centres whose cells reach ``[low, high]`` dilated."""
    inside = np.flatnonzero(
        (centres + half >= low - clearance) & (centres - half <= high + clearance)
    )
    if inside.size == 0:
        return slice(0, 0)
    return slice(int(inside[0]), int(inside[-1]) + 1)
