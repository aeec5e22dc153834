"""The cubic B-spline surface: exact derivatives, reproduction of planes, the node average."""

from __future__ import annotations

import numpy as np
import pytest

from auvplan.terrain import GridGeometry
from auvplan.terrain.spline import SplineSurface

GEOMETRY = GridGeometry(40, 50, 3.0, 2.0, 10.0, -5.0)


@pytest.fixture(scope="module")
def surface() -> SplineSurface:
    values = np.random.default_rng(0).normal(size=GEOMETRY.shape)
    values[5, 7] = np.nan  # no data counts as 0
    return SplineSurface.fit(GEOMETRY, values)


def test_derivatives_match_finite_differences(surface: SplineSurface) -> None:
    rng = np.random.default_rng(1)
    north, east = rng.uniform(0.0, 130.0, 300), rng.uniform(-10.0, 100.0, 300)
    exact = surface.evaluate(north, east)
    step = 1e-5
    d_north = (surface.evaluate(north + step, east) - surface.evaluate(north - step, east)) / (
        2 * step
    )
    d_east = (surface.evaluate(north, east + step) - surface.evaluate(north, east - step)) / (
        2 * step
    )
    np.testing.assert_allclose(d_north[:, 0], exact[:, 1], atol=1e-7)
    np.testing.assert_allclose(d_east[:, 0], exact[:, 2], atol=1e-7)
    np.testing.assert_allclose(d_north[:, 1], exact[:, 3], atol=1e-7)
    np.testing.assert_allclose(d_east[:, 1], exact[:, 4], atol=1e-7)
    np.testing.assert_allclose(d_east[:, 2], exact[:, 5], atol=1e-7)


def test_value_at_a_node_is_the_separable_one_four_one_average() -> None:
    values = np.random.default_rng(2).normal(size=GEOMETRY.shape)
    surface = SplineSurface.fit(GEOMETRY, values)
    i, j = 12, 30
    north = GEOMETRY.origin_north + i * GEOMETRY.spacing_north
    east = GEOMETRY.origin_east + j * GEOMETRY.spacing_east
    weights = np.array([1.0, 4.0, 1.0]) / 6.0
    expected = weights @ values[i - 1 : i + 2, j - 1 : j + 2] @ weights
    assert surface.evaluate(np.array([north]), np.array([east]))[0, 0] == pytest.approx(expected)


def test_a_plane_is_reproduced_inside_the_grid() -> None:
    plane = np.add.outer(0.5 * GEOMETRY.north, -2.0 * GEOMETRY.east) + 3.0
    surface = SplineSurface.fit(GEOMETRY, plane)
    rng = np.random.default_rng(3)
    north, east = rng.uniform(20.0, 100.0, 50), rng.uniform(5.0, 80.0, 50)
    out = surface.evaluate(north, east)
    np.testing.assert_allclose(out[:, 0], 0.5 * north - 2.0 * east + 3.0, atol=1e-9)
    np.testing.assert_allclose(out[:, 1:3], np.tile([0.5, -2.0], (50, 1)), atol=1e-9)
    np.testing.assert_allclose(out[:, 3:], 0.0, atol=1e-9)


def test_far_outside_the_grid_the_surface_is_flat_across_the_edge(
    surface: SplineSurface,
) -> None:
    out = surface.evaluate(np.array([-500.0, 900.0]), np.array([40.0, 40.0]))
    np.testing.assert_allclose(out[:, [1, 3, 4]], 0.0, atol=1e-12)  # every ∂/∂north
