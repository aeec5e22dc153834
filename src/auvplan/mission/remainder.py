r"""The rest of a deconflicted schedule from a replanning time, led in from new starts.

A plan of horizon ``T`` replanned at time ``a`` keeps its stage-2 schedule when that schedule,
shifted by ``a``, is still certified collision-free from where the vehicles now are. Vehicle
``i``, which the old schedule has at ``p_i(t)`` (arc length ``s_i(t)`` [m] along its path
``P_i``), now stands ``d_i = p_{new,i} - p_{plan,i}(a)`` [m] off where its optimised plan had
it (zero for a vehicle whose state is not given). It is taken to fly the old schedule with
that offset fading out over ``τ_i``,

.. math::

    q_i(t) = p_i(a + t) + d_i\, φ(t / τ_i), \qquad
    φ(s) = \tfrac12 \bigl(1 + \cos(π \min(s, 1))\bigr), \qquad 0 \le t \le T - a,

so that it leaves its new start along the old path's direction and from ``t = τ_i`` on is
where the old schedule had it at ``a + t``. The fade-out needs at most ``π ‖d_i‖ / (2 τ_i)``
on top of the old speed: ``τ_i = min(π ‖d_i‖ / (2 v_spare,i), T - a)`` with ``v_spare,i =
max(v_max,i - max ṡ_i, 0.1 v_max,i)`` (``v_max,i`` the speed limit of stage 2). As a
schedule (:class:`~auvplan.deconfliction.CoordinationProblem`): the remainder path ``R_i`` is
the polyline through ``q_i`` at the old grid's times up to ``τ_i``, then the old path beyond
``s_i(a + τ_i)``; the progress is the arc length along it (linear in arc length between
samples, which the separation certificate assumes). With ``d = 0`` it is the old schedule
itself. :func:`shift_schedule` returns it with its continuous separation
certificate (:func:`auvplan.deconfliction.certify_separation`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from auvplan._typing import FloatArray
from auvplan.deconfliction import (
    CoordinationProblem,
    CoordinationResult,
    arrival_times_of,
    certify_separation,
    positions_along,
)
from auvplan.deconfliction.schedule import progress_at


@dataclass(frozen=True)
class Remainder:
    """The old schedule from the replanning time, led in from the new starts (module notes).

    ``problem`` holds the remainder paths ``R_i``, ``schedule`` the progress along them and
    its certificate (``schedule.success``: still collision-free), ``deviations``
    ``(n_vehicles, 2)`` the offsets ``d_i`` [m] and ``fade_times`` ``(n_vehicles,)`` the
    ``τ_i`` [s] over which they fade out.
    """

    problem: CoordinationProblem
    schedule: CoordinationResult
    deviations: FloatArray
    fade_times: FloatArray


def fade_factors(time: FloatArray, fade_times: FloatArray) -> FloatArray:
    """``φ(t / τ_i)`` (module notes) at ``time`` [s], shape ``(n_vehicles, n_t)``.

    0 where ``τ_i = 0`` (no offset to fade out).
    """
    ratio = np.divide(
        time[None, :], fade_times[:, None], out=np.ones((fade_times.size, time.size)),
        where=fade_times[:, None] > 0.0,
    )  # fmt: skip
    return np.asarray(0.5 * (1.0 + np.cos(np.pi * np.minimum(ratio, 1.0))), dtype=np.float64)


#: Smallest spare speed for the fade-out, as a fraction of the speed limit [-] (module notes).
MIN_SPARE_FRACTION = 0.1


def shift_schedule(
    problem: CoordinationProblem,
    coordination: CoordinationResult,
    *,
    at: float,
    horizon: float,
    deviations: FloatArray,
    speed_limits: FloatArray,
) -> Remainder:
    """The remainder paths and the shifted time laws from ``at`` (module notes).

    Parameters
    ----------
    problem, coordination : CoordinationProblem, CoordinationResult
        The old plan's paths and schedule (stage 2).
    at : float
        The replanning time ``a`` [s], ``0 < a < horizon``.
    horizon : float
        The old horizon ``T`` [s].
    deviations : ndarray of shape (n_vehicles, 2)
        ``d_i``: each new start minus the old plan's position at ``at``, north/east [m].
    speed_limits : ndarray of shape (n_vehicles,)
        ``v_max,i`` [m/s], the speeds stage 2 may use.

    Returns
    -------
    Remainder
        The paths ``R_i`` and the progress along them on a grid from 0 to ``T - a`` (the old
        grid's times after ``a`` and the ends of the fade-outs), with its certificate.
    """
    remaining = horizon - at
    offsets = np.hypot(deviations[:, 0], deviations[:, 1])
    vehicles = range(problem.n_vehicles)
    times = coordination.time
    grid = np.unique(np.concatenate([[at], times[(times > at) & (times < horizon)], [horizon]]))
    law = np.stack([progress_at(coordination, i, grid) for i in vehicles])
    fastest = np.max(np.diff(law, axis=1) / np.diff(grid), axis=1, initial=0.0)
    spare = np.maximum(speed_limits - fastest, MIN_SPARE_FRACTION * speed_limits)
    fade_times = np.minimum(0.5 * np.pi * offsets / spare, remaining)
    grid = np.unique(np.concatenate([grid, at + fade_times]))
    law = np.stack([progress_at(coordination, i, grid) for i in vehicles])
    elapsed = grid - at
    factors = fade_factors(elapsed, fade_times)
    paths, progress = [], np.empty_like(law)
    for i in vehicles:
        arc = problem.arc_lengths[i]
        fading = int(np.searchsorted(elapsed, fade_times[i]))  # the sample at a + τ_i
        fade = factors[i, : fading + 1]
        led_in = positions_along(problem.paths[i], arc, law[i, : fading + 1])
        led_in = led_in + fade[:, None] * deviations[i]
        chords = np.hypot(*np.diff(led_in, axis=0).T)
        progress[i, : fading + 1] = np.concatenate([[0.0], np.cumsum(chords)])
        progress[i, fading + 1 :] = progress[i, fading] + law[i, fading + 1 :] - law[i, fading]
        paths.append(np.vstack([led_in, problem.paths[i][arc > law[i, fading]]]))
    remainder = CoordinationProblem(
        paths=tuple(paths),
        safety_radius=problem.safety_radius,
        cruise_speeds=problem.cruise_speeds,
        time_step=problem.time_step,
        names=problem.names,
        min_speeds=problem.min_speeds,
        max_accelerations=problem.max_accelerations,
    )
    progress = np.minimum(progress, remainder.path_lengths[:, None])
    progress[:, -1] = remainder.path_lengths  # every vehicle arrives at T - a
    certificate = certify_separation(remainder, elapsed, progress)
    arrivals = arrival_times_of(remainder, elapsed, progress)
    delays = np.maximum(arrivals - remainder.nominal_arrival_times, 0.0)
    shifted = CoordinationResult(
        status=coordination.status,
        message=f"the schedule of the plan replanned, from its t = {at:g} s",
        method=coordination.method,
        weight=coordination.weight,
        time=elapsed,
        progress=progress,
        arrival_times=arrivals,
        delays=delays,
        certificate=certificate,
        n_expanded=0,
        objective=(float(np.max(arrivals)), float(np.sum(delays))),
        within_limits=coordination.within_limits,
    )
    return Remainder(remainder, shifted, deviations, fade_times)


__all__ = ["MIN_SPARE_FRACTION", "Remainder", "fade_factors", "shift_schedule"]
