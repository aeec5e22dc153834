"""Numba kernels: pairwise forbidden intervals and 2-D monotone reachability.

For an ordered pair ``(i, j)`` the forbidden set of the 2-D coordination grid is stored per
row ``k_i`` as sorted, disjoint, inclusive index intervals ``[lo, hi]`` of ``k_j`` (CSR:
``row_ptr[k_i] … row_ptr[k_i + 1]`` index into ``lo``/``hi``). A grid node is forbidden when
``|p_i(s(k_i)) - p_j(s(k_j))| <= radius``; the caller passes the inflated radius.
"""

from __future__ import annotations

from typing import Final

import numba
import numpy as np
import numpy.typing as npt

from auvplan._typing import FloatArray, IntArray
from auvplan.deconfliction._buffers import grow

ROW_BLOCK = 64
SEGMENT_BLOCK = 32
INDEX_SLACK = 1e-9  # index units: rounding always widens a forbidden interval


@numba.njit(cache=True)
def _bounding_circle(points: FloatArray, first: int, stop: int) -> tuple[float, float, float]:
    n_min = points[first, 0]
    n_max = n_min
    e_min = points[first, 1]
    e_max = e_min
    for r in range(first + 1, stop):
        n_min = min(n_min, points[r, 0])
        n_max = max(n_max, points[r, 0])
        e_min = min(e_min, points[r, 1])
        e_max = max(e_max, points[r, 1])
    c_n = 0.5 * (n_min + n_max)
    c_e = 0.5 * (e_min + e_max)
    radius = 0.0
    for r in range(first, stop):
        radius = max(radius, np.hypot(points[r, 0] - c_n, points[r, 1] - c_e))
    return c_n, c_e, radius


@numba.njit(cache=True)
def pair_intervals(
    points_i: FloatArray,
    vertices_j: FloatArray,
    arc_j: FloatArray,
    step_j: float,
    n_steps_j: int,
    radius: float,
) -> tuple[IntArray, IntArray, IntArray]:
    """Forbidden ``k_j`` intervals for each grid point of vehicle ``i``.

    Parameters
    ----------
    points_i : ndarray of shape (n_i + 1, 2)
        Grid points of vehicle ``i`` [m].
    vertices_j, arc_j : ndarray of shape (m_j, 2) and (m_j,)
        Polyline of vehicle ``j`` and its cumulative arc length [m].
    step_j : float
        Arc-length grid step ``h_j`` [m]; ``s(k) = k h_j`` for ``k < n_j`` and ``L_j`` at ``n_j``.
    n_steps_j : int
        ``n_j``.
    radius : float
        Forbidden distance [m] (inclusive).

    Returns
    -------
    row_ptr : ndarray of shape (n_i + 2,)
        CSR row pointers (the extra entry repeats the end).
    lo, hi : ndarray of shape (n_intervals,)
        Inclusive ``k_j`` bounds.
    """
    n_rows = points_i.shape[0]
    n_seg = vertices_j.shape[0] - 1
    length_j = arc_j[-1]
    n_sb = (n_seg + SEGMENT_BLOCK - 1) // SEGMENT_BLOCK
    sb_n = np.empty(n_sb)
    sb_e = np.empty(n_sb)
    sb_r = np.empty(n_sb)
    for b in range(n_sb):
        first = b * SEGMENT_BLOCK
        stop = min(n_seg, first + SEGMENT_BLOCK) + 1
        sb_n[b], sb_e[b], sb_r[b] = _bounding_circle(vertices_j, first, stop)
    row_ptr = np.zeros(n_rows + 2, dtype=np.int64)
    out_lo = np.empty(1024, dtype=np.int64)
    out_hi = np.empty(1024, dtype=np.int64)
    count = 0
    candidates = np.empty(n_seg, dtype=np.int64)
    buf_lo = np.empty(n_seg + 1, dtype=np.int64)
    buf_hi = np.empty(n_seg + 1, dtype=np.int64)
    r2 = radius * radius
    for block_start in range(0, n_rows, ROW_BLOCK):
        block_stop = min(n_rows, block_start + ROW_BLOCK)
        c_n, c_e, c_r = _bounding_circle(points_i, block_start, block_stop)
        n_cand = 0
        for b in range(n_sb):
            if np.hypot(c_n - sb_n[b], c_e - sb_e[b]) <= c_r + sb_r[b] + radius:
                for seg in range(b * SEGMENT_BLOCK, min(n_seg, (b + 1) * SEGMENT_BLOCK)):
                    candidates[n_cand] = seg
                    n_cand += 1
        for r in range(block_start, block_stop):
            row_ptr[r] = count
            if n_cand == 0:
                continue
            p_n = points_i[r, 0]
            p_e = points_i[r, 1]
            n_buf = 0
            for c in range(n_cand):
                seg = candidates[c]
                a_n = vertices_j[seg, 0]
                a_e = vertices_j[seg, 1]
                seg_len = arc_j[seg + 1] - arc_j[seg]
                u_n = (vertices_j[seg + 1, 0] - a_n) / seg_len
                u_e = (vertices_j[seg + 1, 1] - a_e) / seg_len
                d_n = p_n - a_n
                d_e = p_e - a_e
                along = d_n * u_n + d_e * u_e
                perp2 = max(d_n * d_n + d_e * d_e - along * along, 0.0)
                if perp2 > r2:
                    continue
                half = np.sqrt(r2 - perp2)
                t0 = max(along - half, 0.0)
                t1 = min(along + half, seg_len)
                if t0 > t1:
                    continue
                s0 = arc_j[seg] + t0
                s1 = arc_j[seg] + t1
                k_lo = max(int(np.ceil(s0 / step_j - INDEX_SLACK)), 0)
                if s1 >= length_j * (1.0 - 1e-12):
                    k_hi = n_steps_j
                else:
                    k_hi = min(int(np.floor(s1 / step_j + INDEX_SLACK)), n_steps_j - 1)
                k_lo = min(k_lo, n_steps_j)
                if k_lo > k_hi:
                    continue
                # insertion into the sorted buffer
                pos = n_buf
                while pos > 0 and buf_lo[pos - 1] > k_lo:
                    buf_lo[pos] = buf_lo[pos - 1]
                    buf_hi[pos] = buf_hi[pos - 1]
                    pos -= 1
                buf_lo[pos] = k_lo
                buf_hi[pos] = k_hi
                n_buf += 1
            if n_buf == 0:
                continue
            cur_lo = buf_lo[0]
            cur_hi = buf_hi[0]
            for q in range(1, n_buf + 1):
                if q < n_buf and buf_lo[q] <= cur_hi + 1:
                    cur_hi = max(cur_hi, buf_hi[q])
                    continue
                if count >= out_lo.shape[0]:
                    out_lo = grow(out_lo, count, 0)
                    out_hi = grow(out_hi, count, 0)
                out_lo[count] = cur_lo
                out_hi[count] = cur_hi
                count += 1
                if q < n_buf:
                    cur_lo = buf_lo[q]
                    cur_hi = buf_hi[q]
    row_ptr[n_rows] = count
    row_ptr[n_rows + 1] = count
    return row_ptr, out_lo[:count].copy(), out_hi[:count].copy()


@numba.njit(cache=True)
def pair_reachability(
    row_ptr: IntArray, lo: IntArray, hi: IntArray, n_i: int, n_j: int
) -> tuple[bool, int, int]:
    """Test whether ``(n_i, n_j)`` is reachable from ``(0, 0)`` by monotone moves on the free grid.

    Moves are ``(+1, 0)``, ``(0, +1)`` and ``(+1, +1)``. Rows are swept once, each keeping
    its reachable set as sorted intervals.

    Returns
    -------
    reachable : bool
    row, col : int
        Where the sweep got stuck (the first blocked node on the frontier) when unreachable.
    """
    reach_lo = np.empty(n_j + 2, dtype=np.int64)
    reach_hi = np.empty(n_j + 2, dtype=np.int64)
    free_lo = np.empty(n_j + 2, dtype=np.int64)
    free_hi = np.empty(n_j + 2, dtype=np.int64)
    new_lo = np.empty(n_j + 2, dtype=np.int64)
    new_hi = np.empty(n_j + 2, dtype=np.int64)
    n_reach = 1
    reach_lo[0] = 0
    reach_hi[0] = 0  # entry point of row 0 (extended below like any entry)
    for r in range(n_i + 1):
        # free intervals of row r
        n_free = 0
        start = 0
        for q in range(row_ptr[r], row_ptr[r + 1]):
            if lo[q] > start:
                free_lo[n_free] = start
                free_hi[n_free] = lo[q] - 1
                n_free += 1
            start = hi[q] + 1
        if start <= n_j:
            free_lo[n_free] = start
            free_hi[n_free] = n_j
            n_free += 1
        # entries: previous reachable set S and S + 1 (row 0: just the origin)
        n_new = 0
        e = 0
        for f in range(n_free):
            while e < n_reach and reach_hi[e] + (1 if r > 0 else 0) < free_lo[f]:
                e += 1
            if e < n_reach and reach_lo[e] <= free_hi[f]:
                new_lo[n_new] = max(reach_lo[e], free_lo[f])
                new_hi[n_new] = free_hi[f]
                n_new += 1
        if n_new == 0:
            return False, r, reach_lo[0]
        n_reach = n_new
        reach_lo[:n_new] = new_lo[:n_new]
        reach_hi[:n_new] = new_hi[:n_new]
    if reach_hi[n_reach - 1] != n_j:
        return False, n_i, reach_hi[n_reach - 1] + 1
    return True, -1, -1


@numba.njit(cache=True)
def shadow_cells(
    row_ptr: IntArray, lo: IntArray, hi: IntArray, n_i: int, n_j: int
) -> int:  # pragma: no cover - compiled
    """Cells of the pair grid on a diagonal before its last forbidden cell (an estimate).

    A node ``(a, b)`` has a cost-to-go above the free bound only if the forbidden set blocks
    its optimal monotone paths, the straightest of which runs along its diagonal
    ``d = b - a``; :func:`pair_cost_to_go` computes about this many cells. Diagonal ``d``
    starts at row ``max(0, -d)``, so it contributes ``a_last(d) - max(0, -d) + 1`` cells,
    ``a_last(d)`` the last row of a forbidden cell on it. Rows are visited from the last, and
    a "next unvisited diagonal" forest skips the diagonals already counted, so the work is
    linear in the rows, intervals and diagonals.
    """
    n_diagonals = n_i + n_j + 1
    next_free = np.arange(n_diagonals + 1, dtype=np.int64)  # union-find "next uncounted"
    total = 0
    for a in range(n_i, -1, -1):
        for q in range(row_ptr[a], row_ptr[a + 1]):
            d = lo[q] - a + n_i  # diagonal index, 0 … n_i + n_j
            stop = hi[q] - a + n_i
            while True:
                root = d
                while next_free[root] != root:
                    root = next_free[root]
                while next_free[d] != root:  # path compression
                    d, next_free[d] = next_free[d], root
                d = root
                if d > stop:
                    break
                total += a - max(0, n_i - d) + 1
                next_free[d] = d + 1
    return total


UNREACHABLE: Final[int] = 1 << 40
#: Stored excess values are uint16: ``DEAD_END`` marks nodes that cannot reach the goal and
#: larger excesses are capped at ``EXCESS_CAP`` (``min`` of consistent heuristics stays
#: consistent, so capping keeps the heuristic admissible and consistent).
DEAD_END: Final[int] = 65535
EXCESS_CAP: Final[int] = 65534


@numba.njit(cache=True)
def pair_cost_to_go(
    row_ptr: IntArray,
    lo: IntArray,
    hi: IntArray,
    n_i: int,
    n_j: int,
    values: npt.NDArray[np.uint16],
    count: int,
    max_cells: int,
) -> tuple[IntArray, IntArray, IntArray, npt.NDArray[np.uint16], int, int]:
    r"""Exact two-vehicle cost-to-go (makespan) on the pair's free grid, stored by its excess.

    Backward dynamic programme over rows ``a = n_i … 0``:
    ``C(a, b) = 1 + min(C(a+1, b), C(a, b+1), C(a+1, b+1))`` over free successors, ``C = 0``
    at the goal. Only the excess ``E = C - max(n_i - a, n_j - b)`` is kept (as uint16, capped
    at ``EXCESS_CAP``), per row from its first to its last non-zero entry (``DEAD_END`` where
    the goal cannot be reached; forbidden nodes are stored as 0: they are never queried).
    Values are appended to ``values`` from ``count`` on (the buffer grows when needed), so
    that all pairs share one buffer.

    Only a window of each row is computed: if ``E = 0`` on row ``a + 1`` left of ``N_lo`` and
    right of ``N_hi`` (the span of its forbidden and non-zero cells), and row ``a`` has no
    forbidden cell outside ``[F_lo, F_hi]``, then ``E(a, b) = 0`` for
    ``b < min(N_lo, F_lo) - 1`` (the diagonal move is free and optimal) and for
    ``b > max(N_hi, F_hi)``. Rows without obstacles nearby cost nothing. The programme stops
    (``n_cells > max_cells``) before its windows exceed ``max_cells`` cells in total, so that
    neither its time nor its buffer can outgrow that budget.

    Returns
    -------
    row_first : ndarray of shape (n_i + 1,)
        First column ``b`` of the stored excess of each row.
    row_start : ndarray of shape (n_i + 1,)
        Position of each row's first value in ``values``.
    row_len : ndarray of shape (n_i + 1,)
        Number of stored values of each row.
    values : ndarray of uint16
        The (possibly grown) buffer.
    count : int
        Number of used entries of ``values``.
    n_cells : int
        Number of window cells computed; ``> max_cells`` when the programme stopped at its
        budget (the rows are then unusable).
    """
    inf = UNREACHABLE
    next_row = np.zeros(n_j + 1, dtype=np.int64)
    current = np.zeros(n_j + 1, dtype=np.int64)
    forbidden = np.zeros(n_j + 1, dtype=np.bool_)
    row_first = np.zeros(n_i + 1, dtype=np.int64)
    row_len = np.zeros(n_i + 1, dtype=np.int64)
    starts = np.zeros(n_i + 1, dtype=np.int64)
    next_lo = n_j + 1  # window of row a + 1 (empty)
    next_hi = -1
    span_lo = n_j + 1  # span of forbidden / non-zero cells of row a + 1
    span_hi = -1
    n_cells = 0
    for a in range(n_i, -1, -1):
        f_first = row_ptr[a]
        f_stop = row_ptr[a + 1]
        w_lo = span_lo
        w_hi = span_hi
        if f_stop > f_first:
            w_lo = min(w_lo, lo[f_first])
            w_hi = max(w_hi, hi[f_stop - 1])
        w_lo = max(w_lo - 1, 0)
        w_hi = min(w_hi, n_j)
        starts[a] = count
        n_cells += max(w_hi - w_lo + 1, 0)
        if n_cells > max_cells:
            return row_first, starts, row_len, values, count, n_cells
        if w_hi < w_lo:
            next_lo, next_hi = n_j + 1, -1
            span_lo, span_hi = n_j + 1, -1
            continue
        for b in range(w_lo, w_hi + 1):
            forbidden[b] = False
        for q in range(f_first, f_stop):
            for b in range(max(lo[q], w_lo), min(hi[q], w_hi) + 1):
                forbidden[b] = True
        first_nz = -1
        last_nz = -1
        for b in range(w_hi, w_lo - 1, -1):
            if forbidden[b]:
                current[b] = inf
                first_nz = b
                if last_nz < 0:
                    last_nz = b
                continue
            if a == n_i and b == n_j:
                current[b] = 0
                continue
            best = inf
            if b < n_j:
                right = current[b + 1] if b + 1 <= w_hi else max(n_i - a, n_j - b - 1)
                best = min(best, right)
            if a < n_i:
                below = next_row[b] if next_lo <= b <= next_hi else max(n_i - a - 1, n_j - b)
                best = min(best, below)
                if b < n_j:
                    diagonal = (
                        next_row[b + 1]
                        if next_lo <= b + 1 <= next_hi
                        else max(n_i - a - 1, n_j - b - 1)
                    )
                    best = min(best, diagonal)
            cost = best + 1 if best < inf else inf
            current[b] = cost
            if cost != max(n_i - a, n_j - b):
                first_nz = b
                if last_nz < 0:
                    last_nz = b
        if last_nz >= 0:
            length = last_nz - first_nz + 1
            if count + length > values.shape[0]:
                values = grow(values, count, count + length)
            for b in range(first_nz, last_nz + 1):
                if forbidden[b]:
                    values[count] = 0  # never queried
                elif current[b] >= inf:
                    values[count] = DEAD_END
                else:
                    values[count] = min(current[b] - max(n_i - a, n_j - b), EXCESS_CAP)
                count += 1
            row_first[a] = first_nz
            row_len[a] = length
            span_lo, span_hi = first_nz, last_nz
        else:
            span_lo, span_hi = n_j + 1, -1
        next_lo, next_hi = w_lo, w_hi
        next_row, current = current, next_row
    return row_first, starts, row_len, values, count, n_cells
