r"""Terrain-aided navigation by particle filter on the state ``(north, east)``.

One update ``k`` (Gordon, Salmond and Smith 1993; MB-System's ``TNavParticleFilter``):

1. **predict**: :math:`x_i \leftarrow x_i + \hat d_k + \sigma_k \nu_i`, :math:`\nu_i \sim
   \mathcal N(0, I)` (:func:`~auvplan.navigation.motion.process_noise_sigma`);
2. **weight**: :math:`\log w_i \mathrel{+}= -\tfrac12 \sum_j (z_j - h(x_i + o_j))^2 / r_j`,
   :math:`h` the bilinear map (:mod:`~auvplan.navigation.depth`), :math:`r_j` the map plus beam
   variance (:mod:`~auvplan.navigation.sensors`); a particle whose footprint has no map depth
   gets weight 0, and a sounding no particle can explain is skipped;
3. **estimate**: the weighted mean and covariance of the particles;
4. **resample** when :math:`N_{eff} = 1 / \sum w_i^2 < f N` (systematic resampling), then
   **roughen** (Gordon et al. 1993, Sec. 4).

The numerical kernel is :func:`auvplan.navigation._kernels.particle_filter` (numba, GIL
released, all randomness from the run's generator).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.navigation._checks import require_nonnegative
from auvplan.navigation._kernels import particle_filter
from auvplan.terrain import BathymetryGrid

#: Most particles of one filter: 100 times MB-System TRN's ``MAX_PARTICLES`` (10 000), about
#: 60 MB of particle state per filter (seven arrays of N numbers).
MAX_PARTICLES: Final = 1_000_000


@dataclass(frozen=True)
class ParticleFilterOptions:
    """Particle-filter settings (defaults with sources).

    Parameters
    ----------
    n_particles : int
        Particle count ``N``, 2 to :data:`MAX_PARTICLES`. Default 5000 (MB-System TRN allows
        up to its ``MAX_PARTICLES`` = 10 000; open Python TAN templates use 1000).
    resample_fraction : float
        Resample when the effective sample size falls below ``f N``. Default 0.75: MB-System
        TRN's ``MIN_EFF_SAMP_SIZE`` (``particleFilterDefs.h``).
    roughening : float
        Roughening constant ``K`` (jitter ``K E N^(-1/d)`` after resampling, ``E`` the spread of
        the particles along each axis, ``d = 2``). Default 0.2: Gordon, Salmond and Smith (1993),
        Sec. 4. (MB-System leaves its resampling noise at 0 and relies on the process noise.)
    initial_sigma : float
        Standard deviation [m] per axis of the initial position error and particle cloud.
        Default 7.0: the convergence covariance limit of MB-System's ``mbtrnpp``
        (``trn-ncov`` = ``trn-ecov`` = 49 m²), i.e. the run starts as a fix that TRN would
        just call converged.
    """

    n_particles: int = 5000
    resample_fraction: float = 0.75
    roughening: float = 0.2
    initial_sigma: float = 7.0

    def __post_init__(self) -> None:
        if not 2 <= self.n_particles <= MAX_PARTICLES:
            raise InputError(
                f"particle filter needs >= 2 particles and at most {MAX_PARTICLES} "
                f"(--particles), got {self.n_particles}"
            )
        if not 0.0 < self.resample_fraction <= 1.0:
            raise InputError(f"resample_fraction must be in (0, 1], got {self.resample_fraction}")
        require_nonnegative("roughening", self.roughening)
        if not (np.isfinite(self.initial_sigma) and self.initial_sigma > 0.0):
            raise InputError(f"initial_sigma must be finite and > 0 m, got {self.initial_sigma}")


@dataclass(frozen=True)
class FilterTrace:
    """What one particle-filter run estimated, per update.

    Parameters
    ----------
    estimate : ndarray of shape (K + 1, 2)
        Weighted particle mean ``north, east`` [m].
    covariance : ndarray of shape (K + 1, 2, 2)
        Weighted particle covariance [m²].
    ess : ndarray of shape (K + 1,)
        Effective sample size after the measurement update, before resampling.
    n_resamples : int
        Number of resampling steps.
    n_skipped : int
        Updates whose soundings no particle could explain (left out).
    """

    estimate: FloatArray
    covariance: FloatArray
    ess: FloatArray
    n_resamples: int
    n_skipped: int

    @property
    def sigma(self) -> FloatArray:
        r"""Position standard deviation :math:`\sqrt{P_{nn} + P_{ee}}` [m], shape ``(K + 1,)``."""
        return np.asarray(np.sqrt(np.trace(self.covariance, axis1=1, axis2=2)), dtype=np.float64)


def run_particle_filter(
    grid: BathymetryGrid,
    initial_estimate: FloatArray,
    increments: FloatArray,
    process_sigma: FloatArray,
    soundings: FloatArray,
    offsets: FloatArray,
    variances: FloatArray,
    *,
    options: ParticleFilterOptions,
    rng: np.random.Generator,
) -> FilterTrace:
    """Run the filter over a track's odometry and soundings (module notes).

    Parameters
    ----------
    grid : BathymetryGrid
        The map.
    initial_estimate : ndarray of shape (2,)
        Initial position estimate [m]; the particles start around it with
        ``options.initial_sigma``.
    increments : ndarray of shape (K, 2)
        Dead-reckoned displacements [m] between updates.
    process_sigma : ndarray of shape (K,)
        Process-noise standard deviation [m] per axis of each increment.
    soundings : ndarray of shape (K + 1, n_beams)
        Measured depths [m] (NaN: none).
    offsets : ndarray of shape (K + 1, n_beams, 2)
        Beam footprint offsets [m].
    variances : ndarray of shape (K + 1, n_beams)
        Likelihood variance [m²] of each sounding.
    options : ParticleFilterOptions
        Settings.
    rng : numpy.random.Generator
        The run's random stream.

    Returns
    -------
    FilterTrace

    Raises
    ------
    InputError
        If the array shapes disagree.
    """
    n_updates, n_beams = soundings.shape
    if (
        increments.shape != (n_updates - 1, 2)
        or process_sigma.shape != (n_updates - 1,)
        or offsets.shape != (n_updates, n_beams, 2)
        or variances.shape != (n_updates, n_beams)
    ):
        raise InputError(
            f"inconsistent filter inputs: soundings {soundings.shape}, increments "
            f"{increments.shape}, process_sigma {process_sigma.shape}, offsets {offsets.shape}, "
            f"variances {variances.shape}"
        )
    geometry = grid.geometry
    frame = np.array(
        [geometry.origin_north, geometry.origin_east, geometry.spacing_north, geometry.spacing_east]
    )
    estimate = np.empty((n_updates, 2))
    moments = np.empty((n_updates, 3))
    ess = np.empty(n_updates)
    n_resamples, n_skipped = particle_filter(
        np.ascontiguousarray(grid.depth, dtype=np.float64),
        frame,
        np.asarray(initial_estimate, dtype=np.float64),
        float(options.initial_sigma),
        np.ascontiguousarray(increments, dtype=np.float64),
        np.ascontiguousarray(process_sigma, dtype=np.float64),
        np.ascontiguousarray(soundings, dtype=np.float64),
        np.ascontiguousarray(offsets, dtype=np.float64),
        np.ascontiguousarray(variances, dtype=np.float64),
        int(options.n_particles),
        float(options.resample_fraction * options.n_particles),
        float(options.roughening),
        rng,
        estimate,
        moments,
        ess,
    )
    covariance = np.empty((n_updates, 2, 2))
    covariance[:, 0, 0], covariance[:, 1, 1] = moments[:, 0], moments[:, 1]
    covariance[:, 0, 1] = covariance[:, 1, 0] = moments[:, 2]
    return FilterTrace(estimate, covariance, ess, int(n_resamples), int(n_skipped))
