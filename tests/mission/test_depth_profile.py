"""The depth profile of a constant-altitude plan: clearance, rates, surface, and nothing lost."""

from __future__ import annotations

import numpy as np
import pytest

from auvplan.errors import InputError
from auvplan.mission.checks import seabed_violations
from auvplan.mission.depth_profile import depth_profile, rate_limited_depth
from auvplan.navigation.depth import depth_at
from auvplan.terrain import BathymetryGrid, GridGeometry
from auvplan.vehicle import DepthLimits

#: Round-off allowed on a rate or clearance constraint [m].
TOLERANCE = 1e-9


def _ridge(height: float = 40.0) -> BathymetryGrid:
    """100 m deep, with a ridge rising ``height`` m (a Gaussian 40 m wide) across east = 300 m."""
    geometry = GridGeometry(60, 120, 5.0, 5.0)
    east = geometry.east[None, :]
    depth = 100.0 - height * np.exp(-(((east - 300.0) / 40.0) ** 2)) + 0.0 * geometry.north[:, None]
    return BathymetryGrid(depth, geometry)


def _straight(time: np.ndarray, speed: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """A track eastward along north = 150 m from east = 20 m at ``speed`` [m/s]."""
    return np.full(time.size, 150.0), 20.0 + speed * time


def _assert_rates(time: np.ndarray, depth: np.ndarray, limits: DepthLimits) -> None:
    rate = np.diff(depth) / np.diff(time)
    assert rate.min() >= -limits.climb_rate - TOLERANCE
    assert rate.max() <= limits.dive_rate + TOLERANCE


def test_rate_limited_depth_is_the_greatest_feasible_sequence_below_the_target(
    rng: np.random.Generator,
) -> None:
    for _ in range(20):
        time = np.cumsum(rng.uniform(0.1, 2.0, 200))
        target = np.cumsum(rng.normal(0.0, 3.0, 200)) + 100.0
        climb, dive = rng.uniform(0.05, 1.0, 2)
        depth = rate_limited_depth(time, target, climb_rate=climb, dive_rate=dive)
        assert np.all(depth <= target)
        _assert_rates(time, depth, DepthLimits(climb, dive, 0.0))
        # every feasible sequence below the target lies below it: any lower target's profile
        lower = rate_limited_depth(
            time, target - rng.uniform(0.0, 5.0, 200), climb_rate=climb, dive_rate=dive
        )
        assert np.all(lower <= depth + TOLERANCE)
        # and it is as deep as allowed: each sample meets its target, or the depth a climb
        # to the next sample or a dive from the previous one allows
        dt = np.diff(time)
        after = np.append(depth[1:] + climb * dt, np.inf)
        before = np.insert(depth[:-1] + dive * dt, 0, np.inf)
        assert np.all((depth == target) | np.isclose(depth, after) | np.isclose(depth, before))


def test_flat_seabed_gives_the_desired_depth_exactly() -> None:
    flat = BathymetryGrid(np.full((60, 120), 73.25), GridGeometry(60, 120, 5.0, 5.0))
    time = np.arange(0.0, 300.0, 0.5)
    north, east = _straight(time)
    profile = depth_profile(
        time, north, east, flat, altitude=10.5, limits=DepthLimits(0.1, 0.1, 3.0)
    )
    assert np.array_equal(profile.depth, np.full(time.size, 73.25 - 10.5))
    assert np.array_equal(profile.altitude, np.full(time.size, 10.5))


@pytest.mark.parametrize(("altitude", "min_altitude"), [(8.0, 3.0), (2.0, 5.0)])
def test_ridge_keeps_clearance_between_samples_and_the_rates(
    altitude: float, min_altitude: float
) -> None:
    """A ridge rising 40 m over ~80 m (up to 0.86 m/m), crossed at 1 m/s: 0.4 m/s climbs."""
    grid = _ridge()
    limits = DepthLimits(climb_rate=0.4, dive_rate=0.5, min_altitude=min_altitude)
    time = np.arange(0.0, 400.0, 1.0)
    north, east = _straight(time)
    profile = depth_profile(time, north, east, grid, altitude=altitude, limits=limits)
    depth = profile.depth
    _assert_rates(time, depth, limits)
    assert np.all(depth >= 0.0)
    # the hard clearance at every sample and on 20 points between samples (depth flown linearly)
    fine_time = np.linspace(time[0], time[-1], 20 * (time.size - 1) + 1)
    fine_depth = np.interp(fine_time, time, depth)
    seabed = depth_at(grid, *_straight(fine_time))
    assert np.all(seabed - fine_depth >= min_altitude - TOLERANCE)
    assert np.all(profile.altitude >= min_altitude - TOLERANCE)
    # never deeper than desired, and the rate limits bind (the ridge is steeper than them)
    desired = profile.seabed - max(altitude, min_altitude)
    assert np.all(depth <= desired + TOLERANCE)
    rate = np.diff(depth) / np.diff(time)
    assert np.isclose(rate.min(), -limits.climb_rate)
    assert np.isclose(rate.max(), limits.dive_rate)
    # the climb starts before the seabed rises: above desired where it is still 99 m deep
    assert np.any((desired - depth > 0.5) & (profile.seabed > 99.0))
    # far from the ridge the profile is the desired depth (to the seabed's slope over a step)
    np.testing.assert_allclose(depth[[0, -1]], desired[[0, -1]], atol=1e-2)


def test_a_shoal_shallower_than_the_altitude_is_flown_at_the_surface() -> None:
    grid = _ridge(height=97.0)  # 3 m deep at the crest
    time = np.arange(0.0, 400.0, 1.0)
    north, east = _straight(time)
    profile = depth_profile(
        time, north, east, grid, altitude=10.0, limits=DepthLimits(0.5, 0.5, 1.0)
    )
    assert profile.depth.min() == 0.0
    assert np.all(profile.depth >= 0.0)
    assert np.all(profile.depth[profile.seabed <= 10.0] == 0.0)


def test_samples_off_the_map_take_the_nearest_seabed() -> None:
    flat = BathymetryGrid(np.full((60, 120), 50.0), GridGeometry(60, 120, 5.0, 5.0))
    time = np.arange(0.0, 20.0, 1.0)
    east = np.linspace(560.0, 620.0, time.size)  # the grid ends at east = 595 m
    profile = depth_profile(
        time, np.full(time.size, 100.0), east, flat, altitude=5.0, limits=DepthLimits()
    )
    assert np.all(profile.depth == 45.0)
    with pytest.raises(InputError, match="off the map"):
        depth_profile(time, np.full(time.size, 1e4), east, flat, altitude=5.0, limits=DepthLimits())


def test_a_shoal_under_the_minimum_altitude_is_a_named_seabed_violation() -> None:
    grid = _ridge(height=97.0)  # 3 m deep at the crest, the minimum altitude is 4 m
    time = np.arange(0.0, 400.0, 1.0)
    north, east = _straight(time)
    limits = DepthLimits(0.5, 0.5, 4.0)
    shoal = depth_profile(time, north, east, grid, altitude=10.0, limits=limits)
    (violation,) = seabed_violations(("blue",), (shoal,))
    assert violation.who == "blue"
    assert violation.value == pytest.approx(3.0, abs=0.01)
    assert violation.time == pytest.approx(280.0, abs=1.0)  # the crest, east = 300 m
    assert violation.describe().startswith("seabed clearance: blue at 3.00 m < 4 m (t = 2")
    deep = depth_profile(time, north, east, _ridge(), altitude=10.0, limits=limits)
    assert seabed_violations(("blue",), (deep,)) == []
