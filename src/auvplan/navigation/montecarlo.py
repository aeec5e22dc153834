"""Monte-Carlo runs of terrain-aided navigation along one vehicle's planned track.

Each run draws, from its own generator, an initial position error, the dead-reckoning errors
(:mod:`~auvplan.navigation.motion`), the sounding noise (:mod:`~auvplan.navigation.sensors`)
and the filter's particles (:mod:`~auvplan.navigation.filter`). Run ``i`` of seed ``s`` uses
``numpy.random.Generator(SFC64(SeedSequence(s).spawn(n)[i]))`` (SFC64: numpy's fastest bit
generator, which matters here because the filter draws two normals per particle and update),
so results do not depend on how many threads run them; the filter kernel releases the GIL, so
runs go in parallel threads.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Final

import numpy as np

from auvplan._typing import BoolArray, FloatArray
from auvplan.errors import InputError
from auvplan.navigation.filter import ParticleFilterOptions, run_particle_filter
from auvplan.navigation.metrics import (
    CONVERGENCE_UPDATES,
    convergence_time,
    has_diverged,
    nees,
    rmse,
)
from auvplan.navigation.motion import (
    DeadReckoningModel,
    dead_reckon,
    process_noise_sigma,
    simulate_odometry,
)
from auvplan.navigation.pcrb import posterior_crb
from auvplan.navigation.sensors import SensorModel, beam_geometry, simulate_soundings
from auvplan.terrain import BathymetryGrid

#: Progress callback: called with the number of runs finished so far.
Progress = Callable[[int], None]

#: Most Monte-Carlo runs per track (``--runs``).
MAX_RUNS: Final = 100_000
#: Most filter updates in one run: a 48 h mission (the longest ``fleet.horizon_s``) updated
#: every 0.1 s (the shortest ``navigation.update_period_s``).
MAX_UPDATES: Final = 48 * 3600 * 10
#: Most particle updates (runs x particles x updates per run) one track may cost: about 6 h
#: of one core at the filter's ~5e6 particle updates per second.
MAX_PARTICLE_UPDATES: Final = 10**11
#: Bytes kept per run and update until a track's runs are summarised (estimates, dead
#: reckoning, sigma, ESS and NEES of every run, then stacked), and the most they may take.
RESULT_BYTES_PER_UPDATE: Final = 128
RESULT_MEMORY_BUDGET: Final = 4 * 2**30


@dataclass(frozen=True)
class Track:
    """A vehicle's true track.

    Parameters
    ----------
    time : ndarray of shape (n,)
        Strictly increasing time [s].
    positions : ndarray of shape (n, 2)
        ``north, east`` [m].
    heading : ndarray of shape (n,)
        Heading [rad], clockwise from north (may wrap; it is unwrapped before interpolation).
    depth : ndarray of shape (n,), optional
        The vehicle's depth [m], positive down, when it varies along the track (a plan of
        ``[mission] altitude_m``); ``None``: the sensor's constant ``vehicle_depth``.
    """

    time: FloatArray
    positions: FloatArray
    heading: FloatArray
    depth: FloatArray | None = None

    def __post_init__(self) -> None:
        n = self.time.shape[0]
        if self.time.ndim != 1 or n < 2:
            raise InputError(f"a track needs at least 2 samples, got {self.time.shape}")
        if self.positions.shape != (n, 2) or self.heading.shape != (n,):
            raise InputError(
                f"track arrays disagree: time {self.time.shape}, positions "
                f"{self.positions.shape}, heading {self.heading.shape}"
            )
        if not np.all(np.isfinite(self.positions)) or not np.all(np.isfinite(self.heading)):
            raise InputError("track positions and heading must be finite")
        if self.depth is not None and (
            self.depth.shape != (n,) or not np.all(np.isfinite(self.depth) & (self.depth >= 0.0))
        ):
            raise InputError(f"track depth must be {n} finite depths >= 0 m")
        if not np.all(np.diff(self.time) > 0.0):
            raise InputError("track time must be strictly increasing")

    @property
    def duration(self) -> float:
        """Time [s] from the first sample to the last."""
        return float(self.time[-1] - self.time[0])

    def n_updates(self, period: float) -> int:
        """Samples of :meth:`sampled` at ``period`` [s]: ``floor(duration / period) + 1``.

        Raises
        ------
        InputError
            If ``period`` is not finite and > 0, or longer than the track.
        """
        if not (np.isfinite(period) and period > 0.0):
            raise InputError(f"update period must be > 0 s, got {period}")
        n_updates = math.floor(self.duration / period + 1e-9) + 1
        if n_updates < 2:
            raise InputError(
                f"the track lasts {self.duration:g} s, less than one update period ({period:g} s)"
            )
        return n_updates

    def sampled(self, period: float) -> Track:
        """The track at ``time[0] + k * period`` up to ``time[-1]``, linearly interpolated."""
        n_updates = self.n_updates(period)
        time = self.time[0] + period * np.arange(n_updates, dtype=np.float64)
        positions = np.column_stack(
            [np.interp(time, self.time, self.positions[:, axis]) for axis in range(2)]
        )
        heading = np.interp(time, self.time, np.unwrap(self.heading))
        depth = None if self.depth is None else np.interp(time, self.time, self.depth)
        return Track(time, positions, heading, depth)


@dataclass(frozen=True)
class NavigationSettings:
    """The navigation system simulated: sensor, dead reckoning, filter and update period.

    Parameters
    ----------
    sensor : SensorModel
        Depth sensor (default: an altimeter).
    motion : DeadReckoningModel
        Dead-reckoning errors and the filter's process noise.
    filter : ParticleFilterOptions
        Particle-filter settings.
    update_period : float
        Time [s] between filter updates (one sounding each). Default 3 s: MB-System
        ``mbtrnpp`` decimates its TRN updates to one every few seconds (``trn-decs=3.0`` in
        ``src/mbtrn/tools/cfg/mbtrnpp-cfg.example``; the alternative ``trn-decn=9`` pings).
    convergence_updates : int
        Consecutive updates with position sigma <= 5 m that declare convergence. Default 200:
        MB-System ``mbtrnpp``'s ``convergence-repeat-min`` (counted in its TRN updates; at
        3 s that is 10 minutes, so shorter missions may ask for fewer).
    """

    sensor: SensorModel = field(default_factory=SensorModel.altimeter)
    motion: DeadReckoningModel = field(default_factory=DeadReckoningModel)
    filter: ParticleFilterOptions = field(default_factory=ParticleFilterOptions)
    update_period: float = 3.0
    convergence_updates: int = CONVERGENCE_UPDATES

    def __post_init__(self) -> None:
        if not 1 <= self.convergence_updates <= MAX_UPDATES:
            raise InputError(
                f"convergence_updates (--convergence-updates) must be >= 1 and <= {MAX_UPDATES} "
                f"(the most updates of a run), got {self.convergence_updates}"
            )


@dataclass(frozen=True)
class MonteCarloResult:
    """Terrain-aided navigation along one track over ``R`` Monte-Carlo runs.

    Per update (``K + 1`` of them, at ``time``) and run: ``error`` (TAN position error norm
    [m]), ``sigma`` (filter position standard deviation [m]), ``ess`` (effective sample
    size), ``nees`` and ``dead_reckoning_error`` (error norm of dead reckoning alone [m]), all
    of shape ``(R, K + 1)``. ``pcrb_sigma`` ``(K + 1,)`` is the posterior Cramér-Rao bound on
    the position standard deviation [m]. Per run ``(R,)``: ``n_resamples``. Run 0's tracks
    (``example_estimate``, ``example_dead_reckoning``, ``(K + 1, 2)``) and the true track
    ``truth`` serve the figures. ``convergence_updates`` is the convergence rule's run length.
    """

    time: FloatArray
    truth: FloatArray
    error: FloatArray
    sigma: FloatArray
    ess: FloatArray
    nees: FloatArray
    dead_reckoning_error: FloatArray
    pcrb_sigma: FloatArray
    n_resamples: FloatArray
    example_estimate: FloatArray
    example_dead_reckoning: FloatArray
    convergence_updates: int = CONVERGENCE_UPDATES

    @property
    def n_runs(self) -> int:
        """Number of runs ``R``."""
        return int(self.error.shape[0])

    @property
    def rmse(self) -> FloatArray:
        """TAN RMSE of each run [m], ``(R,)``."""
        return rmse(self.error)

    @property
    def dead_reckoning_rmse(self) -> FloatArray:
        """Dead-reckoning RMSE of each run [m], ``(R,)``."""
        return rmse(self.dead_reckoning_error)

    @property
    def convergence_time(self) -> FloatArray:
        """Time [s] each run met the convergence rule, NaN if it never did, ``(R,)``."""
        return np.array(
            [
                convergence_time(self.time, sigma, n_updates=self.convergence_updates)
                for sigma in self.sigma
            ]
        )

    @property
    def diverged(self) -> BoolArray:
        """Whether each run diverged (:func:`~auvplan.navigation.metrics.has_diverged`)."""
        return np.array([has_diverged(values) for values in self.nees], dtype=bool)

    @property
    def distance(self) -> float:
        """Length of the true track [m]."""
        return float(np.sum(np.hypot(*np.diff(self.truth, axis=0).T)))


def run_monte_carlo(
    grid: BathymetryGrid,
    track: Track,
    settings: NavigationSettings,
    *,
    n_runs: int,
    seed: int | Sequence[int],
    workers: int | None = None,
    progress: Progress | None = None,
) -> MonteCarloResult:
    """Simulate terrain-aided navigation along ``track`` ``n_runs`` times.

    Parameters
    ----------
    grid : BathymetryGrid
        The seabed and the filter's map.
    track : Track
        The true track; it is sampled every ``settings.update_period``.
    settings : NavigationSettings
        The navigation system.
    n_runs : int
        Number of Monte-Carlo runs (>= 1).
    seed : int or sequence of int
        Entropy of the runs' :class:`numpy.random.SeedSequence` (module notes).
    workers : int, optional
        Threads; default: the CPUs this process may use.
    progress : callable, optional
        Called with the number of finished runs after each run.

    Returns
    -------
    MonteCarloResult

    Raises
    ------
    InputError
        If the runs are refused by :func:`check_monte_carlo`, or the track starts where the
        sensor has no sounding of the map.
    """
    check_monte_carlo(track, settings, n_runs=n_runs, seed=seed)
    samples = track.sampled(settings.update_period)
    truth = samples.positions
    offsets, variances = beam_geometry(
        settings.sensor, grid, truth, samples.heading, vehicle_depth=samples.depth
    )
    if np.all(np.isnan(variances[0])):
        raise InputError(
            f"the track starts at north {truth[0, 0]:.1f} m, east {truth[0, 1]:.1f} m, "
            "where the map has no depth"
        )
    nominal_sigma = process_noise_sigma(settings.motion, np.diff(truth, axis=0))
    bound = posterior_crb(
        grid, truth, offsets, variances, nominal_sigma, settings.filter.initial_sigma
    )
    children = np.random.SeedSequence(seed).spawn(n_runs)

    def one_run(child: np.random.SeedSequence) -> tuple[FloatArray, ...]:
        return _simulate_run(grid, samples, offsets, variances, settings, child)

    n_workers = min(n_runs, workers or available_cpus())
    outcomes = []
    with ThreadPoolExecutor(max_workers=n_workers) as pool:
        for outcome in pool.map(one_run, children):
            outcomes.append(outcome)
            if progress is not None:
                progress(len(outcomes))
    estimates, dead_reckoned, sigma, ess, nees_values, n_resamples = (
        np.stack(values) for values in zip(*outcomes, strict=True)
    )
    return MonteCarloResult(
        time=samples.time,
        truth=truth,
        error=np.linalg.norm(estimates - truth, axis=-1),
        sigma=sigma,
        ess=ess,
        nees=nees_values,
        dead_reckoning_error=np.linalg.norm(dead_reckoned - truth, axis=-1),
        pcrb_sigma=np.sqrt(np.trace(bound, axis1=1, axis2=2)),
        n_resamples=n_resamples,
        example_estimate=estimates[0],
        example_dead_reckoning=dead_reckoned[0],
        convergence_updates=settings.convergence_updates,
    )


def check_monte_carlo(
    track: Track, settings: NavigationSettings, *, n_runs: int, seed: int | Sequence[int]
) -> int:
    """The updates per run of ``n_runs`` runs along ``track``, refused before any allocation.

    The bounds: ``1 <= n_runs <=`` :data:`MAX_RUNS`, seeds >= 0, at most :data:`MAX_UPDATES`
    updates per run, at most :data:`MAX_PARTICLE_UPDATES` particle updates (runs x particles
    x updates per run: the work) and at most :data:`RESULT_MEMORY_BUDGET` bytes of results
    (runs x updates per run x :data:`RESULT_BYTES_PER_UPDATE`). Each message names the
    ``auvplan evaluate`` flag to change and the limit.

    Raises
    ------
    InputError
        If a bound is broken, or the track lasts less than one update period.
    """
    if not 1 <= n_runs <= MAX_RUNS:
        raise InputError(f"--runs must be >= 1 and <= {MAX_RUNS}, got {n_runs}")
    seeds = [seed] if isinstance(seed, int) else list(seed)
    if any(value < 0 for value in seeds):
        raise InputError(f"--seed must be a non-negative integer, got {min(seeds)}")
    period = settings.update_period
    n_updates = track.n_updates(period)
    updates = (
        f"{n_updates} updates per run (--update-period {period:g} s over a "
        f"{track.duration:g} s track)"
    )
    if n_updates > MAX_UPDATES:
        raise InputError(f"{updates} are more than the limit {MAX_UPDATES}")
    n_particles = settings.filter.n_particles
    work = n_runs * n_particles * n_updates
    if work > MAX_PARTICLE_UPDATES:
        raise InputError(
            f"--runs {n_runs} x --particles {n_particles} x {updates} = {work:.3g} particle "
            f"updates, more than the limit {MAX_PARTICLE_UPDATES:.0e}: give fewer runs or "
            "particles, or a longer update period"
        )
    needed = n_runs * n_updates * RESULT_BYTES_PER_UPDATE
    if needed > RESULT_MEMORY_BUDGET:
        raise InputError(
            f"--runs {n_runs} x {updates} need ~{needed / 2**30:.0f} GiB of results, more "
            f"than the limit {RESULT_MEMORY_BUDGET / 2**30:.0f} GiB: give fewer runs or a "
            "longer update period"
        )
    return n_updates


def _simulate_run(
    grid: BathymetryGrid,
    samples: Track,
    offsets: FloatArray,
    variances: FloatArray,
    settings: NavigationSettings,
    seed: np.random.SeedSequence,
) -> tuple[FloatArray, ...]:
    """One run: estimates, dead-reckoned track, sigma, ESS, NEES and the resampling count."""
    rng = np.random.Generator(np.random.SFC64(seed))
    truth = samples.positions
    initial = truth[0] + settings.filter.initial_sigma * rng.standard_normal(2)
    increments = simulate_odometry(
        settings.motion, np.diff(truth, axis=0), np.diff(samples.time), rng
    )
    soundings = simulate_soundings(grid, truth, offsets, variances, rng)
    trace = run_particle_filter(
        grid,
        initial,
        increments,
        process_noise_sigma(settings.motion, increments),
        soundings,
        offsets,
        variances,
        options=settings.filter,
        rng=rng,
    )
    return (
        trace.estimate,
        dead_reckon(initial, increments),
        trace.sigma,
        trace.ess,
        nees(trace.estimate - truth, trace.covariance),
        np.array(float(trace.n_resamples)),
    )


def available_cpus() -> int:
    """CPUs this process may run on (the default thread count of :func:`run_monte_carlo`)."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)
