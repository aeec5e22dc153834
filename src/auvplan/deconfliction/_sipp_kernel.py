r"""Numba kernel: earliest-arrival velocity tuning of one vehicle among timed ones.

Vehicle ``i`` moves along its grid ``k = 0 … n_i``; in each time step it waits or advances
one step. The vehicles planned before it are fixed schedules ``K_j(t)`` (non-decreasing; a
vehicle stays at its goal after its schedule ends). Because every ``K_j`` is monotone, the
times at which grid point ``k`` is blocked by ``j`` form one interval per forbidden
``k_j``-interval of row ``k``, so each grid point has a short list of *safe time intervals*
(safe-interval path planning, Phillips & Likhachev 2011). The earliest arrival in each safe
interval is propagated once, in increasing ``k`` — an exact dynamic programme on the
``(k, t)`` grid that never enumerates time steps.
"""

from __future__ import annotations

import numba
import numpy as np

from auvplan._typing import IntArray
from auvplan.deconfliction._buffers import grow

NEVER = np.int64(1) << np.int64(60)


@numba.njit(cache=True)
def _first_at_least(schedule: IntArray, value: int) -> int:
    return int(np.searchsorted(schedule, value, side="left"))


@numba.njit(cache=True)
def earliest_arrival_schedule(
    n_steps_i: int,
    others: IntArray,
    schedules: IntArray,
    schedule_ptr: IntArray,
    others_goal: IntArray,
    pair_base: IntArray,
    row_ptr: IntArray,
    lo: IntArray,
    hi: IntArray,
) -> tuple[bool, IntArray, int]:
    """Earliest-arrival grid schedule of one vehicle avoiding timed vehicles.

    Parameters
    ----------
    n_steps_i : int
        Goal index ``n_i``.
    others : ndarray of shape (n_others,)
        Slot of each already planned vehicle (index into ``pair_base`` and the schedules).
    schedules : ndarray
        Concatenated grid schedules ``K_j(t)``, ``t = 0 … T_j``.
    schedule_ptr : ndarray of shape (n_others + 1,)
        Offsets of each schedule in ``schedules``.
    others_goal : ndarray of shape (n_others,)
        ``n_j`` of each planned vehicle.
    pair_base : ndarray of shape (n_others,)
        Offset of the rows of pair ``(i, j)`` in ``row_ptr``.
    row_ptr, lo, hi : ndarray
        Concatenated CSR interval lists of forbidden ``k_j`` per row ``k_i``.

    Returns
    -------
    found : bool
    arrival : ndarray of shape (n_i + 1,)
        Time step at which the vehicle first reaches each grid index.
    n_states : int
        Number of (grid index, safe interval) states visited.
    """
    n_others = others.shape[0]
    # blocked time intervals of one row, then safe intervals
    blk_start = np.empty(64, dtype=np.int64)
    blk_end = np.empty(64, dtype=np.int64)
    # safe intervals of all rows (growable)
    safe_start = np.empty(4 * (n_steps_i + 1) + 64, dtype=np.int64)
    safe_end = np.empty_like(safe_start)
    earliest = np.empty_like(safe_start)
    parent = np.empty_like(safe_start)
    row_first = np.empty(n_steps_i + 2, dtype=np.int64)
    n_safe = 0
    for k in range(n_steps_i + 1):
        # collect blocked time intervals
        n_blk = 0
        for o in range(n_others):
            base = pair_base[o]
            first = schedule_ptr[o]
            stop = schedule_ptr[o + 1]
            sched = schedules[first:stop]
            last_t = stop - first - 1
            goal = others_goal[o]
            for q in range(row_ptr[base + k], row_ptr[base + k + 1]):
                t0 = _first_at_least(sched, lo[q])
                if t0 > last_t:
                    continue  # j never reaches lo
                t1 = NEVER if hi[q] >= goal else _first_at_least(sched, hi[q] + 1) - 1
                if t1 < t0:
                    continue
                if n_blk >= blk_start.shape[0]:
                    blk_start = grow(blk_start, n_blk, 0)
                    blk_end = grow(blk_end, n_blk, 0)
                pos = n_blk
                while pos > 0 and blk_start[pos - 1] > t0:
                    blk_start[pos] = blk_start[pos - 1]
                    blk_end[pos] = blk_end[pos - 1]
                    pos -= 1
                blk_start[pos] = t0
                blk_end[pos] = t1
                n_blk += 1
        # merge the blocked intervals, then emit the gaps as safe intervals of row k
        row_first[k] = n_safe
        free_from = 0
        b = 0
        while free_from < NEVER:
            if b < n_blk:
                block_from = blk_start[b]
                block_to = blk_end[b]
                b += 1
                while b < n_blk and blk_start[b] <= block_to + 1:
                    block_to = max(block_to, blk_end[b])
                    b += 1
                if block_from <= free_from:
                    free_from = max(free_from, block_to + 1)
                    continue
                end = block_from - 1
                next_free = block_to + 1
            else:
                end = NEVER
                next_free = NEVER
            if n_safe >= safe_start.shape[0]:
                safe_start = grow(safe_start, n_safe, 0)
                safe_end = grow(safe_end, n_safe, 0)
                earliest = grow(earliest, n_safe, 0)
                parent = grow(parent, n_safe, 0)
            safe_start[n_safe] = free_from
            safe_end[n_safe] = end
            earliest[n_safe] = NEVER
            parent[n_safe] = -1
            n_safe += 1
            free_from = next_free
        row_first[k + 1] = n_safe
        # propagate earliest arrivals
        if k == 0:
            if n_safe > 0 and safe_start[0] == 0:
                earliest[0] = 0
            continue
        prev = row_first[k - 1]
        prev_stop = row_first[k]
        for s in range(row_first[k], n_safe):
            best = NEVER
            best_parent = -1
            for p in range(prev, prev_stop):
                if earliest[p] >= NEVER:
                    continue
                if safe_end[p] < NEVER and safe_end[p] + 1 < safe_start[s]:
                    continue
                arrive = max(earliest[p] + 1, safe_start[s])
                if arrive > safe_end[s]:
                    continue
                if safe_end[p] < NEVER and arrive > safe_end[p] + 1:
                    continue
                if arrive < best:
                    best = arrive
                    best_parent = p
            earliest[s] = best
            parent[s] = best_parent
    arrival = np.zeros(n_steps_i + 1, dtype=np.int64)
    goal_state = n_safe - 1  # the last safe interval of the goal row must be unbounded
    if (
        row_first[n_steps_i] == n_safe
        or safe_end[goal_state] < NEVER
        or earliest[goal_state] >= NEVER
    ):
        return False, arrival, n_safe
    state = goal_state
    for k in range(n_steps_i, -1, -1):
        arrival[k] = earliest[state]
        state = parent[state]
    return True, arrival, n_safe
