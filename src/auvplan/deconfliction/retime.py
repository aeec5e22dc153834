r"""Flyable time laws: retime a collision-free schedule to a common arrival time.

A grid schedule waits by stopping dead and moves at its cruise speed otherwise: its speed jumps
between 0 and ``v_i``. :func:`retime_for_arrival` turns it into time laws a vehicle can fly:

1. **Common clock.** The schedule is replayed at the pace ``makespan / T`` (every
   configuration, hence the certificate, is unchanged; the grid's speed ``v_i`` becomes
   :math:`\bar v_i = v_i \cdot makespan / T`).
2. **Corridor.** Vehicle by vehicle, with the others' laws fixed, the arc lengths that keep
   it at least :math:`R_{ij} = 2 r_c + (\bar v_i + \bar v_j) \Delta t / 2` from every other
   vehicle at each sample :math:`t_m` form an interval :math:`[\ell_m, u_m]` around its
   replayed progress (the free stretch of its path around where the schedule has it).
   Any law inside the corridor that moves at most :math:`\bar v \Delta t` per sample keeps
   the certified separation :math:`\ge 2 r_c`: the certificate's bound
   :math:`(d_m + d_{m+1} - \Delta s_i - \Delta s_j)/2 \ge R_{ij} - (\bar v_i + \bar v_j)
   \Delta t / 2` (:mod:`auvplan.deconfliction.schedule`).
3. **Smoothest law in the corridor** (a linear programme): speeds :math:`v_m` at the samples,
   progress by the trapezoidal rule :math:`s_{m+1} = s_m + \Delta t (v_m + v_{m+1}) / 2`
   (so :math:`s'` is continuous and piecewise linear, :math:`s''` piecewise constant),

   .. math::

       \min \sum_m |v_{m+1} - v_m| + \lambda \Delta t \sum_m (v_{min} - v_m)^+
            + \mu \sum_m e_m
       \quad \text{s.t.} \quad \ell_m \le s_m \le u_m,\; s_0 = 0,\; s_M = L_i,\;
       0 \le v_m \le \bar v_i,\; |v_{m+1} - v_m| \le a_{max} \Delta t + e_m .

   The total variation of the speed is smallest for the taut law through the corridor, so a
   stop becomes a slow-down wherever the corridor allows one; speeds below the minimum
   useful speed :math:`v_{min}` are penalised (:math:`\lambda`), and the acceleration bound is
   kept wherever it can be (:math:`e_m` are its violations, :math:`\mu \gg 1`). Where a
   vehicle must hold still the law keeps the stop, ramping in and out of it.
4. **Certificate.** Each vehicle's new law is re-certified against all the others; should it
   fail (a sample where the replayed schedule itself is closer than :math:`R_{ij}`, possible
   after coarsening), the vehicle keeps its replayed law.
5. **Fallback.** Should the laws together fail the certificate on their grid (uniform, at most
   :data:`MAX_SAMPLES` samples: coarser than the schedule's), the schedule itself is replayed
   at the common pace on its own grid (certified, stops included). This is a degradation
   the run reports: the result's message says it (``summary.json``:
   ``deconfliction.message``).
"""

from __future__ import annotations

import dataclasses
import logging
from typing import Final

import numpy as np
from scipy import optimize, sparse

from auvplan._typing import FloatArray
from auvplan.deconfliction._conflict_kernels import pair_intervals
from auvplan.deconfliction.problem import CoordinationProblem, positions_along
from auvplan.deconfliction.result import CoordinationResult
from auvplan.deconfliction.schedule import (
    ARRIVAL_TOLERANCE,
    arrival_times_of,
    certify_separation,
    pair_bound,
)
from auvplan.errors import InfeasibleError, InputError

logger = logging.getLogger(__name__)

#: Weight :math:`\lambda` [1/s] of the time spent below the minimum speed, against the total
#: variation of the speed (a dip of depth δ lasting 2 s costs as much as a speed change of 2 δ).
MIN_SPEED_WEIGHT: Final = 1.0
#: Weight :math:`\mu` of violations of the acceleration bound [per m/s].
ACCELERATION_WEIGHT: Final = 1e3
#: Corridor resolution: arc-length step of the forbidden-set search, as a fraction of R.
CORRIDOR_RESOLUTION: Final = 1.0 / 64.0
#: Largest number of samples of the retimed laws (longer schedules are resampled).
MAX_SAMPLES: Final = 4000


def retime_for_arrival(
    result: CoordinationResult, problem: CoordinationProblem, final_time: float
) -> CoordinationResult:
    """Smooth, flyable time laws along the same paths, every vehicle arriving at ``final_time``.

    Parameters
    ----------
    result : CoordinationResult
        A certified schedule for ``problem``.
    problem : CoordinationProblem
        The paths, cruise speeds (the speed bound), and the optional minimum speeds and
        acceleration bounds of the vehicles.
    final_time : float
        Common arrival time [s], ``>=`` the schedule's makespan.

    Returns
    -------
    CoordinationResult
        Same status, method and search counters; ``time`` uniform on ``[0, final_time]``
        (the input's samples, at most :data:`MAX_SAMPLES`), ``progress`` and ``speeds`` (the
        law is quadratic between samples, module notes), ``arrival_times`` (all
        ``final_time``), ``delays``, the recomputed certificate, and ``within_limits``: per
        vehicle, whether its law keeps the acceleration bound everywhere. ``message`` names
        the vehicles that keep their replayed law and says when the schedule is replayed
        (module notes, steps 4 and 5).

    Raises
    ------
    InputError
        If ``final_time`` is below the makespan or not finite, or the schedule has a single
        sample.
    InfeasibleError
        If the retimed schedule is not certified (only possible for hand-made input
        schedules; names the pair).

    Examples
    --------
    >>> from auvplan.deconfliction import deconflict
    >>> problem = CoordinationProblem(
    ...     (np.array([[-10.0, 0.0], [10.0, 0.0]]), np.array([[0.0, -10.0], [0.0, 10.0]])),
    ...     safety_radius=1.0, cruise_speeds=np.ones(2), time_step=0.5,
    ...     max_accelerations=np.full(2, 0.5))
    >>> result = retime_for_arrival(deconflict(problem), problem, 30.0)
    >>> result.arrival_times.tolist(), result.within_limits, result.min_separation >= 2.0
    ([30.0, 30.0], (True, True), True)
    """
    makespan = float(result.time[-1])
    if not (np.isfinite(final_time) and final_time >= makespan * (1.0 - 1e-12)):
        raise InputError(
            f"final_time must be finite and >= the makespan {makespan:.6g} s, got {final_time}"
        )
    if result.time.shape[0] == 1:
        raise InputError("cannot retime a schedule with a single sample")
    n_samples = min(result.time.shape[0], MAX_SAMPLES + 1)
    time = np.linspace(0.0, final_time, n_samples)
    replay = time * (makespan / final_time)
    progress = np.stack([np.interp(replay, result.time, s) for s in result.progress])
    progress[:, -1] = problem.path_lengths
    pace = problem.cruise_speeds * makespan / final_time
    speeds = np.full_like(progress, np.nan)
    within = [False] * problem.n_vehicles
    for i in np.argsort(-result.delays, kind="stable"):  # the longest waits first
        law = _smooth_law(problem, int(i), time, progress, pace)
        if law is None:  # (the result's message names it)
            logger.debug("retime: vehicle %s keeps its replayed law", problem.label(int(i)))
            progress[i] = _late_arrival(problem, int(i), progress)
            continue
        progress[i], speeds[i], within[i] = law
    certificate = certify_separation(problem, time, progress)
    fallback = ""
    if not certificate.holds:
        # the resampled corridor missed a close pass: replay the schedule itself on its own
        # grid at the common pace, which keeps its configurations and hence its certificate
        i, j = certificate.pair
        fallback = (
            f"the smooth laws of {problem.label(i)} and {problem.label(j)} were not certified "
            f"on the resampled grid ({certificate.min_separation:.3g} m): the schedule is "
            "replayed at a common pace, stops included"
        )
        logger.debug("retime: %s", fallback)  # (a degradation: the result's message says it)
        time = result.time * (final_time / makespan)
        progress = np.array(result.progress, dtype=np.float64)
        speeds = np.full_like(progress, np.nan)
        within = [False] * problem.n_vehicles
        certificate = certify_separation(problem, time, progress)
    if not certificate.holds:
        i, j = certificate.pair
        raise InfeasibleError(
            f"retiming vehicles {problem.label(i)} and {problem.label(j)} to arrive at "
            f"{final_time:.6g} s is not certified ({certificate.min_separation:.4g} m < "
            f"2 r_c = {problem.separation:g} m at t = {certificate.time:.6g} s)"
        )
    arrivals = arrival_times_of(problem, time, progress)
    delays = arrivals - problem.nominal_arrival_times
    message = f"{result.message}; retimed to arrive at {final_time:.6g} s"
    if fallback:
        message += f" ({fallback})"
    kept = [problem.label(i) for i in range(problem.n_vehicles) if np.isnan(speeds[i, 0])]
    if kept:
        message += f" (vehicles {kept} keep their replayed law and may arrive early)"
    if not all(within):
        names = [problem.label(i) for i in range(problem.n_vehicles) if not within[i]]
        message += f" (vehicles {names} exceed their acceleration bound somewhere)"
    return dataclasses.replace(
        result,
        message=message,
        time=time,
        progress=progress,
        arrival_times=arrivals,
        delays=delays,
        certificate=certificate,
        objective=(float(arrivals.max()), float(delays.sum())),
        speeds=speeds,
        within_limits=tuple(within),
    )


def _late_arrival(problem: CoordinationProblem, i: int, progress: FloatArray) -> FloatArray:
    """The replayed law with its last step spread to the end, when that stays certified.

    A vehicle that would reach its goal at sample ``a < M`` and wait there covers its last
    step ``[a - 1, a]`` over ``[a - 1, M]`` instead (slower, so within the grid's margin).
    """
    s: FloatArray = progress[i]
    arrival = int(np.argmax(s >= problem.path_lengths[i] * (1.0 - ARRIVAL_TOLERANCE)))
    last = s.shape[0] - 1
    if arrival == last or arrival == 0:
        return s
    trial: FloatArray = s.copy()
    trial[arrival - 1 :] = np.linspace(s[arrival - 1], s[arrival], last - arrival + 2)
    if _clears_others(problem, i, trial, progress):
        return trial
    return s


def _clears_others(
    problem: CoordinationProblem, i: int, law: FloatArray, progress: FloatArray
) -> bool:
    """Whether vehicle ``i`` on ``law`` keeps the certified ``2 r_c`` from every other."""
    positions = positions_along(problem.paths[i], problem.arc_lengths[i], law)
    moved = np.abs(np.diff(law))
    for j in range(problem.n_vehicles):
        if j == i:
            continue
        other = positions_along(problem.paths[j], problem.arc_lengths[j], progress[j])
        bound, *_ = pair_bound(positions, other, moved, np.abs(np.diff(progress[j])))
        if bound < problem.separation - 1e-9:
            return False
    return True


def _smooth_law(
    problem: CoordinationProblem, i: int, time: FloatArray, progress: FloatArray, pace: FloatArray
) -> tuple[FloatArray, FloatArray, bool] | None:
    """Vehicle ``i``'s smoothest certified law in its corridor: ``(s, v, bound kept)``."""
    lower, upper = _corridor(problem, i, time, progress, pace)
    law = _taut_law(problem, i, time[1] - time[0], lower, upper, float(pace[i]))
    if law is None:
        return None
    return law if _clears_others(problem, i, law[0], progress) else None


def _corridor(
    problem: CoordinationProblem, i: int, time: FloatArray, progress: FloatArray, pace: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Free arc lengths ``[lower, upper]`` [m] around vehicle ``i``'s law at every sample."""
    dt = float(time[1] - time[0])
    length = float(problem.path_lengths[i])
    lower = np.zeros(time.shape[0])
    upper = np.full(time.shape[0], length)  # the forbidden intervals' ends are clipped below
    for j in range(problem.n_vehicles):
        if j == i:
            continue
        radius = (problem.separation + 0.5 * (pace[i] + pace[j]) * dt) * (1.0 + 1e-9)
        step = CORRIDOR_RESOLUTION * radius
        n_grid = int(np.ceil(length / step))
        others = positions_along(problem.paths[j], problem.arc_lengths[j], progress[j])
        row_ptr, lo, hi = pair_intervals(
            others, problem.paths[i], problem.arc_lengths[i], step, n_grid, radius
        )
        # forbidden index intervals per sample: those behind the law raise the lower edge and
        # those ahead lower the upper edge (the continuous forbidden set ends within one
        # index of them, so the edges never pass the law); one holding the law pins it
        sample = np.repeat(np.arange(time.shape[0]), np.diff(row_ptr[:-1]))
        here = progress[i, sample]
        behind = hi * step < here
        ahead = lo * step > here
        holding = ~(behind | ahead)
        np.maximum.at(lower, sample[behind], np.minimum((hi[behind] + 1) * step, here[behind]))
        np.minimum.at(upper, sample[ahead], np.maximum((lo[ahead] - 1) * step, here[ahead]))
        lower[sample[holding]] = upper[sample[holding]] = here[holding]
    return lower, upper


def _taut_law(
    problem: CoordinationProblem,
    i: int,
    dt: float,
    lower: FloatArray,
    upper: FloatArray,
    top: float,
) -> tuple[FloatArray, FloatArray, bool] | None:
    r"""The linear programme of the module notes; None when it has no solution.

    Variables, in order: ``s`` (M + 1), ``v`` (M + 1), ``p, q`` (M each; ``v_{m+1} - v_m =
    p_m - q_m``), ``w`` (M + 1; shortfall below the minimum speed), ``e`` (M; excess over the
    acceleration bound).
    """
    n = lower.shape[0]
    m = n - 1
    length = float(problem.path_lengths[i])
    shift = sparse.eye(m, n, k=1) - sparse.eye(m, n)  # x_{k+1} - x_k
    mean = 0.5 * (sparse.eye(m, n, k=1) + sparse.eye(m, n))
    # rows: trapezoidal progress, then the speed changes; zero blocks fix the column widths
    equality = sparse.bmat(
        [
            [shift, -dt * mean, None, None, sparse.csr_matrix((m, n)), sparse.csr_matrix((m, m))],
            [None, shift, -sparse.eye(m), sparse.eye(m), None, None],  # v_{k+1} - v_k = p - q
        ],
        format="csr",
    )
    inequality = sparse.bmat(
        [
            [None, -sparse.eye(n), None, None, -sparse.eye(n), None],  # v + w >= v_min
            [None, None, sparse.eye(m), None, None, -sparse.eye(m)],  # p <= a dt + e
            [sparse.csr_matrix((m, n)), None, None, sparse.eye(m), None, -sparse.eye(m)],
        ],
        format="csr",
    )
    floors, bounds_a = problem.min_speeds, problem.max_accelerations
    assert floors is not None
    assert bounds_a is not None
    # |v_{k+1} - v_k| <= top always, so an infinite bound never binds
    accel = min(float(bounds_a[i]) * dt, top)
    rhs = np.concatenate(
        [np.full(n, -min(float(floors[i]), top)), np.full(m, accel), np.full(m, accel)]
    )
    s_upper = upper.copy()
    s_upper[:-1] = np.minimum(s_upper[:-1], length * (1.0 - 1e-6))  # arrive at the end only
    bounds = np.concatenate(
        [
            np.column_stack([lower, s_upper]),
            np.column_stack([np.zeros(n), np.full(n, top)]),
            np.column_stack([np.zeros(2 * m + n + m), np.full(2 * m + n + m, np.inf)]),
        ]
    )
    bounds[0] = (0.0, 0.0)
    bounds[m] = (length, length)
    cost = np.concatenate(
        [
            np.zeros(2 * n),
            np.ones(2 * m),
            np.full(n, MIN_SPEED_WEIGHT * dt),
            np.full(m, ACCELERATION_WEIGHT),
        ]
    )
    solution = optimize.linprog(
        cost,
        A_ub=inequality,
        b_ub=rhs,
        A_eq=equality,
        b_eq=np.zeros(2 * m),
        bounds=bounds,
        method="highs",
    )
    if solution.status != 0:
        return None
    v = np.clip(solution.x[n : 2 * n], 0.0, top)
    s = np.concatenate(([0.0], np.cumsum(0.5 * dt * (v[:-1] + v[1:]))))
    if abs(s[-1] - length) > 1e-6 * max(length, 1.0):
        return None
    s[-1] = length
    s = np.minimum(np.maximum.accumulate(s), length)
    within = bool(np.all(np.abs(np.diff(v)) <= accel * (1.0 + 1e-6) + 1e-12))
    return s, v, within
