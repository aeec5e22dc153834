"""The particle filter where the answer is known: flat seabed, strong relief, a matched model."""

from __future__ import annotations

import numpy as np
import pytest
from _navigation_synthetic import straight_track
from scipy.stats import chi2

from auvplan.errors import InputError
from auvplan.navigation import (
    DeadReckoningModel,
    NavigationSettings,
    ParticleFilterOptions,
    run_monte_carlo,
    run_particle_filter,
)
from auvplan.navigation._kernels import _systematic_resample
from auvplan.terrain import BathymetryGrid


def test_systematic_resampling_copies_each_particle_floor_or_ceil_times(
    rng: np.random.Generator,
) -> None:
    n = 1000
    weight = rng.gamma(0.3, size=n)
    north, east = np.arange(n, dtype=float), -np.arange(n, dtype=float)
    out_n, out_e = np.empty(n), np.empty(n)
    _systematic_resample(weight, float(weight.sum()), north, east, out_n, out_e, rng)
    counts = np.bincount(out_n.astype(int), minlength=n)
    expected = n * weight / weight.sum()
    assert counts.sum() == n
    assert np.all(counts >= np.floor(expected) - 1e-9)
    assert np.all(counts <= np.ceil(expected) + 1e-9)
    np.testing.assert_array_equal(out_e, -out_n)  # both coordinates copied from one particle


def test_flat_seabed_error_grows_like_dead_reckoning(flat_grid: BathymetryGrid) -> None:
    """No terrain information: the estimate is the dead-reckoned track, sigma the random walk."""
    settings = NavigationSettings(
        motion=DeadReckoningModel(drift_fraction=0.03),
        filter=ParticleFilterOptions(n_particles=1000, initial_sigma=0.5),
    )
    track = straight_track((100.0, 100.0), 0.5, 1.0, 900.0)
    result = run_monte_carlo(flat_grid, track, settings, n_runs=12, seed=3)
    # the TAN error is the dead-reckoning error, up to the mean of the particles' noise
    assert np.max(np.abs(result.error - result.dead_reckoning_error)) < 0.6
    final, start = result.error[:, -1].mean(), result.error[:, 0].mean()
    assert final > 10.0 * start  # 3 % of 900 m CEP: about 27 m, against 0.5 m at the start
    # no information, no resampling: the particles spread as the process noise says
    assert result.n_resamples.max() == 0
    assert result.ess.min() == pytest.approx(1000.0)
    process = np.full(result.time.size - 1, 0.25)  # the floor: 3 m steps are below it
    process = np.maximum(process, 2.0 * 0.03 * 3.0 / np.sqrt(2.0 * np.log(2.0)))
    expected = np.sqrt(2.0 * (0.5**2 + np.concatenate([[0.0], np.cumsum(process**2)])))
    np.testing.assert_allclose(result.sigma.mean(axis=0), expected, rtol=0.05)


def test_featured_terrain_bounds_the_error(featured_grid: BathymetryGrid) -> None:
    settings = NavigationSettings(filter=ParticleFilterOptions(n_particles=1000))
    track = straight_track((150.0, 150.0), 0.6, 1.0, 900.0)
    result = run_monte_carlo(featured_grid, track, settings, n_runs=12, seed=4)
    assert result.dead_reckoning_error[:, -1].mean() > 8.0  # 7 m initial error + 1 % drift
    assert result.error[:, -1].mean() < 2.0
    assert result.error[:, result.time > 100.0].max() < 5.0  # bounded once the terrain is seen
    assert result.rmse.mean() < 0.3 * result.dead_reckoning_rmse.mean()
    assert not result.diverged.any()


def test_consistent_when_the_model_matches_the_truth(featured_grid: BathymetryGrid) -> None:
    """Truth drawn from the filter's own model: mean NEES within chi-square bounds, RMSE ~ PCRB."""
    step_sigma = 0.3
    settings = NavigationSettings(
        motion=DeadReckoningModel(
            drift_fraction=0.0, velocity_noise=step_sigma / 3.0, noise_floor=step_sigma
        ),
        filter=ParticleFilterOptions(n_particles=2000, initial_sigma=5.0),
        update_period=3.0,
    )
    n_runs = 40
    result = run_monte_carlo(
        featured_grid,
        straight_track((200.0, 200.0), 0.7, 1.0, 450.0),
        settings,
        n_runs=n_runs,
        seed=5,
    )
    average = result.nees.mean(axis=0)  # ANEES per update, 2 dof
    low, high = chi2.ppf([0.005, 0.995], 2 * n_runs) / n_runs
    assert low < average.mean() < high
    assert np.mean((average > low) & (average < high)) > 0.9
    ratio = np.sqrt(np.mean(result.error**2)) / np.sqrt(np.mean(result.pcrb_sigma**2))
    assert 0.9 < ratio < 1.3  # no estimator beats the bound; this one nearly attains it


def test_inconsistent_shapes_are_refused(featured_grid: BathymetryGrid) -> None:
    with pytest.raises(InputError, match="inconsistent filter inputs"):
        run_particle_filter(
            featured_grid,
            np.zeros(2),
            np.zeros((4, 2)),
            np.ones(4),
            np.zeros((4, 1)),
            np.zeros((4, 1, 2)),
            np.ones((4, 1)),
            options=ParticleFilterOptions(n_particles=10),
            rng=np.random.default_rng(0),
        )


def test_soundings_no_particle_explains_are_left_out(featured_grid: BathymetryGrid) -> None:
    """All particles off the map: every update is skipped and the filter dead-reckons."""
    n_updates = 20
    increments = np.tile([2.0, 1.0], (n_updates - 1, 1))
    trace = run_particle_filter(
        featured_grid,
        np.array([-5000.0, -5000.0]),
        increments,
        np.full(n_updates - 1, 0.01),
        np.full((n_updates, 1), 50.0),
        np.zeros((n_updates, 1, 2)),
        np.ones((n_updates, 1)),
        options=ParticleFilterOptions(n_particles=500, initial_sigma=1.0),
        rng=np.random.default_rng(1),
    )
    assert trace.n_skipped == n_updates
    assert trace.n_resamples == 0
    np.testing.assert_allclose(trace.ess, 500.0)
    expected = np.array([-5000.0, -5000.0]) + np.vstack([[0.0, 0.0], np.cumsum(increments, 0)])
    np.testing.assert_allclose(trace.estimate, expected, atol=0.2)


def test_a_wildly_unlikely_sounding_keeps_weights_finite(featured_grid: BathymetryGrid) -> None:
    """Residuals of ~1000 sigma: log weights below exp's range are taken relative to the best."""
    soundings = np.array([[60.0], [1000.0]])  # the second ping is 1 km off every particle
    trace = run_particle_filter(
        featured_grid,
        np.array([500.0, 500.0]),
        np.array([[1.0, 0.0]]),
        np.array([0.25]),
        soundings,
        np.zeros((2, 1, 2)),
        np.ones((2, 1)),
        options=ParticleFilterOptions(n_particles=500, initial_sigma=5.0),
        rng=np.random.default_rng(2),
    )
    assert np.all(np.isfinite(trace.estimate))
    assert np.all(np.isfinite(trace.covariance))
    assert 1.0 <= trace.ess[1] <= 500.0
    assert trace.n_skipped == 0
