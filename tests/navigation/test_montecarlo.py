"""Monte-Carlo runner: reproducible under a seed whatever the threads; inputs checked."""

from __future__ import annotations

import numpy as np
import pytest
from _navigation_synthetic import straight_track

from auvplan.errors import InputError
from auvplan.navigation import (
    NavigationSettings,
    ParticleFilterOptions,
    SensorModel,
    Track,
    run_monte_carlo,
)
from auvplan.terrain import BathymetryGrid

SMALL = NavigationSettings(filter=ParticleFilterOptions(n_particles=300))


def test_same_seed_same_result_whatever_the_threads(featured_grid: BathymetryGrid) -> None:
    track = straight_track((150.0, 150.0), 0.3, 1.0, 200.0)
    calls: list[int] = []
    one = run_monte_carlo(
        featured_grid, track, SMALL, n_runs=4, seed=11, workers=1, progress=calls.append
    )
    two = run_monte_carlo(featured_grid, track, SMALL, n_runs=4, seed=11, workers=2)
    other = run_monte_carlo(featured_grid, track, SMALL, n_runs=4, seed=12, workers=2)
    assert calls == [1, 2, 3, 4]
    for name in ("error", "sigma", "ess", "nees", "dead_reckoning_error", "example_estimate"):
        np.testing.assert_array_equal(getattr(one, name), getattr(two, name))
    assert not np.array_equal(one.error, other.error)
    assert len({tuple(run) for run in one.error.round(9)}) == 4  # runs are independent draws


def test_multibeam_sees_more_terrain_than_an_altimeter(featured_grid: BathymetryGrid) -> None:
    track = straight_track((150.0, 150.0), 0.3, 1.0, 300.0)
    altimeter = run_monte_carlo(featured_grid, track, SMALL, n_runs=1, seed=0)
    swath = NavigationSettings(sensor=SensorModel.multibeam(), filter=SMALL.filter)
    multibeam = run_monte_carlo(featured_grid, track, swath, n_runs=1, seed=0)
    assert np.all(multibeam.pcrb_sigma[1:] < altimeter.pcrb_sigma[1:])


def test_beam_footprints_lie_across_track(featured_grid: BathymetryGrid) -> None:
    from auvplan.navigation import beam_geometry

    sensor = SensorModel.multibeam()
    heading = np.array([0.0, np.pi / 2])
    offsets, variances = beam_geometry(sensor, featured_grid, np.full((2, 2), 500.0), heading)
    altitude = featured_grid.depth[100, 100]
    np.testing.assert_allclose(offsets[0, :, 0], 0.0, atol=1e-12)  # heading north: east offsets
    np.testing.assert_allclose(offsets[0, [0, -1], 1], [-altitude, altitude], rtol=1e-12)
    np.testing.assert_allclose(offsets[1, [0, -1], 0], [altitude, -altitude], rtol=1e-12)
    slant = altitude / np.cos(sensor.beam_angles)
    np.testing.assert_allclose(variances[0], 1.0 + (0.01 * slant) ** 2, rtol=1e-12)


def test_track_off_the_map_is_refused(featured_grid: BathymetryGrid) -> None:
    with pytest.raises(InputError, match="no depth"):
        run_monte_carlo(
            featured_grid, straight_track((-100.0, 50.0), 0.0, 1.0, 60.0), SMALL, n_runs=1, seed=0
        )


@pytest.mark.parametrize(
    ("time", "match"),
    [(np.array([0.0, 1.0, 1.0]), "strictly increasing"), (np.array([0.0]), "at least 2")],
)
def test_malformed_tracks_are_refused(time: np.ndarray, match: str) -> None:
    with pytest.raises(InputError, match=match):
        Track(time, np.zeros((time.size, 2)), np.zeros(time.size))


def test_track_shorter_than_an_update_period_is_refused() -> None:
    track = Track(np.array([0.0, 1.0]), np.zeros((2, 2)), np.zeros(2))
    with pytest.raises(InputError, match="less than one update"):
        track.sampled(3.0)
