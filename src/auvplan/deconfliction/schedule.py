r"""Timed schedules: positions, headings, the continuous separation certificate, retiming.

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

import dataclasses
import logging

import numpy as np

from auvplan._typing import FloatArray
from auvplan.deconfliction.problem import CoordinationProblem, headings_along, positions_along
from auvplan.deconfliction.result import CoordinationResult, SeparationCertificate
from auvplan.errors import InfeasibleError, InputError

logger = logging.getLogger(__name__)

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


def _pair_bound(
    pos_i: FloatArray, pos_j: FloatArray, moved_i: FloatArray, moved_j: FloatArray
) -> tuple[float, int, float, float]:
    """Certified bound, its step, fraction of the step, and the sampled minimum of one pair."""
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
            bound, step, fraction, sampled = _pair_bound(
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
    times = np.asarray(times, dtype=np.float64)
    return np.stack(
        [
            positions_along(
                problem.paths[i],
                problem.arc_lengths[i],
                np.interp(times, result.time, result.progress[i]),
            )
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
    times = np.asarray(times, dtype=np.float64)
    return np.stack(
        [
            headings_along(
                problem.paths[i],
                problem.arc_lengths[i],
                np.interp(times, result.time, result.progress[i]),
            )
            for i in range(problem.n_vehicles)
        ]
    )


def _tail_candidates(arrival_index: int) -> list[float]:
    """Sample (possibly fractional) where a vehicle's slow-down may begin, smoothest first."""
    a = float(arrival_index)
    candidates = [0.0]
    fraction = 0.5
    while a * fraction >= 1.0 and len(candidates) < 6:
        candidates.append(a * (1.0 - fraction))
        fraction *= 0.5
    candidates += [a - 1.0, a - 0.25]
    return [b for b in candidates if 0.0 <= b < a]


def retime_for_arrival(
    result: CoordinationResult, problem: CoordinationProblem, final_time: float
) -> CoordinationResult:
    r"""Stretch a collision-free schedule so that every vehicle arrives at ``final_time``.

    1. **Common time law.** The whole coordination-space path is replayed at the pace
       ``makespan / final_time``: ``t' = t · final_time / makespan``. Every configuration, and
       therefore the certified separation, is unchanged; every speed scales by
       ``makespan / final_time <= 1``.
    2. **No early arrivals.** A vehicle that reached its goal at sample ``a < M`` (it would
       then wait there) is slowed down instead: from a sample ``b < a`` on, its old progress on
       ``[b, a]`` is spread over ``[b, M]``. The earliest ``b`` (the gentlest slow-down)
       whose schedule still passes the continuous certificate against all other vehicles is
       taken; the last candidate moves the vehicle by at most a quarter grid step in the
       stretched tail, which the grid's collision inflation ``(h_i + h_j)/2`` always allows
       for schedules produced by :func:`auvplan.deconfliction.deconflict`. If no candidate
       passes (only possible for schedules from elsewhere), the vehicle keeps waiting at its
       goal and the message says so.

    Guarantees: the paths are unchanged; speeds never exceed the input schedule's; the
    returned certificate is recomputed and is at least ``2 r_c`` whenever the input's was.

    Parameters
    ----------
    result : CoordinationResult
        A schedule for ``problem``.
    problem : CoordinationProblem
        The paths.
    final_time : float
        Common arrival time [s], ``>=`` the schedule's makespan.

    Returns
    -------
    CoordinationResult
        Same status and search counters; new ``time`` (``M + 1`` samples, uniform on
        ``[0, final_time]``), ``progress``, ``arrival_times``, ``delays`` and certificate.

    Raises
    ------
    InputError
        If ``final_time`` is below the makespan or not finite.
    """
    makespan = float(result.time[-1])
    if not (np.isfinite(final_time) and final_time >= makespan * (1.0 - 1e-12)):
        raise InputError(
            f"final_time must be finite and >= the makespan {makespan:.6g} s, got {final_time}"
        )
    n_samples = result.time.shape[0]
    if n_samples == 1:
        raise InputError("cannot retime a schedule with a single sample")
    time = result.time * (final_time / makespan)
    progress = result.progress.copy()
    last = n_samples - 1
    samples = np.arange(n_samples, dtype=np.float64)
    n = problem.n_vehicles
    positions = [
        positions_along(problem.paths[i], problem.arc_lengths[i], progress[i]) for i in range(n)
    ]
    early: list[int] = []
    lengths = problem.path_lengths * (1.0 - ARRIVAL_TOLERANCE)
    for i in range(n):
        arrival_index = int(np.argmax(progress[i] >= lengths[i]))
        if arrival_index >= last:
            continue
        accepted = False
        for b in _tail_candidates(arrival_index):
            first = int(np.floor(b))
            tail = samples[first:]
            old = np.interp(
                b + (tail - b) * (arrival_index - b) / (last - b), samples, result.progress[i]
            )
            old[0] = progress[i, first]
            trial_progress = progress[i].copy()
            trial_progress[first:] = old
            trial_progress[-1] = problem.path_lengths[i]
            start = max(first - 1, 0)
            trial_pos = positions_along(
                problem.paths[i], problem.arc_lengths[i], trial_progress[start:]
            )
            moved_i = np.abs(np.diff(trial_progress[start:]))
            ok = True
            for j in range(n):
                if j == i:
                    continue
                bound, _, _, _ = _pair_bound(
                    trial_pos, positions[j][start:], moved_i, np.abs(np.diff(progress[j, start:]))
                )
                if bound < problem.separation - 1e-9:
                    ok = False
                    break
            if ok:
                progress[i] = trial_progress
                positions[i] = positions_along(
                    problem.paths[i], problem.arc_lengths[i], trial_progress
                )
                accepted = True
                break
        if not accepted:
            early.append(i)
    certificate = certify_separation(problem, time, progress)
    arrivals = arrival_times_of(problem, time, progress)
    message = f"{result.message}; retimed to arrive at {final_time:.6g} s"
    if early:
        message += f" (vehicles {early} arrive early and wait at their goals)"
        logger.warning("retime_for_arrival: vehicles %s could not be slowed down safely", early)
    if not certificate.holds:
        i, j = certificate.pair
        raise InfeasibleError(
            f"retiming vehicles {problem.label(i)} and {problem.label(j)} to arrive at "
            f"{final_time:.6g} s is not certified ({certificate.min_separation:.4g} m < "
            f"2 r_c = {problem.separation:g} m at t = {certificate.time:.6g} s)"
        )
    delays = arrivals - problem.nominal_arrival_times
    return dataclasses.replace(
        result,
        message=message,
        time=time,
        progress=progress,
        arrival_times=arrivals,
        delays=delays,
        certificate=certificate,
        objective=(float(arrivals.max()), float(delays.sum())),
    )
