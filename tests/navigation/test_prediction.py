"""The predicted TAN error: known answers, the PCRB without drift, and the particle filter."""

from __future__ import annotations

import numpy as np
import pytest
from _navigation_synthetic import featured_depth, make_grid, straight_track

from auvplan.navigation import (
    DeadReckoningModel,
    NavigationSettings,
    ParticleFilterOptions,
    SensorModel,
    Track,
    posterior_crb,
    process_noise_sigma,
    run_monte_carlo,
)
from auvplan.navigation.prediction import fisher_map, predict_error
from auvplan.navigation.sensors import beam_geometry
from auvplan.terrain import BathymetryGrid, GridGeometry


def _flat(depth: float = 40.0) -> BathymetryGrid:
    return BathymetryGrid(np.full((60, 60), depth), GridGeometry(60, 60, 100.0, 100.0))


def test_flat_seabed_grows_like_dead_reckoning() -> None:
    """No information: σ² = 2 (σ0² + (σ_b D)²) exactly without process noise, and the filter's
    process noise only raises the growth where dead reckoning grows slower than it."""
    track = straight_track((3000.0, 200.0), np.pi / 2, 1.0, 4200.0, dt=30.0)
    quiet = NavigationSettings(motion=DeadReckoningModel(noise_floor=0.0, noise_multiplier=0.0))
    prediction = predict_error(_flat(), track, quiet)
    distance = np.hypot(*(prediction.positions - prediction.positions[0]).T)
    bias = quiet.motion.bias_sigma
    expected = np.sqrt(2.0 * (7.0**2 + (bias * distance) ** 2))
    np.testing.assert_allclose(prediction.sigma, expected, rtol=1e-9)
    noisy = predict_error(_flat(), track, NavigationSettings())
    assert np.all(noisy.sigma >= expected - 1e-9)
    n_updates = np.arange(distance.size)
    white = process_noise_sigma(NavigationSettings().motion, np.array([[3.0, 0.0]]))[0] ** 2
    assert np.all(noisy.sigma**2 <= expected**2 + 2.0 * n_updates * white + 1e-9)


def test_without_drift_the_prediction_is_the_pcrb() -> None:
    grid = make_grid(featured_depth)
    track = straight_track((200.0, 100.0), 0.6, 0.8, 900.0)
    settings = NavigationSettings(
        sensor=SensorModel.multibeam(), motion=DeadReckoningModel(drift_fraction=0.0)
    )
    prediction = predict_error(grid, track, settings)
    samples = track.sampled(settings.update_period)
    offsets, variances = beam_geometry(settings.sensor, grid, samples.positions, samples.heading)
    bound = posterior_crb(
        grid,
        samples.positions,
        offsets,
        variances,
        process_noise_sigma(settings.motion, np.diff(samples.positions, axis=0)),
        settings.filter.initial_sigma,
    )
    np.testing.assert_allclose(prediction.covariance, bound, rtol=1e-10, atol=1e-12)


def test_fisher_map_of_a_plane_is_its_gradient_outer_product() -> None:
    """Altimeter over a plane of slope (a, b): F = g gᵀ / (σ_map² + (κ h)²) in every cell."""
    geometry = GridGeometry(40, 50, 10.0, 10.0)
    north, east = np.meshgrid(geometry.north, geometry.east, indexing="ij")
    grid = BathymetryGrid(50.0 + 0.05 * north - 0.02 * east, geometry)
    coarse = geometry.coarsen(2, 2)
    fisher = fisher_map(grid, coarse, SensorModel.altimeter())
    centre = 50.0 + 0.05 * coarse.north[:, None] - 0.02 * coarse.east[None, :]
    variance = 1.0 + (0.01 * centre) ** 2
    inner = (slice(1, -1), slice(1, -1))  # the map's edge cells reach past the last node
    np.testing.assert_allclose(fisher[..., 0][inner], (0.05**2 / variance)[inner], rtol=0.02)
    np.testing.assert_allclose(fisher[..., 1][inner], (-0.001 / variance)[inner], rtol=0.02)
    np.testing.assert_allclose(fisher[..., 2][inner], (0.02**2 / variance)[inner], rtol=0.02)


def test_swath_information_does_not_depend_on_heading_for_a_plane() -> None:
    geometry = GridGeometry(60, 60, 10.0, 10.0)
    north = np.repeat(geometry.north[:, None], geometry.n_cols, axis=1)
    grid = BathymetryGrid(50.0 + 0.05 * north, geometry)
    fisher = fisher_map(grid, geometry, SensorModel.multibeam())
    # 11 beams of the same slope, heavier variance off-nadir: between 1x and 11x the nadir's
    nadir = 0.05**2 / (1.0 + (0.01 * (50.0 + 0.05 * geometry.north[30])) ** 2)
    assert nadir < fisher[30, 30, 0] < 11.0 * nadir
    assert fisher[30, 30, 2] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize(
    ("depth", "heading"),
    [(featured_depth, 0.4), (lambda n, e: 60.0 + 0.0 * n, 1.2)],
    ids=["featured", "flat"],
)
def test_prediction_tracks_the_particle_filter(depth: object, heading: float) -> None:
    """Predicted RMS radial error within 30 % of the simulated RMSE (a handful of runs)."""
    grid = make_grid(depth)  # type: ignore[arg-type]
    track = straight_track((150.0, 150.0), heading, 0.7, 900.0)
    settings = NavigationSettings(filter=ParticleFilterOptions(n_particles=2000))
    simulated = float(np.mean(run_monte_carlo(grid, track, settings, n_runs=12, seed=3).rmse))
    predicted = predict_error(grid, track, settings).rms
    assert predicted == pytest.approx(simulated, rel=0.3)


def test_short_tracks_are_refused_with_one_line() -> None:
    track = Track(np.array([0.0, 1.0]), np.array([[0.0, 0.0], [1.0, 0.0]]), np.zeros(2))
    with pytest.raises(Exception, match="less than one update period"):
        predict_error(_flat(), track, NavigationSettings())
