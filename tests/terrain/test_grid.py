"""Grid geometry: world -> cell index, also for points far outside or not finite."""

from __future__ import annotations

import numpy as np

from auvplan.terrain.grid import GridGeometry


def test_to_index_is_the_nearest_cell_centre(rng: np.random.Generator) -> None:
    geometry = GridGeometry(7, 9, 10.0, 5.0, origin_north=-3.0, origin_east=2.0)
    north = rng.uniform(-20.0, 80.0, 500)
    east = rng.uniform(-10.0, 60.0, 500)
    row, col = geometry.to_index(north, east)
    inside = geometry.contains(north, east)
    # Oracle: the nearest cell centre along each axis, by brute force over all centres.
    nearest_row = np.argmin(np.abs(north[:, None] - geometry.north[None, :]), axis=1)
    nearest_col = np.argmin(np.abs(east[:, None] - geometry.east[None, :]), axis=1)
    np.testing.assert_array_equal(row[inside], nearest_row[inside])
    np.testing.assert_array_equal(col[inside], nearest_col[inside])
    n_lo, n_hi = geometry.north_bounds
    e_lo, e_hi = geometry.east_bounds
    expected_inside = (north >= n_lo) & (north < n_hi) & (east >= e_lo) & (east < e_hi)
    np.testing.assert_array_equal(inside, expected_inside)


def test_far_and_non_finite_points_are_outside_without_overflow() -> None:
    """Casting 1e300 m to a cell index used to overflow int64 (a RuntimeWarning on stderr)."""
    geometry = GridGeometry(3, 4, 10.0, 5.0)
    north = np.array([-1e300, 1e300, np.nan, np.inf, -np.inf, 19.0])
    east = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 6.0])
    row, col = geometry.to_index(north, east)  # filterwarnings = error: no cast warning
    assert row.tolist() == [-1, 3, -1, 3, -1, 2]
    assert col.tolist() == [0, 0, 0, 0, 0, 1]
    assert geometry.contains(north, east).tolist() == [False] * 5 + [True]
