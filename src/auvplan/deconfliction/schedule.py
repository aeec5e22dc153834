r"""Timed schedules: positions, headings and the continuous separation certificate.

A schedule is a common time grid ``t_m`` and per vehicle its arc-length progress
``s_i(t_m)``; in between, each vehicle moves linearly in arc length. During the step
``[t_m, t_{m+1}]`` vehicle ``i`` covers the arc ``Δs_i`` and so stays within ``Δs_i`` (a chord
is never longer than its arc) of both end positions. Hence for every ``t`` in the step

.. math::

    \lVert p_i(t) - p_j(t) \rVert \ge \max\bigl(d_m - (Δs_i + Δs_j)\,\tau,\;
    d_{m+1} - (Δs_i + Δs_j)(1 - \tau)\bigr)
    \ge \tfrac12 \bigl(d_m + d_{m+1} - Δs_i - Δs_j\bigr),

with ``τ`` the fraction of the step elapsed. The minimum of this bound over pairs and steps
is the *certified* separation: a lower bound on the true continuous minimum.
"""

from __future__ import annotations

import numpy as np

from auvplan._typing import FloatArray
from auvplan.deconfliction.problem import CoordinationProblem, headings_along, positions_along
from auvplan.deconfliction.result import CoordinationResult, SeparationCertificate
from auvplan.errors import InputError

#: Relative tolerance [-] on the path length when deciding that a vehicle has arrived.
ARRIVAL_TOLERANCE = 1e-9


def _check_schedule(problem: CoordinationProblem, time: FloatArray, progress: FloatArray) -> None:
    n_t = time.shape[0]
    if time.ndim != 1 or n_t < 1:
        raise InputError(f"time must have shape (n_t >= 1,), got {time.shape}")
    if progress.shape != (problem.n_vehicles, n_t):
        raise InputError(
            f"progress must have shape ({problem.n_vehicles}, {n_t}), got {progress.shape}"
        )
    if n_t > 1 and np.any(np.diff(time) <= 0.0):
        raise InputError("time must be strictly increasing")


def pair_bound(
    pos_i: FloatArray, pos_j: FloatArray, moved_i: FloatArray, moved_j: FloatArray
) -> tuple[float, int, float, float]:
    """Certified bound, its step, fraction of the step, and the sampled minimum of one pair.

    ``pos_*`` are the positions ``(n_t, 2)`` [m] at the samples, ``moved_*`` the arc lengths
    ``(n_t - 1,)`` [m] covered monotonically during each step (module notes).
    """
    distance = np.hypot(pos_i[:, 0] - pos_j[:, 0], pos_i[:, 1] - pos_j[:, 1])
    sampled = float(distance.min())
    if distance.shape[0] == 1:
        return sampled, 0, 0.0, sampled
    motion = moved_i + moved_j
    bound = 0.5 * (distance[:-1] + distance[1:] - motion)
    bound = np.minimum(bound, np.minimum(distance[:-1], distance[1:]))
    step = int(np.argmin(bound))
    fraction = 0.0
    if motion[step] > 0.0:
        fraction = float(
            np.clip((distance[step] - distance[step + 1] + motion[step]) / (2 * motion[step]), 0, 1)
        )
    return float(bound[step]), step, fraction, sampled


def certify_separation(
    problem: CoordinationProblem, time: FloatArray, progress: FloatArray
) -> SeparationCertificate:
    """Certified minimum pairwise distance of a schedule over continuous time.

    Parameters
    ----------
    problem : CoordinationProblem
        Paths and required separation.
    time : ndarray of shape (n_t,)
        Strictly increasing sample times [s].
    progress : ndarray of shape (n_vehicles, n_t)
        Arc length [m] of each vehicle at each sample; linear in between.

    Returns
    -------
    SeparationCertificate
        ``min_separation = min_{i<j, m} (d_m + d_{m+1} - Δs_i - Δs_j) / 2`` (module notes),
        a lower bound on ``min_t ||p_i(t) - p_j(t)||``.

    Examples
    --------
    >>> problem = CoordinationProblem(
    ...     (np.array([[0.0, 0.0], [0.0, 10.0]]), np.array([[5.0, 0.0], [5.0, 10.0]])),
    ...     safety_radius=1.0, cruise_speeds=np.ones(2), time_step=1.0)
    >>> time = np.arange(11.0)
    >>> cert = certify_separation(problem, time, np.vstack([time, time]))
    >>> cert.min_sampled_separation  # side by side, 5 m apart at every sample
    5.0
    >>> cert.min_separation  # the bound subtracts the 1 m + 1 m moved within a step, halved
    4.0
    """
    time = np.asarray(time, dtype=np.float64)
    progress = np.asarray(progress, dtype=np.float64)
    _check_schedule(problem, time, progress)
    n = problem.n_vehicles
    positions = [
        positions_along(problem.paths[i], problem.arc_lengths[i], progress[i]) for i in range(n)
    ]
    moved = [np.abs(np.diff(progress[i])) for i in range(n)]
    best = (np.inf, (-1, -1), 0.0)
    best_sampled = np.inf
    for i in range(n):
        for j in range(i + 1, n):
            bound, step, fraction, sampled = pair_bound(
                positions[i], positions[j], moved[i], moved[j]
            )
            best_sampled = min(best_sampled, sampled)
            if bound < best[0]:
                t = time[step] + fraction * (time[step + 1] - time[step]) if time.size > 1 else 0.0
                best = (bound, (i, j), float(t))
    return SeparationCertificate(
        min_separation=float(best[0]),
        pair=best[1],
        time=best[2],
        min_sampled_separation=float(best_sampled),
        required=problem.separation,
    )


def arrival_times_of(
    problem: CoordinationProblem, time: FloatArray, progress: FloatArray
) -> FloatArray:
    """First sample time [s] at which each vehicle reaches its path's end, shape (n_vehicles,)."""
    reached = progress >= (problem.path_lengths * (1.0 - ARRIVAL_TOLERANCE))[:, None]
    if not np.all(reached[:, -1]):
        late = int(np.argmin(reached[:, -1]))
        raise InputError(f"vehicle {late} does not reach the end of its path by t = {time[-1]} s")
    return np.asarray(time[np.argmax(reached, axis=1)], dtype=np.float64)


def progress_at(result: CoordinationResult, vehicle: int, times: FloatArray) -> FloatArray:
    r"""Arc length [m] of ``vehicle`` at ``times`` [s] (clamped to the schedule's span).

    Linear between samples, or, where ``result.speeds`` gives the vehicle's speeds,
    quadratic: :math:`s = s_m + v_m \tau + (v_{m+1} - v_m) \tau^2 / (2 \Delta t_m)`,
    :math:`\tau = t - t_m` (continuous speed, constant acceleration per step).
    """
    time = result.time
    t = np.clip(np.asarray(times, dtype=np.float64), time[0], time[-1])
    s = result.progress[vehicle]
    if result.speeds is None or np.isnan(result.speeds[vehicle, 0]) or time.shape[0] == 1:
        return np.asarray(np.interp(t, time, s), dtype=np.float64)
    v = result.speeds[vehicle]
    m = np.clip(np.searchsorted(time, t, side="right") - 1, 0, time.shape[0] - 2)
    tau = t - time[m]
    step = time[m + 1] - time[m]
    return np.asarray(
        np.minimum(s[m] + v[m] * tau + (v[m + 1] - v[m]) * tau**2 / (2.0 * step), s[m + 1]),
        dtype=np.float64,
    )


def timed_positions(
    result: CoordinationResult, problem: CoordinationProblem, times: FloatArray
) -> FloatArray:
    """Positions ``[north, east]`` [m] of every vehicle at ``times`` [s].

    Returns
    -------
    ndarray of shape (n_vehicles, n_t, 2)
        Times before 0 or after the last sample are clamped (vehicles wait at start / goal).

    Examples
    --------
    >>> from auvplan.deconfliction import deconflict
    >>> problem = CoordinationProblem(
    ...     (np.array([[-5.0, 0.0], [5.0, 0.0]]), np.array([[0.0, -5.0], [0.0, 5.0]])),
    ...     safety_radius=1.0, cruise_speeds=np.ones(2), time_step=0.5)
    >>> result = deconflict(problem, method="prioritized")
    >>> timed_positions(result, problem, np.array([0.0, result.time[-1]])).tolist()
    [[[-5.0, 0.0], [5.0, 0.0]], [[0.0, -5.0], [0.0, 5.0]]]
    """
    return np.stack(
        [
            positions_along(problem.paths[i], problem.arc_lengths[i], progress_at(result, i, times))
            for i in range(problem.n_vehicles)
        ]
    )


def timed_headings(
    result: CoordinationResult, problem: CoordinationProblem, times: FloatArray
) -> FloatArray:
    """Heading ``psi`` [rad] of every vehicle at ``times`` from its path tangent.

    Clockwise from north, unwrapped along each path (see
    :func:`auvplan.deconfliction.problem.headings_along`); a waiting vehicle keeps the
    heading of its path at that point.

    Returns
    -------
    ndarray of shape (n_vehicles, n_t)
    """
    return np.stack(
        [
            headings_along(problem.paths[i], problem.arc_lengths[i], progress_at(result, i, times))
            for i in range(problem.n_vehicles)
        ]
    )
