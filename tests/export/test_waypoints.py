"""Waypoint thinning keeps the path and the time law within tolerance (oracle: np.interp)."""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely import LineString

from auvplan.errors import InputError
from auvplan.export.plan import VehicleTrack
from auvplan.export.waypoints import synchronized_distances, thin_track

from ._plans import synthetic_track


def _track(north: np.ndarray, east: np.ndarray, dt: float = 0.5) -> VehicleTrack:
    time = dt * np.arange(north.size)
    return VehicleTrack("v", time, north, east, north * 1e-5, east * 1e-5)


def _timed_error(track: VehicleTrack, tolerance: float) -> tuple[float, float, np.ndarray]:
    """Largest distance at the sample times and Hausdorff distance of the paths; the times."""
    waypoints = thin_track(track, tolerance)
    # the waypoint plan flown at constant leg speeds, sampled at the track's times
    north = np.interp(track.time, waypoints.time, waypoints.north)
    east = np.interp(track.time, waypoints.time, waypoints.east)
    timed = float(np.max(np.hypot(north - track.north, east - track.east)))
    full = LineString(np.column_stack([track.east, track.north]))
    thinned = LineString(np.column_stack([waypoints.east, waypoints.north]))
    return timed, float(full.hausdorff_distance(thinned)), waypoints.time


@settings(max_examples=60, deadline=None)
@given(
    steps=st.lists(
        st.tuples(
            st.floats(0.0, 1.5),  # speed [m/s], 0 = waiting
            st.floats(-np.pi, np.pi),  # heading [rad]
            st.integers(1, 30),  # samples held
        ),
        min_size=1,
        max_size=12,
    ),
    tolerance=st.sampled_from([0.0, 0.05, 0.5, 2.0, 10.0]),
)
def test_thinned_plan_stays_within_tolerance_of_the_track_at_every_time(
    steps: list[tuple[float, float, int]], tolerance: float
) -> None:
    dt = 0.5
    velocity = np.concatenate(
        [
            np.tile([speed * np.cos(psi), speed * np.sin(psi)], (count, 1))
            for speed, psi, count in steps
        ]
    )
    points = np.vstack([[0.0, 0.0], np.cumsum(velocity * dt, axis=0)])
    track = _track(points[:, 0], points[:, 1], dt)
    timed, hausdorff, times = _timed_error(track, tolerance)
    assert timed <= tolerance + 1e-9
    assert hausdorff <= tolerance + 1e-9
    assert np.all(np.diff(times) > 0.0)
    assert times[0] == track.time[0]
    assert times[-1] == track.time[-1]


def test_a_straight_line_at_constant_speed_needs_two_waypoints() -> None:
    s = np.linspace(0.0, 100.0, 201)
    assert thin_track(_track(0.6 * s, 0.8 * s), 0.01).index.tolist() == [0, 200]


def test_a_wait_on_a_straight_line_is_kept() -> None:
    """The path alone would be one segment; the time law needs the wait's two ends."""
    north = np.concatenate(
        [np.linspace(0.0, 20.0, 41), np.full(20, 20.0), np.linspace(20.5, 40.0, 40)]
    )
    waypoints = thin_track(_track(north, np.zeros_like(north)), 0.5)
    assert waypoints.index.size >= 4
    np.testing.assert_allclose(waypoints.leg_speeds.min(), 0.0, atol=0.05)


def test_thinning_compresses_a_smooth_track() -> None:
    track = synthetic_track("a", 0.0)
    waypoints = thin_track(track, 0.5)
    assert waypoints.index.size < 0.15 * track.time.size
    assert thin_track(track, 0.0).index.size > 3 * waypoints.index.size


@pytest.mark.parametrize("tolerance", [-1.0, float("nan"), float("inf")])
def test_bad_tolerance_names_the_key(tolerance: float) -> None:
    with pytest.raises(InputError, match="tolerance_m"):
        thin_track(synthetic_track("a", 0.0), tolerance)


@contextmanager
def _deadline(seconds: float) -> Iterator[None]:
    """Raise TimeoutError in the block after ``seconds`` [s] of wall time (Unix timers)."""

    def expire(signum: int, frame: object) -> None:
        raise TimeoutError(f"still running after {seconds:g} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)


@pytest.mark.parametrize(
    ("column", "value"), [("north", np.nan), ("east", np.inf), ("lat", np.nan), ("lon", -np.inf)]
)
def test_a_non_finite_track_is_an_error_not_an_endless_loop(column: str, value: float) -> None:
    """A NaN position never falls within the tolerance: the refinement looped forever."""
    track = synthetic_track("blue", 0.0)
    getattr(track, column)[17] = value
    with _deadline(10.0), pytest.raises(InputError) as raised:
        thin_track(track, 0.5)
    assert str(raised.value) == (
        f"track blue: {column} is {value} at sample 17 (1 non-finite of {track.time.size}); "
        "a track holds finite numbers only"
    )


def test_a_zero_tolerance_terminates_when_the_last_leg_rounds() -> None:
    """Interpolating to the last sample rounds; the kept samples' distances are exactly 0."""
    steps = [(1.2456566508179518, 1.2558427732033879, 10), (5e-324, -0.8375291082797736, 20),
             (1.0838656588728839, -2.7412365237798872, 27), (1e-300, 0.6351925565456384, 26),
             (0.9120863355851956, -2.595644752699721, 6)]  # fmt: skip
    velocity = np.concatenate(
        [np.tile([s * np.cos(psi), s * np.sin(psi)], (n, 1)) for s, psi, n in steps]
    )
    points = np.vstack([[0.0, 0.0], np.cumsum(velocity * 0.5, axis=0)])
    track = _track(points[:, 0], points[:, 1], 0.5)
    kept = thin_track(track, 0.0).index
    points = np.column_stack([track.north, track.east])
    distances, _ = synchronized_distances(track.time, points, kept)
    assert np.all(distances[kept] == 0.0)
    assert distances.max() == 0.0
