r"""Numba kernel of the belief-space search: labels (cost, covariance) on a padded 8-grid.

A label is a path prefix ending at a cell, with its graph cost ``g``, the predicted position
covariance ``P`` at its end (``p00, p01, p11`` [m²] and the variance ``V`` dead reckoning has
added since the fixes: the recursion of :mod:`auvplan.navigation._prediction_kernel` applied
move by move), the distance travelled
[m] and the peak radial error after the settling distance. Its bin is
``min(⌊σ / Δσ⌋, n_bins − 1)`` with :math:`\sigma = \sqrt{\operatorname{tr} P}`.

Labels are popped from a heap in order of ``key``: ``g + h`` (cost mode, A* with the
consistent heuristic ``h`` of :mod:`auvplan.planning._kernel`), or the peak error (bottleneck
mode, ties broken by ``g``). Either key is non-decreasing along a path and equal heuristics
at one cell make the pop order at a cell the order of ``g`` (or of the peak), so a label
popped at a cell is dominated — and skipped — when a label of a lower or equal bin was popped
there before (``closed[cell]`` keeps the lowest closed bin). A label is thus expanded only if
it is better in error than every cheaper label at its cell: at most ``n_bins`` per cell.
After the settling distance a move whose predicted σ exceeds ``max_error`` is not made.

Ties. Unit-cost grids have many labels of exactly equal key (routes of the same moves in
another order), and which of them pops first decides, through the bin dominance that ignores
everything but σ, which route is kept. With more than one bin the heap therefore orders labels
by the compound key

.. math:: (\text{key},\ \sigma^2,\ \text{peak},\ \text{label number})

lexicographically: among equal keys the lower σ first (the lower bin, then the lower σ within
it), then the lower peak error, then the label created first. The order is total and does not
depend on the heap's layout; the label number only ranks labels identical in cost and error.
With one bin (plain A*: no budget, no soft term) σ decides nothing and the heap compares keys
only, as a binary heap does: the shortest route is then not chosen for its σ among the equally
short ones (it is the reference the navigation budgets are measured against,
:mod:`auvplan.mission.navigation`, so it must not look more informative than an energy-only
route is).

Push-time dominance (more than one bin). A new label is not even created when a label
already queued at its cell pops before it in that order and is in no higher bin: that label
closes the cell at its bin when it pops, so the new one would be skipped. Two queued labels
per cell are kept for the comparison, the first in the pop order and the one of the lowest bin
(a reference already popped has closed the cell at its bin or lower, so it still dominates),
as records beside the cell (key, σ², peak, label number: no look-up in the label table). The
labels created keep their relative order (their numbers only lose gaps), so the labels popped
and the route found are those of the search without this pruning; it only cuts the labels and
the heap. Being total, the order also lets the heap be 4-ary (half the levels of a binary
heap, the four children of an entry side by side) without changing what pops.

A move ``u → v`` of length ℓ [m] with the move factor ``f`` (e.g. the time ratio in a
current) costs ``ℓ f (c_u + c_v) / 2 + λ ℓ (σ_u² + σ_v²) / 2`` and takes
``n = ℓ · updates_per_metre`` TAN updates: drift over ℓ, white variance ``n q`` and
information ``n (F_u + F_v) / 2``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt
from numba import njit

from auvplan._typing import FloatArray, IntArray
from auvplan.navigation._prediction_kernel import propagate

#: Columns of the label table: cost, p00, p01, p11, variance grown since the fixes, distance,
#: peak.
_G, _P00, _P01, _P11, _GROWN, _DIST, _PEAK = 0, 1, 2, 3, 4, 5, 6
#: Most labels the tables of :func:`belief_search` have room for from the start (88 B each).
_INITIAL_LABELS = 1 << 24
#: Exit codes of :func:`belief_search`.
FOUND, UNREACHABLE, TOO_MANY_LABELS = 0, 1, 2


@njit(cache=True)
def moves(
    width: int, spacing_north: float, spacing_east: float, n_moves: int
) -> tuple[IntArray, IntArray, FloatArray]:  # pragma: no cover - compiled
    """Flat offsets, the offsets of the cells each move crosses, and lengths [m].

    The 8 king moves in the order of :data:`~auvplan.planning.problem.MOVES` (crossing only
    the cell entered), then, with ``n_moves = 16``, the 8 knight moves, each crossing the two
    cells beside its segment's midpoint (both must be passable).
    """
    d_row = np.array([-1, -1, -1, 0, 0, 1, 1, 1, -2, -2, -1, -1, 1, 1, 2, 2], np.int64)
    d_col = np.array([-1, 0, 1, -1, 1, -1, 0, 1, -1, 1, -2, 2, -2, 2, -1, 1], np.int64)
    offsets = d_row[:n_moves] * width + d_col[:n_moves]
    crossed = np.empty((n_moves, 2), np.int64)
    length = np.empty(n_moves)
    for k in range(n_moves):
        length[k] = math.hypot(d_row[k] * spacing_north, d_col[k] * spacing_east)
        if k < 8:
            crossed[k, 0] = crossed[k, 1] = offsets[k]
        else:  # the cells at half the long step, beside the segment
            half_row = d_row[k] // 2 if abs(d_row[k]) == 2 else 0
            half_col = d_col[k] // 2 if abs(d_col[k]) == 2 else 0
            crossed[k, 0] = half_row * width + half_col
            crossed[k, 1] = (half_row + (d_row[k] if half_row == 0 else 0)) * width + (
                half_col + (d_col[k] if half_col == 0 else 0)
            )
    return offsets, crossed, length


@njit(cache=True)
def _grow_rows(table: FloatArray, size: int) -> FloatArray:  # pragma: no cover - compiled
    bigger = np.empty((2 * table.shape[0], table.shape[1]), table.dtype)
    bigger[:size] = table[:size]
    return bigger


@njit(cache=True)
def _grow(values: npt.NDArray[Any], size: int) -> npt.NDArray[Any]:  # pragma: no cover
    """``values`` in an array twice as long, its first ``size`` entries copied."""
    bigger = np.empty(2 * values.shape[0], values.dtype)
    bigger[:size] = values[:size]
    return bigger


@njit(cache=True)
def _before(
    key_a: float,
    variance_a: float,
    peak_a: float,
    a: float,
    key_b: float,
    variance_b: float,
    peak_b: float,
    b: float,
) -> bool:  # pragma: no cover - compiled
    """Whether label ``a`` pops before label ``b`` in the compound order (module notes)."""
    if key_a != key_b:
        return key_a < key_b
    return _tie_before(variance_a, peak_a, a, variance_b, peak_b, b)


@njit(cache=True)
def _tie_before(
    variance_a: float, peak_a: float, a: float, variance_b: float, peak_b: float, b: float
) -> bool:  # pragma: no cover - compiled
    """Whether label ``a`` pops before label ``b`` of the same key: lower σ², peak, number."""
    if variance_a != variance_b:
        return variance_a < variance_b
    if peak_a != peak_b:
        return peak_a < peak_b
    return a < b


@njit(cache=True)
def _tie_first(table: FloatArray, a: int, b: int) -> bool:  # pragma: no cover - compiled
    """:func:`_tie_before` of labels ``a`` and ``b`` read from the label ``table``."""
    return _tie_before(
        table[a, _P00] + table[a, _P11], table[a, _PEAK], a,
        table[b, _P00] + table[b, _P11], table[b, _PEAK], b,
    )  # fmt: skip


@njit(cache=True)
def _bin(sigma: float, bin_width: float, n_bins: int) -> int:  # pragma: no cover - compiled
    """Bin of σ [m]: ``min(⌊σ / Δσ⌋, n_bins − 1)``."""
    return min(int(sigma / bin_width), n_bins - 1)


@njit(cache=True)
def _dominated(
    reference: FloatArray,
    key: float,
    variance: float,
    peak: float,
    label: int,
    bin_label: int,
    bin_width: float,
    n_bins: int,
) -> bool:  # pragma: no cover - compiled
    """Whether the queued ``reference`` pops before ``label`` in no higher bin.

    ``reference`` is a cell's record ``key, σ², peak, label`` (label ``-1``: none; module
    notes: push-time dominance); the other arguments are ``label``'s.
    """
    if reference[3] < 0.0 or _bin(math.sqrt(reference[1]), bin_width, n_bins) > bin_label:
        return False
    return _before(
        reference[0], reference[1], reference[2], reference[3], key, variance, peak, label
    )  # fmt: skip


@njit(cache=True)
def _push(
    table: FloatArray,
    keys: FloatArray,
    items: IntArray,
    size: int,
    key: float,
    item: int,
    ties: bool,
    shift: int,
) -> None:  # pragma: no cover - compiled
    """Sift ``(key, item)`` up from position ``size`` of a ``2^shift``-ary heap (room for it)."""
    i = size
    while i > 0:
        parent = (i - 1) >> shift
        above = keys[parent]  # the parent pops first unless the new key is lower or tied first
        if key > above or (key == above and not (ties and _tie_first(table, item, items[parent]))):
            break
        keys[i] = keys[parent]
        items[i] = items[parent]
        i = parent
    keys[i] = key
    items[i] = item


@njit(cache=True)
def _pop(
    table: FloatArray, keys: FloatArray, items: IntArray, size: int, ties: bool, shift: int
) -> int:  # pragma: no cover - compiled
    """Remove the first entry of a heap of ``size`` and return its item.

    Entries pop in the order of their keys, ties by :func:`_tie_first` if ``ties``.
    """
    top = items[0]
    last_key = keys[size - 1]
    last_item = items[size - 1]
    n = size - 1
    i = 0
    while True:
        child = (i << shift) + 1
        if child >= n:
            break
        for other in range(child + 1, min(child + (1 << shift), n)):
            key = keys[other]
            if key < keys[child] or (
                key == keys[child] and ties and _tie_first(table, items[other], items[child])
            ):
                child = other
        key = keys[child]  # the last entry settles here unless the child pops first
        if key > last_key or (
            key == last_key and not (ties and _tie_first(table, items[child], last_item))
        ):
            break
        keys[i] = keys[child]
        items[i] = items[child]
        i = child
    if n > 0:
        keys[i] = last_key
        items[i] = last_item
    return int(top)


@njit(cache=True)
def belief_search(
    cost: FloatArray,
    width: int,
    start: int,
    goal: int,
    spacing_north: float,
    spacing_east: float,
    factor: FloatArray,
    factor_stride: int,
    n_moves: int,
    heuristic: FloatArray,
    fisher: FloatArray,
    updates_per_metre: float,
    drift_variance: float,
    process_variance: float,
    initial_variance: float,
    max_error: float,
    settle_distance: float,
    error_weight: float,
    bin_width: float,
    n_bins: int,
    bottleneck: bool,
    max_labels: int,
) -> tuple[int, IntArray, FloatArray, float, float, int]:  # pragma: no cover - compiled
    """Search from ``start`` to ``goal`` (flat cells of a grid padded by 2; module notes).

    ``cost``, ``heuristic`` ``(n_padded,)``; ``fisher`` ``(n_padded, 3)`` per update;
    ``factor`` ``(8, ·)`` with ``factor_stride`` for the king moves (knight moves only
    without factors: ``n_moves`` 8 or 16, :func:`moves`). Returns the exit code, the path's
    cells and its σ at each cell, its cost and peak error after settling, and the labels
    created.
    """
    offsets, crossed, length = moves(width, spacing_north, spacing_east, n_moves)
    n_updates = length * updates_per_metre  # TAN updates of each move
    white = n_updates * process_variance
    half_updates = 0.5 * n_updates
    closed = np.full(cost.shape[0], n_bins, np.int32)
    ties = n_bins > 1
    shift = 2 if ties else 1  # 4-ary under the total order (any heap pops in it), else binary
    # queued labels per cell for the push-time dominance, the first to pop (slot 0) and the
    # lowest bin (slot 1), as records key, σ², peak, label: kept beside the cell for locality
    references = np.full((cost.shape[0] if ties else 0, 2, 4), -1.0)
    # room for a label per cell (up to 2^24) from the start: growing by doubling copied the
    # tables again and again; the pages are only touched as labels fill them
    capacity = max(1024, min(max_labels, cost.shape[0], _INITIAL_LABELS))
    table = np.empty((capacity, 7))
    cells = np.empty(capacity, np.int64)
    parents = np.empty(capacity, np.int64)
    keys = np.empty(capacity)
    items = np.empty(capacity, np.int64)
    heap = 0
    f0 = fisher[start]
    j00 = 1.0 / initial_variance + f0[0]
    j01 = f0[1]
    j11 = 1.0 / initial_variance + f0[2]
    det = j00 * j11 - j01 * j01
    table[0, _G], table[0, _GROWN], table[0, _DIST], table[0, _PEAK] = 0.0, 0.0, 0.0, 0.0
    table[0, _P00], table[0, _P01], table[0, _P11] = j11 / det, -j01 / det, j00 / det
    cells[0], parents[0] = start, -1
    n_labels = 1
    _push(table, keys, items, heap, 0.0 if bottleneck else heuristic[start], 0, ties, shift)
    heap += 1
    found = -1
    while heap > 0:
        label = _pop(table, keys, items, heap, ties, shift)
        heap -= 1
        u = cells[label]
        row = table[label]
        sigma_u = math.sqrt(row[_P00] + row[_P11])
        bin_u = _bin(sigma_u, bin_width, n_bins)
        if bin_u >= closed[u]:
            continue
        closed[u] = bin_u
        if u == goal:
            found = label
            break
        f_u = fisher[u]
        for k in range(n_moves):
            v = u + offsets[k]
            c_v = cost[v]
            move = factor[k, v * factor_stride] if k < 8 else 1.0
            if not (math.isfinite(c_v) and math.isfinite(move)):
                continue
            if not (
                math.isfinite(cost[u + crossed[k, 0]]) and math.isfinite(cost[u + crossed[k, 1]])
            ):
                continue
            ell = length[k]
            f_v = fisher[v]
            p00, p01, p11, grown = propagate(
                row[_P00], row[_P01], row[_P11], row[_GROWN], drift_variance, ell, white[k],
                half_updates[k] * (f_u[0] + f_v[0]), half_updates[k] * (f_u[1] + f_v[1]),
                half_updates[k] * (f_u[2] + f_v[2]),
            )  # fmt: skip
            sigma_v = math.sqrt(p00 + p11)
            bin_v = _bin(sigma_v, bin_width, n_bins)
            if bin_v >= closed[v]:
                continue
            distance = row[_DIST] + ell
            peak = row[_PEAK]
            if distance > settle_distance:
                if sigma_v > max_error:
                    continue
                peak = max(peak, sigma_v)
            g = row[_G] + ell * move * 0.5 * (cost[u] + c_v)
            g += error_weight * ell * 0.5 * (sigma_u * sigma_u + sigma_v * sigma_v)
            key = peak * 1e9 + g if bottleneck else g + heuristic[v]  # non-decreasing
            variance = p00 + p11
            if ties and (
                _dominated(
                    references[v, 0], key, variance, peak, n_labels, bin_v, bin_width, n_bins
                )
                or _dominated(
                    references[v, 1], key, variance, peak, n_labels, bin_v, bin_width, n_bins
                )
            ):
                continue
            if n_labels == max_labels:
                return TOO_MANY_LABELS, np.empty(0, np.int64), np.empty(0), 0.0, 0.0, n_labels
            if n_labels == table.shape[0]:
                table = _grow_rows(table, n_labels)
                cells = _grow(cells, n_labels)
                parents = _grow(parents, n_labels)
            if heap == keys.shape[0]:
                keys = _grow(keys, heap)
                items = _grow(items, heap)
            table[n_labels, _G], table[n_labels, _DIST], table[n_labels, _PEAK] = g, distance, peak
            table[n_labels, _P00], table[n_labels, _P01], table[n_labels, _P11] = p00, p01, p11
            table[n_labels, _GROWN] = grown
            cells[n_labels], parents[n_labels] = v, label
            _push(table, keys, items, heap, key, n_labels, ties, shift)
            heap += 1
            if ties:  # not dominated: in a lower bin than the references, or pops before them
                for slot in range(2):
                    reference = references[v, slot]
                    if reference[3] < 0.0 or (
                        _before(key, variance, peak, n_labels, reference[0], reference[1],
                                reference[2], reference[3])
                        if slot == 0
                        else bin_v <= _bin(math.sqrt(reference[1]), bin_width, n_bins)
                    ):  # fmt: skip
                        reference[0], reference[1], reference[2] = key, variance, peak
                        reference[3] = n_labels
            n_labels += 1
    if found < 0:
        return UNREACHABLE, np.empty(0, np.int64), np.empty(0), 0.0, 0.0, n_labels
    n_path = 0
    label = found
    while label >= 0:
        n_path += 1
        label = parents[label]
    path = np.empty(n_path, np.int64)
    sigma = np.empty(n_path)
    label = found
    for i in range(n_path - 1, -1, -1):
        path[i] = cells[label]
        sigma[i] = math.sqrt(table[label, _P00] + table[label, _P11])
        label = parents[label]
    return FOUND, path, sigma, table[found, _G], table[found, _PEAK], n_labels
