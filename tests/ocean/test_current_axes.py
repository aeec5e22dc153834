"""A current file's depth and time axes: linear depth interpolation, the mission's time slices."""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest

from auvplan.io.currents import read_current
from auvplan.io.currents.levels import at_depth

from ._current_files import EAST, PROJECTION, analytic, level_factor, write_hycom

EXTENT = ((0.0, 2000.0), (0.0, 2000.0))
START_TIME = datetime(2026, 5, 1, 7, 0, tzinfo=UTC)  # one hour after the file's first time


@pytest.mark.parametrize(
    ("depth", "expected"),
    [(0.0, 1.0), (5.0, 0.75), (10.0, 0.5), (30.0, 0.3), (50.0, 0.1), (80.0, 0.1)],
)
def test_depth_is_linear_between_the_bracketing_levels(
    tmp_path: Path, depth: float, expected: float
) -> None:
    """Levels 0, 10, 50 m hold 1, 0.5, 0.1 of the surface field: linear between them, the
    last level's below it (the nearest level would give 0.5 at 30 m)."""
    field = read_current(
        write_hycom(tmp_path / "hycom.nc"),
        projection=PROJECTION,
        extent=EXTENT,
        start_time=START_TIME,
        depth=depth,
    )
    point = np.array([1000.0])
    lat, lon = PROJECTION.to_geographic(point, point)
    _, v_e = field.velocity(point, point, np.zeros(1))
    assert level_factor(depth) == pytest.approx(expected)
    np.testing.assert_allclose(v_e, expected * analytic(EAST, lat, lon, np.ones(1)), atol=1e-3)


def test_at_depth_holds_the_deepest_valid_level_below_the_floor() -> None:
    """Column 0 is water to 50 m, column 1's floor lies between 10 and 50 m (fill below),
    column 2 is land (all fill), column 3 has fill only at the surface level."""
    nan = np.nan
    values = np.array([[1.0, 1.0, nan, nan], [0.5, 0.5, nan, 0.5], [0.1, nan, nan, 0.1]])
    depths = np.array([0.0, 10.0, 50.0])[:, None]
    result = at_depth(values, depths, 30.0)
    np.testing.assert_allclose(result[[0, 1, 3]], [0.3, 0.5, 0.3])
    assert np.isnan(result[2])
    np.testing.assert_allclose(at_depth(values, depths, 2.0)[[0, 1]], [0.9, 0.9])


@pytest.mark.parametrize(
    ("horizon", "slices"),
    [(1800.0, 4), (5400.0, 5), (None, 6)],
)
def test_only_the_slices_around_the_mission_are_kept(
    tmp_path: Path, rng: np.random.Generator, horizon: float | None, slices: int
) -> None:
    """Hourly slices at mission times −1 … 4 h: a mission of ``horizon`` keeps those that
    bracket [0, horizon] and one more each side (the cubic B-spline reaches them), and the
    field over the mission is unchanged by the cut (linear in time, exactly reproduced)."""
    path = write_hycom(tmp_path / "hycom.nc")
    read = {"projection": PROJECTION, "extent": EXTENT, "start_time": START_TIME, "depth": 0.0}
    field = read_current(path, horizon=horizon, **read)  # type: ignore[arg-type]
    assert field.n_slices == slices
    assert field.start_offset == pytest.approx(-3600.0)
    assert field.time_step == pytest.approx(3600.0)
    time = rng.uniform(0.0, horizon or 3 * 3600.0, 30)
    north, east = rng.uniform(200.0, 1800.0, (2, 30))
    lat, lon = PROJECTION.to_geographic(north, east)
    _, v_e = field.velocity(north, east, time)
    np.testing.assert_allclose(v_e, analytic(EAST, lat, lon, 1.0 + time / 3600.0), atol=1e-3)
