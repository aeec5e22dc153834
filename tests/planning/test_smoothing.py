"""smooth_path: exact endpoints, deviation bound, uniform steps, never in no-go cells."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy import ndimage

from auvplan.errors import InputError
from auvplan.planning import (
    CircleObstacle,
    EdgeModel,
    blocked_cells,
    blocked_lookup,
    path_headings,
    path_length,
    plan_route,
    smooth_path,
)
from auvplan.terrain.grid import GridGeometry


def distance_to_polyline(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """Exact distance from each point to a polyline (vectorised over segments)."""
    a, b = polyline[:-1], polyline[1:]
    ab = b - a
    length2 = np.maximum(np.sum(ab * ab, axis=1), 1e-300)
    t = np.clip(np.einsum("psk,sk->ps", points[:, None, :] - a[None], ab) / length2, 0.0, 1.0)
    nearest = a[None] + t[..., None] * ab[None]
    return np.asarray(np.min(np.linalg.norm(points[:, None, :] - nearest, axis=2), axis=1))


def terrain_case(seed: int, model: EdgeModel) -> tuple[np.ndarray, GridGeometry, object]:
    rng = np.random.default_rng(seed)
    n = 60
    noise = ndimage.gaussian_filter(rng.standard_normal((n, n)), 3.0)
    cost = 10.0 + 10.0 * np.cos(0.5 * np.pi * np.abs(noise) / np.abs(noise).max())
    cost[20:24, 5:45] = np.nan
    grid = GridGeometry(n, n, 2.0, 3.0)
    obstacles = [CircleObstacle(80.0, 120.0, 10.0)]
    route = plan_route(
        cost, grid, (3.0, 4.0), (115.0, 170.0), obstacles=obstacles, clearance=1.0, edge_model=model
    )
    is_blocked = blocked_lookup(grid, blocked_cells(cost, grid, obstacles=obstacles, clearance=1.0))
    return route.points, grid, is_blocked


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("model", list(EdgeModel))
def test_smoothing_constraints_on_astar_paths(seed: int, model: EdgeModel) -> None:
    points, _grid, is_blocked = terrain_case(seed, model)
    spacing, max_deviation = 0.7, 1.0
    curve = smooth_path(
        points,
        spacing=spacing,
        max_deviation=max_deviation,
        is_blocked=is_blocked,  # type: ignore[arg-type]
    )
    np.testing.assert_array_equal(curve[0], points[0])
    np.testing.assert_array_equal(curve[-1], points[-1])
    # curve -> polyline, exact distances at the samples; a real spline, not the fallback
    deviation = distance_to_polyline(curve, points)
    assert deviation.max() <= max_deviation
    assert deviation.max() > 0.1 * max_deviation
    # polyline -> curve: the sampled curve's chords are within a tiny sagitta of the curve
    dense_polyline = np.vstack([np.linspace(p, q, 20) for p, q in itertools.pairwise(points)])
    assert distance_to_polyline(dense_polyline, curve).max() <= max_deviation + 0.05
    # uniform arc-length steps close to the requested spacing
    steps = np.linalg.norm(np.diff(curve, axis=0), axis=1)
    step = path_length(curve) / len(steps)
    assert abs(step - spacing) <= 0.5 * spacing
    # chords of equal arcs: equal except where the curve turns (or at polyline corners
    # when the fallback polyline is returned)
    assert np.median(steps) >= 0.99 * steps.max()
    assert steps.min() >= 0.5 * steps.max()
    # never in a no-go cell, also between samples
    fine = np.vstack([np.linspace(p, q, 10) for p, q in itertools.pairwise(curve)])
    assert not is_blocked(fine[:, 0], fine[:, 1]).any()  # type: ignore[operator]


def test_staircase_is_smoothed() -> None:
    cells = np.array([[0, 0], [0, 1], [1, 2], [1, 3], [2, 4], [2, 5], [3, 6], [3, 7], [4, 8]])
    points = cells * 10.0
    curve = smooth_path(points, spacing=1.0, max_deviation=5.0)
    assert distance_to_polyline(curve, points).max() <= 5.0
    # far less turning than the staircase; C2 spline -> no heading jumps between samples
    turning = np.abs(np.diff(path_headings(curve)))
    assert turning.sum() < 0.5 * np.abs(np.diff(path_headings(points))).sum()
    assert turning.max() < 0.05


def test_straight_segment_is_resampled_exactly() -> None:
    curve = smooth_path(np.array([[0.0, 0.0], [0.0, 10.0]]), spacing=3.0, max_deviation=0.5)
    np.testing.assert_allclose(curve, np.column_stack((np.zeros(4), np.linspace(0.0, 10.0, 4))))


def test_falls_back_to_polyline_when_every_curve_is_blocked() -> None:
    points = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 0.0], [3.0, 1.0]])

    def everything_but_the_polyline(north: np.ndarray, east: np.ndarray) -> np.ndarray:
        return distance_to_polyline(np.column_stack((north, east)), points) > 1e-9

    curve = smooth_path(
        points, spacing=0.1, max_deviation=0.3, is_blocked=everything_but_the_polyline
    )
    assert distance_to_polyline(curve, points).max() < 1e-9
    np.testing.assert_array_equal(curve[[0, -1]], points[[0, -1]])


def test_repeated_points_are_dropped() -> None:
    points = np.array([[0.0, 0.0], [0.0, 0.0], [1.0, 1.0], [2.0, 1.0], [2.0, 1.0]])
    curve = smooth_path(points, spacing=0.2, max_deviation=0.2)
    np.testing.assert_array_equal(curve[[0, -1]], [[0.0, 0.0], [2.0, 1.0]])


def test_headings_clockwise_from_north_and_unwrapped() -> None:
    angle = np.linspace(0.0, 3.0 * np.pi, 300)  # 1.5 turns of a clockwise circle
    points = np.column_stack((np.sin(angle), -np.cos(angle)))  # starts heading north? check:
    # d(north)/da = cos a, d(east)/da = sin a -> heading psi = a (clockwise from north)
    psi = path_headings(points)
    np.testing.assert_allclose(psi[1:-1], angle[1:-1], atol=1e-3)
    assert path_length(points) == pytest.approx(3.0 * np.pi, rel=1e-4)


@pytest.mark.parametrize(
    ("points", "kwargs", "match"),
    [
        (np.zeros((1, 2)), {}, "shape"),
        (np.zeros((3, 2)), {}, "distinct"),
        (np.array([[0.0, 0.0], [np.nan, 1.0]]), {}, "finite"),
        (np.array([[0.0, 0.0], [1.0, 1.0]]), {"spacing": 0.0}, "spacing"),
        (np.array([[0.0, 0.0], [1.0, 1.0]]), {"max_deviation": -1.0}, "max_deviation"),
    ],
)
def test_validation(points: np.ndarray, kwargs: dict[str, float], match: str) -> None:
    options = {"spacing": 1.0, "max_deviation": 0.5}
    options.update(kwargs)
    with pytest.raises(InputError, match=match):
        smooth_path(points, spacing=options["spacing"], max_deviation=options["max_deviation"])
