r"""Numba kernels of the terrain-aided navigation simulator: map interpolation and the filter.

Map interpolation is bilinear between the four grid nodes around a point given by its
fractional ``(row, col)`` index (:meth:`auvplan.terrain.GridGeometry.to_fractional_index`,
cell centres at integers). A point outside ``[0, n - 1]`` along either axis, or touching a NaN
node, has no depth (NaN), exactly as :func:`auvplan.terrain.resample` treats no-go cells.

The particle filter (:func:`particle_filter`) is the bootstrap filter of Gordon, Salmond and
Smith (1993) on the state ``(north, east)``: every update moves each particle by the measured
dead-reckoning increment plus Gaussian process noise, weights it by the Gaussian likelihood of
the soundings against the map, and resamples systematically when the effective sample size
falls below a fraction of the particle count, followed by roughening. Prediction, weighting
and the weighted moments share one pass over the particles. All random numbers come
from the ``numpy.random.Generator`` passed in, so a run is reproducible from its seed whatever
thread runs it (the kernels release the GIL).
"""

from __future__ import annotations

from typing import Final

import numba
import numpy as np

from auvplan._typing import FloatArray

#: Below this best log weight, exp(log w) and its square could underflow: weigh relative to it.
_UNDERFLOW_LOG_WEIGHT: Final = -300.0


@numba.njit(cache=True, nogil=True, inline="always")
def _bilinear(depth: FloatArray, row: float, col: float) -> float:
    """Bilinear depth at fractional ``(row, col)``; NaN outside the grid or next to NaN."""
    n_rows, n_cols = depth.shape
    if not (0.0 <= row <= n_rows - 1.0 and 0.0 <= col <= n_cols - 1.0):
        return np.nan
    r0 = min(int(row), n_rows - 2)
    c0 = min(int(col), n_cols - 2)
    fr = row - r0
    fc = col - c0
    south = depth[r0, c0] + fc * (depth[r0, c0 + 1] - depth[r0, c0])
    north = depth[r0 + 1, c0] + fc * (depth[r0 + 1, c0 + 1] - depth[r0 + 1, c0])
    return float(south + fr * (north - south))


@numba.njit(cache=True, nogil=True)
def sample_depth(depth: FloatArray, rows: FloatArray, cols: FloatArray) -> FloatArray:
    """Bilinear depth at every fractional index of the flat arrays ``rows``, ``cols``."""
    out = np.empty(rows.size)
    for i in range(rows.size):
        out[i] = _bilinear(depth, rows[i], cols[i])
    return out


@numba.njit(cache=True, nogil=True)
def sample_gradient(depth: FloatArray, rows: FloatArray, cols: FloatArray) -> FloatArray:
    """Gradient ``(d/d row, d/d col)`` of the bilinear surface, shape ``(n, 2)``; NaN off-map.

    On a cell edge the cell to the north (east) is used, except on the last row (column).
    """
    n_rows, n_cols = depth.shape
    out = np.full((rows.size, 2), np.nan)
    for i in range(rows.size):
        row, col = rows[i], cols[i]
        if not (0.0 <= row <= n_rows - 1.0 and 0.0 <= col <= n_cols - 1.0):
            continue
        r0 = min(int(row), n_rows - 2)
        c0 = min(int(col), n_cols - 2)
        fr = row - r0
        fc = col - c0
        d00, d01 = depth[r0, c0], depth[r0, c0 + 1]
        d10, d11 = depth[r0 + 1, c0], depth[r0 + 1, c0 + 1]
        out[i, 0] = (1.0 - fc) * (d10 - d00) + fc * (d11 - d01)
        out[i, 1] = (1.0 - fr) * (d01 - d00) + fr * (d11 - d10)
    return out


@numba.njit(cache=True, nogil=True)
def particle_filter(
    depth: FloatArray,
    grid: FloatArray,
    initial: FloatArray,
    initial_sigma: float,
    increments: FloatArray,
    process_sigma: FloatArray,
    soundings: FloatArray,
    offsets: FloatArray,
    variances: FloatArray,
    n_particles: int,
    resample_below: float,
    roughening: float,
    rng: np.random.Generator,
    estimate: FloatArray,
    covariance: FloatArray,
    ess: FloatArray,
) -> tuple[int, int]:
    r"""Run the particle filter over ``K + 1`` updates; fill ``estimate``, ``covariance``, ``ess``.

    Parameters
    ----------
    depth : ndarray of shape (n_rows, n_cols)
        Map depth [m] (NaN: no data).
    grid : ndarray of shape (4,)
        ``origin_north, origin_east, spacing_north, spacing_east`` [m] of the map's nodes.
    initial : ndarray of shape (2,)
        Initial position estimate ``north, east`` [m].
    initial_sigma : float
        Standard deviation [m] per axis of the initial particle cloud around ``initial``.
    increments : ndarray of shape (K, 2)
        Measured (dead-reckoned) displacement ``north, east`` [m] into update ``k + 1``.
    process_sigma : ndarray of shape (K,)
        Process-noise standard deviation [m] per axis of each increment.
    soundings : ndarray of shape (K + 1, n_beams)
        Measured seabed depth [m] of each beam at each update; NaN: no sounding.
    offsets : ndarray of shape (K + 1, n_beams, 2)
        Beam footprint offset ``north, east`` [m] from the vehicle.
    variances : ndarray of shape (K + 1, n_beams)
        Likelihood variance [m²] of each sounding (map plus beam).
    n_particles : int
        Particle count ``N``.
    resample_below : float
        Resample when the effective sample size :math:`1 / \sum w_i^2` is below this count.
    roughening : float
        Roughening constant ``K_r``: after resampling each coordinate gets Gaussian jitter of
        standard deviation :math:`K_r E N^{-1/2}`, ``E`` the spread (max - min) of the
        particles along it (Gordon et al. 1993, Sec. 4, with ``d = 2``). The jitter is drawn
        with the next prediction's process noise, as one normal of the summed variance (the
        same distribution, half the draws; the moments are taken before resampling).
    rng : numpy.random.Generator
        The run's random stream.
    estimate, covariance, ess : ndarray
        Outputs of shapes ``(K + 1, 2)``, ``(K + 1, 3)`` (``P_nn, P_ee, P_ne`` [m²]) and
        ``(K + 1,)``: weighted mean and covariance of the particles after each measurement
        update (before resampling), and the effective sample size then.

    Returns
    -------
    n_resamples : int
        How many times the particles were resampled.
    n_skipped : int
        Updates whose soundings no particle could explain (every particle off the map or on
        no-data cells): their weights were left unchanged.
    """
    origin_n, origin_e = grid[0], grid[1]
    inv_n, inv_e = 1.0 / grid[2], 1.0 / grid[3]
    n_beams = soundings.shape[1]
    north = initial[0] + initial_sigma * rng.standard_normal(n_particles)
    east = initial[1] + initial_sigma * rng.standard_normal(n_particles)
    log_w = np.zeros(n_particles)  # log weights up to a constant; their maximum is `shift`
    prior = np.empty(n_particles)
    weight = np.empty(n_particles)
    spare_n = np.empty(n_particles)
    spare_e = np.empty(n_particles)
    jitter = roughening / np.sqrt(n_particles)
    sums = np.zeros(7)  # of the weighted moments (_add_moments)
    shift = 0.0
    rough_n = rough_e = 0.0
    n_resamples = 0
    n_skipped = 0
    for k in range(soundings.shape[0]):
        has_beam = False
        for b in range(n_beams):
            has_beam = has_beam or not np.isnan(soundings[k, b])
        step_n = step_e = sigma_n = sigma_e = 0.0
        if k > 0:
            step_n, step_e = increments[k - 1, 0], increments[k - 1, 1]
            sigma_n = np.sqrt(process_sigma[k - 1] ** 2 + rough_n**2)
            sigma_e = np.sqrt(process_sigma[k - 1] ** 2 + rough_e**2)
            rough_n = rough_e = 0.0
        # one fused pass: predict (with the last resampling's roughening), weigh, moments
        best = -np.inf
        ref_n = ref_e = 0.0
        sums[:] = 0.0
        for i in range(n_particles):
            if k > 0:
                north[i] += step_n + sigma_n * rng.standard_normal()
                east[i] += step_e + sigma_e * rng.standard_normal()
            if i == 0:
                ref_n, ref_e = north[0], east[0]
            prior[i] = log_w[i] - shift
            log_w[i] = prior[i]
            if has_beam:
                log_w[i] += _log_likelihood(
                    depth, north[i], east[i], soundings[k], offsets[k], variances[k],
                    origin_n, origin_e, inv_n, inv_e,
                )  # fmt: skip
            best = max(best, log_w[i])
            w = np.exp(log_w[i])
            weight[i] = w
            _add_moments(sums, w, north[i] - ref_n, east[i] - ref_e)
        if best == -np.inf:  # no particle can explain the soundings: leave them out
            n_skipped += 1
            log_w[:] = prior
            best = np.max(log_w)
            weight[:] = np.exp(log_w - best)
            s, s2, mean_n, mean_e, p_nn, p_ee, p_ne = _weighted_moments(weight, north, east)
        elif best < _UNDERFLOW_LOG_WEIGHT:  # rare: weigh relative to the best particle
            weight[:] = np.exp(log_w - best)
            s, s2, mean_n, mean_e, p_nn, p_ee, p_ne = _weighted_moments(weight, north, east)
        else:
            s, s2, mean_n, mean_e, p_nn, p_ee, p_ne = _moments(sums, ref_n, ref_e)
        shift = best
        estimate[k, 0], estimate[k, 1] = mean_n, mean_e
        covariance[k, 0], covariance[k, 1], covariance[k, 2] = p_nn, p_ee, p_ne
        ess[k] = s * s / s2
        if ess[k] < resample_below:
            _systematic_resample(weight, s, north, east, spare_n, spare_e, rng)
            north, spare_n = spare_n, north
            east, spare_e = spare_e, east
            rough_n = jitter * (np.max(north) - np.min(north))
            rough_e = jitter * (np.max(east) - np.min(east))
            log_w[:] = 0.0
            shift = 0.0
            n_resamples += 1
    return n_resamples, n_skipped


@numba.njit(cache=True, nogil=True, inline="always")
def _log_likelihood(
    depth: FloatArray,
    north: float,
    east: float,
    soundings: FloatArray,
    offsets: FloatArray,
    variances: FloatArray,
    origin_n: float,
    origin_e: float,
    inv_n: float,
    inv_e: float,
) -> float:
    """Gaussian log-likelihood of one ping's soundings at a particle; -inf if a beam is off-map."""
    total = 0.0
    for b in range(soundings.size):
        z = soundings[b]
        if np.isnan(z):
            continue
        h = _bilinear(
            depth,
            (north + offsets[b, 0] - origin_n) * inv_n,
            (east + offsets[b, 1] - origin_e) * inv_e,
        )
        if np.isnan(h):
            return -np.inf
        total -= 0.5 * (z - h) * (z - h) / variances[b]
    return total


@numba.njit(cache=True, nogil=True)
def _weighted_moments(
    weight: FloatArray, north: FloatArray, east: FloatArray
) -> tuple[float, float, float, float, float, float, float]:
    """Sum and sum of squares of the weights, weighted mean and covariance of the particles.

    Returns ``sum w, sum w², mean north, mean east, P_nn, P_ee, P_ne``; the sums run about
    particle 0, so that the covariance loses no digits to the mean's magnitude.
    """
    sums = np.zeros(7)
    for i in range(weight.size):
        _add_moments(sums, weight[i], north[i] - north[0], east[i] - east[0])
    return _moments(sums, north[0], east[0])


@numba.njit(cache=True, nogil=True, inline="always")
def _add_moments(sums: FloatArray, w: float, dn: float, de: float) -> None:
    """Add a particle of weight ``w`` at ``(dn, de)`` from the reference to the 7 ``sums``."""
    sums[0] += w
    sums[1] += w * w
    sums[2] += w * dn
    sums[3] += w * de
    sums[4] += w * dn * dn
    sums[5] += w * de * de
    sums[6] += w * dn * de


@numba.njit(cache=True, nogil=True, inline="always")
def _moments(
    sums: FloatArray, ref_n: float, ref_e: float
) -> tuple[float, float, float, float, float, float, float]:
    """``sum w, sum w², mean north, mean east, P_nn, P_ee, P_ne`` from the sums about ``ref``."""
    s = sums[0]
    m_n, m_e = sums[2] / s, sums[3] / s
    return (
        s,
        sums[1],
        ref_n + m_n,
        ref_e + m_e,
        max(sums[4] / s - m_n * m_n, 0.0),
        max(sums[5] / s - m_e * m_e, 0.0),
        sums[6] / s - m_n * m_e,
    )


@numba.njit(cache=True, nogil=True)
def _systematic_resample(
    weight: FloatArray,
    total: float,
    north: FloatArray,
    east: FloatArray,
    out_n: FloatArray,
    out_e: FloatArray,
    rng: np.random.Generator,
) -> None:
    """Systematic (low-variance) resampling: one uniform offset, ``N`` evenly spaced pointers.

    Particle ``i`` is copied ``floor`` or ``ceil`` of ``N w_i / total`` times (Thrun, Burgard
    and Fox, Probabilistic Robotics, 2005, Table 4.4).
    """
    n = weight.size
    step = total / n
    pointer = rng.random() * step
    cumulative = weight[0]
    j = 0
    for i in range(n):
        while cumulative < pointer and j < n - 1:
            j += 1
            cumulative += weight[j]
        out_n[i] = north[j]
        out_e[i] = east[j]
        pointer += step
