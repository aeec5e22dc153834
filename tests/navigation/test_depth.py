"""Map interpolation: bilinear depth against scipy, gradient against finite differences."""

from __future__ import annotations

import numpy as np
from scipy.interpolate import RegularGridInterpolator

from auvplan.navigation import depth_at, depth_gradient_at
from auvplan.terrain import BathymetryGrid, GridGeometry


def _random_grid(rng: np.random.Generator) -> BathymetryGrid:
    geometry = GridGeometry(13, 17, 3.0, 5.0, origin_north=-10.0, origin_east=20.0)
    return BathymetryGrid(30.0 + 10.0 * rng.random(geometry.shape), geometry)


def test_depth_matches_scipy_linear_interpolation(rng: np.random.Generator) -> None:
    grid = _random_grid(rng)
    geometry = grid.geometry
    oracle = RegularGridInterpolator((geometry.north, geometry.east), grid.depth)
    north = rng.uniform(geometry.north[0], geometry.north[-1], 500)
    east = rng.uniform(geometry.east[0], geometry.east[-1], 500)
    north[:3], east[:3] = geometry.north[-1], geometry.east[-1]  # the far corner node itself
    np.testing.assert_allclose(depth_at(grid, north, east), oracle((north, east)), rtol=1e-12)


def test_no_depth_off_the_map_or_next_to_a_no_data_node(rng: np.random.Generator) -> None:
    grid = _random_grid(rng)
    grid.depth[5, 5] = np.nan
    north, east = grid.geometry.to_world(
        np.array([4.5, 5.9, 7.0, -0.01]), np.array([4.2, 5.0, 7.0, 3])
    )
    depth = depth_at(grid, north, east)
    np.testing.assert_array_equal(np.isnan(depth), [True, True, False, True])
    assert np.isnan(depth_gradient_at(grid, north[3:], east[3:])).all()


def test_gradient_matches_central_differences(rng: np.random.Generator) -> None:
    grid = _random_grid(rng)
    # points well inside cells: the bilinear surface is smooth there
    rows = rng.integers(0, 12, 200) + rng.uniform(0.1, 0.9, 200)
    cols = rng.integers(0, 16, 200) + rng.uniform(0.1, 0.9, 200)
    north, east = grid.geometry.to_world(rows, cols)
    step = 1e-4
    numeric = np.column_stack(
        [
            (depth_at(grid, north + step, east) - depth_at(grid, north - step, east)) / (2 * step),
            (depth_at(grid, north, east + step) - depth_at(grid, north, east - step)) / (2 * step),
        ]
    )
    np.testing.assert_allclose(depth_gradient_at(grid, north, east), numeric, rtol=1e-6, atol=1e-9)
