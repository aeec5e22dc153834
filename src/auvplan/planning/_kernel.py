r"""Numba-compiled A* kernels on a padded, flattened 8-connected grid.

Cells are flat indices into the padded grid (stored as int32 in the parent and bucket
arrays, so grids are limited to :math:`2^{31} - 1` cells). The grid is padded with one ring of
impassable cells, so a neighbour is always ``u + offset``
and no bounds check is needed. Impassable cells (and the ring) have cost ``inf``.

Edge weight of a move ``u -> v`` with step length :math:`\ell_k` [m]:

* ``crossed == False`` (paper): :math:`w = c_v`;
* ``crossed == True``: :math:`w = \ell_k (c_u + c_v) / 2`;

each times the move's factor :math:`f_{k,v}` (``factor[k, v * factor_stride]``: stride 0 with
a ``(8, 1)`` array of ones when there is none; e.g. a current's ``U_w / s`` ratio of
through-water to ground speed, ``inf`` for a move the vehicle cannot make). The heuristic's
rate :math:`\rho` and the bucket width below then use :math:`c_{min} f_{min}`.

Heuristic at a cell ``(r, c)`` with :math:`a = |r - r_g|`, :math:`b = |c - c_g|`,
:math:`k = \min(a, b)` and a rate :math:`\rho \le c_{min}`:

* paper: :math:`h = \rho \max(a, b)` (Chebyshev distance in cells);
* crossed: :math:`h = \rho (k \ell_d + (a - k) \Delta_n + (b - k) \Delta_e)` (octile
  distance in metres, the exact shortest 8-connected path length on the anisotropic grid).

Two open lists, both exact (they close every cell with its optimal cost), served by one
search loop (:func:`_astar`):

``astar_heap``
    binary min-heap of ``(f, cell)`` with lazy deletion (stale duplicates are skipped when
    popped because their cell is already closed); ``pop`` sinks the hole to a leaf along the
    smaller children and sifts the last entry up (Floyd), halving the comparisons.
``astar_buckets``
    a circular bucket queue of width :math:`\Delta` on :math:`f = g + h` (Dial's algorithm
    with Dinitz's rule). With :math:`\rho = \alpha c_{min}`, :math:`\alpha < 1`, every reduced
    edge weight :math:`w'(u, v) = w(u, v) - h(u) + h(v)` is at least
    :math:`\Delta = (1 - \alpha) c_{min} \ell_{min}` (:math:`\ell_{min} = 1` for the paper
    model, :math:`\min(\Delta_n, \Delta_e)` for the crossed model). Then every cell in the
    lowest non-empty bucket already has its optimal ``g``: a cheaper path would reach it
    through an open cell whose :math:`f` is at least the bucket's lower edge, plus at least
    one more edge of reduced weight :math:`\ge \Delta`. So the cells of the lowest bucket are
    closed in any order (LIFO), with O(1) pushes and pops. Reduced weights are at most
    :math:`w'_{max} = \ell_{max} (c_{max} + \rho)`, so
    :math:`\lceil w'_{max} / \Delta \rceil + 2` buckets never wrap around onto live entries.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from numba import njit

from auvplan._typing import BoolArray, FloatArray, IntArray


@njit(cache=True)
def _moves(
    n_cols: int, spacing_north: float, spacing_east: float
) -> tuple[IntArray, IntArray, IntArray, FloatArray]:  # pragma: no cover - compiled
    """Flat offsets, row steps, column steps and lengths [m] of the 8 moves."""
    diagonal = np.sqrt(spacing_north * spacing_north + spacing_east * spacing_east)
    offsets = np.array(
        [-n_cols - 1, -n_cols, -n_cols + 1, -1, 1, n_cols - 1, n_cols, n_cols + 1], np.int64
    )
    d_row = np.array([-1, -1, -1, 0, 0, 1, 1, 1], np.int64)
    d_col = np.array([-1, 0, 1, -1, 1, -1, 0, 1], np.int64)
    length = np.array(
        [
            diagonal,
            spacing_north,
            diagonal,
            spacing_east,
            spacing_east,
            diagonal,
            spacing_north,
            diagonal,
        ]
    )
    return offsets, d_row, d_col, length


@njit(cache=True, inline="always")
def _heuristic(
    row: int,
    col: int,
    goal_row: int,
    goal_col: int,
    crossed: bool,
    rate: float,
    spacing_north: float,
    spacing_east: float,
    diagonal: float,
) -> float:  # pragma: no cover - compiled
    """``rate`` times the Chebyshev (paper) or octile-in-metres (crossed) distance."""
    a = abs(row - goal_row)
    b = abs(col - goal_col)
    if crossed:
        m = min(a, b)
        return rate * (m * diagonal + (a - m) * spacing_north + (b - m) * spacing_east)
    return rate * max(a, b)


@njit(cache=True)
def heuristic_grid(
    n_rows: int,
    n_cols: int,
    goal_row: int,
    goal_col: int,
    crossed: bool,
    rate: float,
    spacing_north: float,
    spacing_east: float,
) -> FloatArray:  # pragma: no cover - compiled
    """The kernels' heuristic evaluated at every cell of an unpadded grid."""
    diagonal = np.sqrt(spacing_north * spacing_north + spacing_east * spacing_east)
    out = np.empty((n_rows, n_cols))
    for row in range(n_rows):
        for col in range(n_cols):
            out[row, col] = _heuristic(
                row, col, goal_row, goal_col, crossed, rate, spacing_north, spacing_east, diagonal
            )
    return out


@njit(cache=True)
def _trace_path(
    parent: npt.NDArray[np.int32], start: int, goal: int
) -> IntArray:  # pragma: no cover
    """Flat cells from ``start`` to ``goal`` by following ``parent`` back from the goal."""
    n_path = 1
    v = goal
    while v != start:
        v = parent[v]
        n_path += 1
    path = np.empty(n_path, np.int64)
    v = goal
    for i in range(n_path - 1, -1, -1):
        path[i] = v
        v = parent[v]
    return path


@njit(cache=True)
def _open_mask(cost: FloatArray) -> BoolArray:  # pragma: no cover - compiled
    """``closed`` flags initialised to true on impassable (``inf``) cells."""
    closed = np.empty(cost.size, np.bool_)
    for v in range(cost.size):
        closed[v] = not cost[v] < np.inf
    return closed


@njit(cache=True)
def finite_range(cost: FloatArray) -> tuple[float, float]:  # pragma: no cover - compiled
    """Smallest and largest finite value of ``cost`` (``inf, -inf`` if none)."""
    low = np.inf
    high = -np.inf
    for v in range(cost.size):
        c = cost[v]
        if c < np.inf and c > -np.inf:
            low = min(low, c)
            high = max(high, c)
    return low, high


@njit(cache=True)
def astar_heap(
    cost: FloatArray,
    n_cols: int,
    start: int,
    goal: int,
    crossed: bool,
    spacing_north: float,
    spacing_east: float,
    rate: float,
    factor: FloatArray,
    factor_stride: int,
) -> tuple[IntArray, float, int]:  # pragma: no cover - compiled
    """A* with a binary heap on the padded flat grid ``cost`` of row length ``n_cols``.

    ``rate`` is the heuristic's cost per cell (paper) or per metre (crossed), ``<= c_min
    f_min``; ``factor`` ``(8, n)`` and ``factor_stride`` as in the module notes. Returns the
    path as flat padded indices from start to goal (empty if unreachable), its cost (``inf``
    if unreachable) and the number of expanded cells.
    """
    return _astar(
        cost, n_cols, start, goal, crossed, spacing_north, spacing_east, rate, factor,
        factor_stride, 0, 0.0,
    )  # fmt: skip


@njit(cache=True)
def astar_buckets(
    cost: FloatArray,
    n_cols: int,
    start: int,
    goal: int,
    crossed: bool,
    spacing_north: float,
    spacing_east: float,
    rate: float,
    factor: FloatArray,
    factor_stride: int,
    n_buckets: int,
    width: float,
) -> tuple[IntArray, float, int]:  # pragma: no cover - compiled
    """A* with a Dial/Dinitz bucket queue of ``n_buckets`` buckets of width ``width``.

    ``width`` must not exceed the smallest reduced edge weight and ``n_buckets`` must exceed
    ``largest reduced edge weight / width + 1`` (see the module docstring); otherwise the same
    arguments and returns as :func:`astar_heap`.
    """
    return _astar(
        cost, n_cols, start, goal, crossed, spacing_north, spacing_east, rate, factor,
        factor_stride, n_buckets, width,
    )  # fmt: skip


@njit(cache=True)
def _astar(
    cost: FloatArray,
    n_cols: int,
    start: int,
    goal: int,
    crossed: bool,
    spacing_north: float,
    spacing_east: float,
    rate: float,
    factor: FloatArray,
    factor_stride: int,
    n_buckets: int,
    width: float,
) -> tuple[IntArray, float, int]:  # pragma: no cover - compiled
    """A* with the bucket queue when ``n_buckets > 0``, else with the binary heap.

    One search loop serves both open lists: the queue is chosen by a loop-invariant flag
    (a call per push or pop would cost reference counting of the queue arrays).
    """
    offsets, d_row, d_col, length = _moves(n_cols, spacing_north, spacing_east)
    diagonal = length[0]
    closed = _open_mask(cost)
    g = np.full(cost.size, np.inf)
    parent = np.full(cost.size, -1, np.int32)
    goal_row = goal // n_cols
    goal_col = goal - goal_row * n_cols
    g[start] = 0.0
    use_buckets = n_buckets > 0

    # binary heap of (f, cell)
    capacity = 1024 if not use_buckets else 1
    keys = np.empty(capacity)
    nodes = np.empty(capacity, np.int64)
    # bucket queue: row b holds the cells whose f lies in bucket b (mod n_buckets)
    bucket_capacity = 64 if use_buckets else 1
    buckets = np.empty((max(n_buckets, 1), bucket_capacity), np.int32)
    counts = np.zeros(max(n_buckets, 1), np.int64)
    inv_width = 1.0 / width if use_buckets else 0.0
    current = 0  # absolute number of the lowest bucket
    if use_buckets:
        start_row = start // n_cols
        h_start = _heuristic(
            start_row,
            start - start_row * n_cols,
            goal_row,
            goal_col,
            crossed,
            rate,
            spacing_north,
            spacing_east,
            diagonal,
        )
        current = int(h_start * inv_width)
        buckets[current % n_buckets, 0] = start
        counts[current % n_buckets] = 1
    else:
        keys[0] = 0.0
        nodes[0] = start
    size = 1
    n_expanded = 0
    while size > 0:
        if use_buckets:  # pop from the lowest non-empty bucket (LIFO)
            b = current % n_buckets
            if counts[b] == 0:
                current += 1
                continue
            counts[b] -= 1
            size -= 1
            u = np.int64(buckets[b, counts[b]])
        else:  # pop: sink the hole at the root to a leaf, then sift the last entry up into it
            u = nodes[0]
            size -= 1
            key = keys[size]
            node = nodes[size]
            i = 0
            child = 1
            while child < size:
                if child + 1 < size and keys[child + 1] < keys[child]:
                    child += 1
                keys[i] = keys[child]
                nodes[i] = nodes[child]
                i = child
                child = 2 * i + 1
            while i > 0:
                up = (i - 1) >> 1
                if keys[up] <= key:
                    break
                keys[i] = keys[up]
                nodes[i] = nodes[up]
                i = up
            keys[i] = key
            nodes[i] = node

        if closed[u]:
            continue
        closed[u] = True
        n_expanded += 1
        if u == goal:
            return _trace_path(parent, start, goal), g[goal], n_expanded
        g_u = g[u]
        c_u = cost[u]
        row = u // n_cols
        col = u - row * n_cols
        for k in range(8):
            v = u + offsets[k]
            if closed[v]:
                continue
            w = length[k] * 0.5 * (c_u + cost[v]) if crossed else cost[v]
            g_v = g_u + w * factor[k, v * factor_stride]
            if g_v >= g[v]:
                continue
            g[v] = g_v
            parent[v] = u
            f_v = g_v + _heuristic(
                row + d_row[k],
                col + d_col[k],
                goal_row,
                goal_col,
                crossed,
                rate,
                spacing_north,
                spacing_east,
                diagonal,
            )
            if use_buckets:  # push onto the bucket of f_v
                target = int(f_v * inv_width) % n_buckets
                if counts[target] == bucket_capacity:
                    grown = np.empty((n_buckets, 2 * bucket_capacity), np.int32)
                    grown[:, :bucket_capacity] = buckets
                    buckets = grown
                    bucket_capacity *= 2
                buckets[target, counts[target]] = v
                counts[target] += 1
            else:  # push: sift up from the end of the heap
                if size == capacity:
                    capacity *= 2
                    keys = np.concatenate((keys, np.empty(size)))
                    nodes = np.concatenate((nodes, np.empty(size, np.int64)))
                i = size
                while i > 0:
                    up = (i - 1) >> 1
                    if keys[up] <= f_v:
                        break
                    keys[i] = keys[up]
                    nodes[i] = nodes[up]
                    i = up
                keys[i] = f_v
                nodes[i] = v
            size += 1
    return np.empty(0, np.int64), np.inf, n_expanded
