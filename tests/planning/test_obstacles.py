"""Obstacle rasterisation against hand-computed cases and a dense-sampling loop oracle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from auvplan.errors import InputError
from auvplan.planning.obstacles import (
    CircleObstacle,
    Obstacle,
    OperatingArea,
    PolygonObstacle,
    distance_to_obstacle,
    obstacle_mask,
)
from auvplan.terrain.grid import GridGeometry


def test_circle_hand_computed() -> None:
    grid = GridGeometry(5, 5, 1.0, 1.0)
    # centre on cell (2, 2); radius 0.6 reaches the 4 edge-neighbours (gap 0.5) not diagonals
    # (gap hypot(0.5, 0.5) = 0.707)
    mask = obstacle_mask(grid, [CircleObstacle(2.0, 2.0, 0.6)])
    expected = np.zeros((5, 5), dtype=bool)
    expected[2, 1:4] = expected[1:4, 2] = True
    np.testing.assert_array_equal(mask, expected)
    # with clearance 0.2 the diagonals (0.707 < 0.8) are blocked too, not the distance-2 cells
    mask = obstacle_mask(grid, [CircleObstacle(2.0, 2.0, 0.6)], clearance=0.2)
    expected[1:4, 1:4] = True
    np.testing.assert_array_equal(mask, expected)


def test_circle_anisotropic_and_offset_grid() -> None:
    grid = GridGeometry(4, 3, 2.0, 10.0, origin_north=100.0, origin_east=-5.0)
    # cell rows span north 99..101, 101..103, ...; columns east -10..0, 0..10, 10..20
    mask = obstacle_mask(grid, [CircleObstacle(104.0, 0.5, 0.6)])
    expected = np.zeros((4, 3), dtype=bool)
    expected[2, 1] = True  # contains the centre
    expected[2, 0] = True  # 0.5 m from the column edge at east 0
    np.testing.assert_array_equal(mask, expected)


def test_polygon_hand_computed() -> None:
    grid = GridGeometry(6, 6, 1.0, 1.0)
    # square from north 1.6..3.4, east 1.6..2.4 lies in rows 2..3, col 2 (cells span +-0.5)
    square = PolygonObstacle(np.array([[1.6, 1.6], [1.6, 2.4], [3.4, 2.4], [3.4, 1.6]]))
    mask = obstacle_mask(grid, [square])
    expected = np.zeros((6, 6), dtype=bool)
    expected[2:4, 2] = True
    np.testing.assert_array_equal(mask, expected)
    # clearance 0.2 reaches cells whose edge is within 0.2: rows 1 (edge 1.5, gap 0.1) and 4
    # (edge 3.5, gap 0.1), cols 1 (edge 1.5) and 3 (edge 2.5), corners at hypot(0.1, 0.1)
    mask = obstacle_mask(grid, [square], clearance=0.2)
    expected[1:5, 1:4] = True
    np.testing.assert_array_equal(mask, expected)


def test_thin_polygon_crossing_cells_without_vertices_inside() -> None:
    grid = GridGeometry(3, 3, 1.0, 1.0)
    # long thin sliver along north = 1 crossing the whole grid; no vertex or centre inside
    # the middle cells' rectangles except through edges
    sliver = PolygonObstacle(np.array([[0.9, -5.0], [0.95, 5.0], [1.1, -5.0]]))
    mask = obstacle_mask(grid, [sliver])
    assert mask[1].all()
    assert not mask[0].any()
    assert not mask[2].any()


def _inside(vertices: np.ndarray, north: np.ndarray, east: np.ndarray) -> np.ndarray:
    """Even-odd ray casting along +east, one edge at a time."""
    is_inside = np.zeros(north.shape, dtype=bool)
    n = len(vertices)
    for i in range(n):
        (n1, e1), (n2, e2) = vertices[i], vertices[(i + 1) % n]
        if n1 == n2:
            continue
        straddles = (n1 > north) != (n2 > north)
        east_cross = e1 + (north - n1) * (e2 - e1) / (n2 - n1)
        is_inside ^= straddles & (east < east_cross)
    return is_inside


def _segment_distances(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ab = b - a
    t = np.clip((points - a) @ ab / (ab @ ab), 0.0, 1.0)
    return np.asarray(np.linalg.norm(points - (a + t[:, None] * ab), axis=1))


def _sampled_distance(
    obstacle: CircleObstacle | PolygonObstacle, grid: GridGeometry, row: int, col: int, n: int
) -> float:
    """Min distance from samples of the cell rectangle to the obstacle region (>= truth)."""
    centre_north = grid.origin_north + row * grid.spacing_north
    centre_east = grid.origin_east + col * grid.spacing_east
    s, t = np.meshgrid(np.linspace(-0.5, 0.5, n), np.linspace(-0.5, 0.5, n))
    north = (centre_north + s * grid.spacing_north).ravel()
    east = (centre_east + t * grid.spacing_east).ravel()
    if isinstance(obstacle, CircleObstacle):
        d = np.hypot(north - obstacle.north, east - obstacle.east) - obstacle.radius
        return float(max(d.min(), 0.0))
    v = obstacle.vertices
    points = np.column_stack((north, east))
    d = np.min([_segment_distances(points, v[i], v[(i + 1) % len(v)]) for i in range(len(v))], 0)
    d[_inside(v, north, east)] = 0.0
    return float(d.min())


@pytest.mark.parametrize("seed", range(4))
def test_mask_matches_sampling_oracle(seed: int) -> None:
    rng = np.random.default_rng(seed)
    grid = GridGeometry(9, 11, rng.uniform(0.5, 2.0), rng.uniform(0.5, 2.0), -3.0, 2.0)
    angles = np.sort(rng.uniform(0, 2 * np.pi, 6))
    radii = rng.uniform(1.0, 4.0, 6)
    centre = np.array([3.0, 9.0])
    vertices = centre + np.column_stack((radii * np.cos(angles), radii * np.sin(angles)))
    obstacles: list[Obstacle] = [
        PolygonObstacle(vertices),
        CircleObstacle(8.0, 4.0, rng.uniform(0.3, 2.0)),
    ]
    clearance = float(rng.choice([0.0, 0.3, 1.1]))
    mask = obstacle_mask(grid, obstacles, clearance=clearance)
    n_samples = 31
    # sampled distance overestimates the truth by at most half the sampling diagonal
    slack = 0.5 * math.hypot(grid.spacing_north, grid.spacing_east) / (n_samples - 1)
    for row in range(grid.n_rows):
        for col in range(grid.n_cols):
            sampled = min(_sampled_distance(o, grid, row, col, n_samples) for o in obstacles)
            if mask[row, col]:
                assert sampled <= clearance + slack, (row, col, sampled)
            else:
                assert sampled >= clearance, (row, col, sampled)
                assert sampled > 0.0


def test_distance_to_obstacle_signs() -> None:
    square = PolygonObstacle(np.array([[0.0, 0.0], [0.0, 2.0], [2.0, 2.0], [2.0, 0.0]]))
    d = distance_to_obstacle(
        square, np.array([1.0, 1.0, 5.0, -3.0]), np.array([1.0, 1.5, 1.0, -4.0])
    )
    np.testing.assert_allclose(d, [-1.0, -0.5, 3.0, 5.0])
    circle = CircleObstacle(1.0, 1.0, 2.0)
    np.testing.assert_allclose(
        distance_to_obstacle(circle, np.array([1.0, 4.0]), np.array([1.0, 5.0])), [-2.0, 3.0]
    )


def test_obstacle_outside_grid_blocks_nothing() -> None:
    grid = GridGeometry(4, 4, 1.0, 1.0)
    assert not obstacle_mask(grid, [CircleObstacle(100.0, 100.0, 3.0)]).any()


@pytest.mark.parametrize(
    ("build", "match"),
    [
        (lambda: CircleObstacle(0.0, 0.0, 0.0), "radius"),
        (lambda: CircleObstacle(np.nan, 0.0, 1.0), "centre"),
        (lambda: PolygonObstacle(np.array([[0.0, 0.0], [1.0, 1.0]])), "shape"),
        (lambda: PolygonObstacle(np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]])), "zero area"),
        (  # a vertex 1e300 m out (found by the fuzz test: an OverflowError before)
            lambda: PolygonObstacle(np.array([[1e300, 200.0], [98.5, 202.6], [98.5, 197.4]])),
            "zero area",
        ),
        (lambda: PolygonObstacle(np.array([[0.0, 0.0], [1.0, np.inf], [2.0, 0.0]])), "finite"),
        (
            lambda: obstacle_mask(GridGeometry(2, 2, 1.0, 1.0), [], clearance=-1.0),
            "clearance",
        ),
    ],
)
def test_validation(build: object, match: str) -> None:
    with pytest.raises(InputError, match=match):
        build()  # type: ignore[operator]


def _ring(centre: tuple[float, float], radii: np.ndarray, phase: float) -> np.ndarray:
    angles = phase + np.linspace(0.0, 2.0 * np.pi, len(radii), endpoint=False)
    return np.array(centre) + np.column_stack((radii * np.cos(angles), radii * np.sin(angles)))


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("kind", ["holed polygon", "operating area"])
def test_holes_and_areas_match_a_shapely_oracle(seed: int, kind: str) -> None:
    """Blocked cells come within the clearance of the no-go region, free cells do not.

    The no-go region of a polygon with a hole excludes the hole; an operating area's is the
    outside of the area (and its hole, an island). The oracle is shapely's distance from
    points sampled over each cell to that region.
    """
    import shapely
    from shapely import Polygon, box

    rng = np.random.default_rng(seed)
    grid = GridGeometry(14, 15, rng.uniform(0.6, 1.2), rng.uniform(0.6, 1.2), 0.0, 0.0)
    outer = _ring((7.0, 7.5), rng.uniform(5.0, 6.5, 9), rng.uniform(0.0, 1.0))
    hole = _ring((7.0, 7.5), rng.uniform(1.5, 2.5, 7), rng.uniform(0.0, 1.0))
    region = PolygonObstacle(outer, holes=(hole,))
    shape = Polygon(outer[:, ::-1], [hole[:, ::-1]])  # shapely x = east, y = north
    assert shape.is_valid
    obstacle: Obstacle = region
    no_go = shape
    if kind == "operating area":
        obstacle = OperatingArea(region)
        no_go = box(-100.0, -100.0, 100.0, 100.0).difference(shape)
    clearance = float(rng.choice([0.0, 0.4, 1.3]))
    mask = obstacle_mask(grid, [obstacle], clearance=clearance)
    n = 15
    slack = 0.5 * math.hypot(grid.spacing_north, grid.spacing_east) / (n - 1)
    s, t = np.meshgrid(np.linspace(-0.5, 0.5, n), np.linspace(-0.5, 0.5, n))
    rows, cols = np.meshgrid(np.arange(grid.n_rows), np.arange(grid.n_cols), indexing="ij")
    north = (rows[..., None] + s.ravel()) * grid.spacing_north  # (n_rows, n_cols, n * n)
    east = (cols[..., None] + t.ravel()) * grid.spacing_east
    sampled = shapely.distance(no_go, shapely.points(east, north)).min(axis=-1)
    assert np.all(sampled[mask] <= clearance + slack)
    free = sampled[~mask]
    assert np.all(free >= clearance)
    assert np.all(free > 0.0)
    assert mask.any()
    assert (~mask).any()
    # signed distances: the oracle's distance to the boundary, negative in the no-go region
    north = rng.uniform(0.0, 14.0, 300)
    east = rng.uniform(0.0, 15.0, 300)
    points = shapely.points(east, north)
    expected = np.where(no_go.contains(points), -1.0, 1.0) * shapely.distance(
        shape.boundary, points
    )
    np.testing.assert_allclose(distance_to_obstacle(obstacle, north, east), expected, atol=1e-9)


def test_a_hole_is_free_water_and_an_area_blocks_its_outside() -> None:
    square = np.array([[0.0, 0.0], [0.0, 10.0], [10.0, 10.0], [10.0, 0.0]])
    hole = np.array([[3.0, 3.0], [3.0, 7.0], [7.0, 7.0], [7.0, 3.0]])
    grid = GridGeometry(12, 12, 1.0, 1.0)  # cell (r, c) spans r +- 0.5, c +- 0.5
    ring = obstacle_mask(grid, [PolygonObstacle(square, holes=(hole,))])
    assert not ring[5, 5]  # the centre of the hole
    assert ring[1, 1]
    assert ring[5, 1]
    assert not ring[11, 11]  # outside the square
    area = obstacle_mask(grid, [OperatingArea(PolygonObstacle(square))], clearance=1.0)
    assert area[11, 11]
    assert area[0, 5]
    assert area[1, 5]
    assert not area[2, 5]
    assert not area[5, 5]
