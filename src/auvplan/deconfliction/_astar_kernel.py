r"""Numba kernel: weighted A* on the N-dimensional coordination grid.

A node is ``k = (k_1, …, k_N)``, encoded as the mixed-radix integer ``Σ k_i stride_i``.
A move advances any non-empty subset of the vehicles that are not yet at their goal by one
step; it takes one time step. The path cost is lexicographic:

1. ``steps`` — the number of moves (the makespan in time steps);
2. ``waits`` — the number of (vehicle, step) pairs in which a vehicle not yet at its goal
   stands still (= the total delay in steps).

The heuristic ``h(k) = max_i (n_i - k_i)`` bounds the remaining makespan. It is raised to
``max_{i<j} C_ij(k_i, k_j)``, the exact makespan-to-go of the pair ``(i, j)`` alone on its
free 2-D grid (a relaxation of the N-vehicle problem, precomputed by a backward dynamic
programme); nodes from which some pair cannot reach its goal are pruned. Both are admissible
and consistent (the maximum of consistent heuristics is consistent) for the lexicographic
cost (with a zero second component), so ``weight = 1`` returns the lexicographic optimum
without reopening nodes. The priority is
``(steps + weight·h, waits, -steps)``. Collision checks are lazy: a node is tested pair by
pair in the per-row interval lists when it is generated; the N-D grid is never stored.
"""

from __future__ import annotations

import enum

import numba
import numpy as np
import numpy.typing as npt

from auvplan._typing import FloatArray, IntArray
from auvplan.deconfliction._buffers import grow
from auvplan.deconfliction._conflict_kernels import DEAD_END

EMPTY = -1


class AstarOutcome(enum.IntEnum):
    """How :func:`astar_coordination` ended."""

    FOUND = 0
    """The goal was reached; the path is returned."""
    NO_SCHEDULE = 1
    """The open list ran empty: no collision-free schedule exists on the grid."""
    BUDGET_EXHAUSTED = 2
    """``max_expanded`` expansions or ``max_stored`` nodes without reaching the goal."""


@numba.njit(cache=True)
def _hash(key: int, mask: int) -> int:
    h = (key * 0x2545F4914F6CDD1D) & 0x7FFFFFFFFFFFFFFF
    return (h ^ (h >> 29)) & mask


@numba.njit(cache=True)
def _find_slot(table_keys: IntArray, key: int, mask: int) -> int:
    slot = _hash(key, mask)
    while table_keys[slot] != EMPTY and table_keys[slot] != key:
        slot = (slot + 1) & mask
    return slot


@numba.njit(cache=True)
def _is_free(
    k: IntArray,
    moved: IntArray,
    pair_base: IntArray,
    row_ptr: IntArray,
    lo: IntArray,
    hi: IntArray,
) -> bool:
    n = k.shape[0]
    for i in range(n):
        for j in range(i + 1, n):
            if moved[i] == 0 and moved[j] == 0:
                continue
            base = pair_base[i * n + j]
            kj = k[j]
            for q in range(row_ptr[base + k[i]], row_ptr[base + k[i] + 1]):
                if lo[q] > kj:
                    break
                if hi[q] >= kj:
                    return False
    return True


@numba.njit(cache=True)
def _heuristic(
    k: IntArray,
    n_steps: IntArray,
    heur_base: IntArray,
    heur_first: IntArray,
    heur_start: IntArray,
    heur_len: IntArray,
    heur_excess: npt.NDArray[np.uint16],
) -> int:
    """``max_i (n_i - k_i)``, raised to the exact pairwise cost-to-go where one is given."""
    n = k.shape[0]
    h = 0
    for i in range(n):
        h = max(h, n_steps[i] - k[i])
    for i in range(n):
        for j in range(i + 1, n):
            base = heur_base[i * n + j]
            if base < 0:
                continue
            row = base + k[i]
            column = k[j] - heur_first[row]
            if column < 0 or column >= heur_len[row]:
                continue
            excess = np.int64(heur_excess[heur_start[row] + column])
            if excess == DEAD_END:
                return -1
            h = max(h, max(n_steps[i] - k[i], n_steps[j] - k[j]) + excess)
    return h


@numba.njit(cache=True)
def _heap_less(f: FloatArray, w: IntArray, g: IntArray, a: int, b: int) -> bool:
    if f[a] != f[b]:
        return bool(f[a] < f[b])
    if w[a] != w[b]:
        return bool(w[a] < w[b])
    return bool(g[a] > g[b])


@numba.njit(cache=True)
def _swap(f: FloatArray, w: IntArray, g: IntArray, node: IntArray, a: int, b: int) -> None:
    f[a], f[b] = f[b], f[a]
    w[a], w[b] = w[b], w[a]
    g[a], g[b] = g[b], g[a]
    node[a], node[b] = node[b], node[a]


@numba.njit(cache=True)
def astar_coordination(
    n_steps: IntArray,
    pair_base: IntArray,
    row_ptr: IntArray,
    lo: IntArray,
    hi: IntArray,
    heur_base: IntArray,
    heur_first: IntArray,
    heur_start: IntArray,
    heur_len: IntArray,
    heur_excess: npt.NDArray[np.uint16],
    weight: float,
    max_expanded: int,
    max_stored: int,
) -> tuple[AstarOutcome, IntArray, int]:
    """Weighted A* from ``(0, …, 0)`` to ``(n_1, …, n_N)``.

    Parameters
    ----------
    n_steps : ndarray of shape (N,)
        Goal index ``n_i`` of every vehicle.
    pair_base : ndarray of shape (N * N,)
        For ``i < j``: offset of pair ``(i, j)``'s rows in ``row_ptr``.
    row_ptr, lo, hi : ndarray
        Concatenated CSR interval lists (absolute offsets into ``lo``/``hi``).
    heur_base, heur_first, heur_start, heur_len, heur_excess : ndarray
        Pairwise cost-to-go excess (see ``pair_cost_to_go``); ``heur_base[i * N + j]`` is the
        offset of pair ``(i, j)``'s rows, ``-1`` to use only ``max_i (n_i - k_i)``.
    weight : float
        Heuristic weight (>= 1).
    max_expanded : int
        Expansion budget.
    max_stored : int
        Memory budget: the largest number of stored nodes, and of heap entries.

    Returns
    -------
    outcome : AstarOutcome
        Found, no collision-free grid schedule, or budget exhausted.
    path : ndarray of shape (n_moves + 1, N)
        Grid indices along the found path (empty when not found).
    n_expanded : int
        Number of expanded nodes.
    """
    n = n_steps.shape[0]
    stride = np.ones(n, dtype=np.int64)
    for i in range(1, n):
        stride[i] = stride[i - 1] * (n_steps[i - 1] + 1)
    goal_key = 0
    for i in range(n):
        goal_key += n_steps[i] * stride[i]

    # node store
    cap_nodes = 1 << 16
    node_key = np.empty(cap_nodes, dtype=np.int64)
    node_steps = np.empty(cap_nodes, dtype=np.int64)
    node_waits = np.empty(cap_nodes, dtype=np.int64)
    node_parent = np.empty(cap_nodes, dtype=np.int64)
    node_closed = np.empty(cap_nodes, dtype=np.bool_)
    node_h = np.empty(cap_nodes, dtype=np.int64)
    n_nodes = 0
    # hash table key -> node id
    cap_table = 1 << 17
    mask = cap_table - 1
    table_keys = np.full(cap_table, EMPTY, dtype=np.int64)
    table_node = np.empty(cap_table, dtype=np.int64)
    # binary heap
    cap_heap = 1 << 16
    heap_f = np.empty(cap_heap)
    heap_w = np.empty(cap_heap, dtype=np.int64)
    heap_g = np.empty(cap_heap, dtype=np.int64)
    heap_node = np.empty(cap_heap, dtype=np.int64)
    heap_size = 0

    k = np.zeros(n, dtype=np.int64)
    child = np.zeros(n, dtype=np.int64)
    moved = np.zeros(n, dtype=np.int64)
    active = np.zeros(n, dtype=np.int64)
    all_moved = np.ones(n, dtype=np.int64)

    if not _is_free(k, all_moved, pair_base, row_ptr, lo, hi):
        return AstarOutcome.NO_SCHEDULE, np.zeros((0, n), dtype=np.int64), 0

    h0 = _heuristic(k, n_steps, heur_base, heur_first, heur_start, heur_len, heur_excess)
    if h0 < 0:
        return AstarOutcome.NO_SCHEDULE, np.zeros((0, n), dtype=np.int64), 0
    node_key[0] = 0
    node_steps[0] = 0
    node_waits[0] = 0
    node_parent[0] = -1
    node_closed[0] = False
    node_h[0] = h0
    n_nodes = 1
    slot = _find_slot(table_keys, 0, mask)
    table_keys[slot] = 0
    table_node[slot] = 0
    heap_f[0] = weight * h0
    heap_w[0] = 0
    heap_g[0] = 0
    heap_node[0] = 0
    heap_size = 1

    n_expanded = 0
    found = -1
    while heap_size > 0:
        # pop
        current = heap_node[0]
        entry_w = heap_w[0]
        entry_g = heap_g[0]
        heap_size -= 1
        if heap_size > 0:
            heap_f[0] = heap_f[heap_size]
            heap_w[0] = heap_w[heap_size]
            heap_g[0] = heap_g[heap_size]
            heap_node[0] = heap_node[heap_size]
            pos = 0
            while True:
                left = 2 * pos + 1
                if left >= heap_size:
                    break
                best = left
                if left + 1 < heap_size and _heap_less(heap_f, heap_w, heap_g, left + 1, left):
                    best = left + 1
                if _heap_less(heap_f, heap_w, heap_g, best, pos):
                    _swap(heap_f, heap_w, heap_g, heap_node, best, pos)
                    pos = best
                else:
                    break
        if node_closed[current]:
            continue
        if entry_g != node_steps[current] or entry_w != node_waits[current]:
            continue  # stale entry
        if node_key[current] == goal_key:
            found = current
            break
        node_closed[current] = True
        n_expanded += 1
        if n_expanded > max_expanded:
            return AstarOutcome.BUDGET_EXHAUSTED, np.zeros((0, n), dtype=np.int64), n_expanded - 1
        # decode
        rest = node_key[current]
        n_active = 0
        for i in range(n - 1, -1, -1):
            k[i] = rest // stride[i]
            rest -= k[i] * stride[i]
        for i in range(n):
            if k[i] < n_steps[i]:
                active[n_active] = i
                n_active += 1
        steps = node_steps[current] + 1
        for subset in range(1, 1 << n_active):
            n_moving = 0
            for i in range(n):
                child[i] = k[i]
                moved[i] = 0
            for a in range(n_active):
                if subset & (1 << a):
                    child[active[a]] += 1
                    moved[active[a]] = 1
                    n_moving += 1
            if not _is_free(child, moved, pair_base, row_ptr, lo, hi):
                continue
            waits = node_waits[current] + (n_active - n_moving)
            key = 0
            for i in range(n):
                key += child[i] * stride[i]
            slot = _find_slot(table_keys, key, mask)
            if table_keys[slot] == key:
                other = table_node[slot]
                if node_closed[other]:
                    continue
                if steps > node_steps[other] or (
                    steps == node_steps[other] and waits >= node_waits[other]
                ):
                    continue
                node_steps[other] = steps
                node_waits[other] = waits
                node_parent[other] = current
                target = other
                h = node_h[other]
            else:
                h = _heuristic(
                    child, n_steps, heur_base, heur_first, heur_start, heur_len, heur_excess
                )
                if h < 0:
                    continue  # dead end: some pair can no longer reach its goal
                if n_nodes >= max_stored:
                    return AstarOutcome.BUDGET_EXHAUSTED, np.zeros((0, n), np.int64), n_expanded
                if n_nodes >= node_key.shape[0]:
                    node_key = grow(node_key, n_nodes, 0)
                    node_steps = grow(node_steps, n_nodes, 0)
                    node_waits = grow(node_waits, n_nodes, 0)
                    node_parent = grow(node_parent, n_nodes, 0)
                    node_closed = grow(node_closed, n_nodes, 0)
                    node_h = grow(node_h, n_nodes, 0)
                target = n_nodes
                node_key[target] = key
                node_steps[target] = steps
                node_waits[target] = waits
                node_parent[target] = current
                node_closed[target] = False
                node_h[target] = h
                n_nodes += 1
                table_keys[slot] = key
                table_node[slot] = target
                if 2 * n_nodes > cap_table:  # keep the load factor <= 1/2
                    cap_table *= 2
                    mask = cap_table - 1
                    table_keys = np.full(cap_table, EMPTY, dtype=np.int64)
                    table_node = np.empty(cap_table, dtype=np.int64)
                    for m in range(n_nodes):
                        s = _find_slot(table_keys, node_key[m], mask)
                        table_keys[s] = node_key[m]
                        table_node[s] = m
            # push
            if heap_size >= max_stored:
                return AstarOutcome.BUDGET_EXHAUSTED, np.zeros((0, n), np.int64), n_expanded
            if heap_size >= heap_f.shape[0]:
                heap_f = grow(heap_f, heap_size, 0)
                heap_w = grow(heap_w, heap_size, 0)
                heap_g = grow(heap_g, heap_size, 0)
                heap_node = grow(heap_node, heap_size, 0)
            pos = heap_size
            heap_f[pos] = steps + weight * h
            heap_w[pos] = waits
            heap_g[pos] = steps
            heap_node[pos] = target
            heap_size += 1
            while pos > 0:
                parent = (pos - 1) // 2
                if _heap_less(heap_f, heap_w, heap_g, pos, parent):
                    _swap(heap_f, heap_w, heap_g, heap_node, pos, parent)
                    pos = parent
                else:
                    break
    if found < 0:
        return AstarOutcome.NO_SCHEDULE, np.zeros((0, n), dtype=np.int64), n_expanded
    length = node_steps[found] + 1
    path = np.empty((length, n), dtype=np.int64)
    node = found
    for m in range(length - 1, -1, -1):
        rest = node_key[node]
        for i in range(n - 1, -1, -1):
            path[m, i] = rest // stride[i]
            rest -= path[m, i] * stride[i]
        node = node_parent[node]
    return AstarOutcome.FOUND, path, n_expanded
