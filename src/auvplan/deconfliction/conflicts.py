r"""Pairwise collision sets on the 2-D coordination grids, and what timing cannot solve.

For a pair ``(i, j)`` the grid node ``(k_i, k_j)`` is *forbidden* when

.. math::

    \lVert p_i(s(k_i)) - p_j(s(k_j)) \rVert \le 2 r_c + \delta_{ij}, \qquad
    \delta_{ij} = \tfrac12 (h_i + h_j),

with ``h_i = v_i dt`` the per-step motion. The inflation ``δ_ij`` is what makes grid
schedules safe *between* samples: if a vehicle moves at most ``h`` along its path during a
step, the distance of a pair during a step from node ``a`` to node ``b`` is at least
``(d_a + d_b - h_i - h_j) / 2 >= 2 r_c`` (see :func:`auvplan.deconfliction.certify_separation`).

The forbidden set is stored per row ``k_i`` as sorted intervals of ``k_j`` (never as a dense
bitmap), so a 6000 × 6000 pair grid costs a few kilobytes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from auvplan._typing import FloatArray, IntArray
from auvplan.deconfliction._budget import MAX_HEURISTIC_CELLS
from auvplan.deconfliction._conflict_kernels import (
    pair_cost_to_go,
    pair_intervals,
    pair_reachability,
    shadow_cells,
)
from auvplan.deconfliction.problem import CoordinationProblem
from auvplan.errors import InfeasibleError

#: Relative widening of the inflated radius, so floating-point rounding stays conservative.
RADIUS_ROUNDING = 1e-9


@dataclass(frozen=True, eq=False)
class ConflictTable:
    """Forbidden ``k_j`` intervals for ordered pairs ``(i, j)``, rows indexed by ``k_i``.

    Parameters
    ----------
    n_vehicles : int
        Number of vehicles.
    pair_base : ndarray of shape (n_vehicles ** 2,)
        Offset of pair ``(i, j)``'s rows in ``row_ptr`` (index ``i * n_vehicles + j``);
        ``-1`` when the pair was not built.
    row_ptr : ndarray
        Concatenated CSR row pointers (absolute offsets into ``lo`` and ``hi``).
    lo, hi : ndarray
        Inclusive bounds of the forbidden intervals.
    radius : ndarray of shape (n_vehicles, n_vehicles)
        Inflated forbidden radius ``2 r_c + δ_ij`` [m] of each pair.
    """

    n_vehicles: int
    pair_base: IntArray
    row_ptr: IntArray
    lo: IntArray
    hi: IntArray
    radius: FloatArray

    def forbidden(self, i: int, j: int, k_i: int) -> list[tuple[int, int]]:
        """Forbidden ``k_j`` intervals of row ``k_i`` of pair ``(i, j)`` (inclusive)."""
        base = int(self.pair_base[i * self.n_vehicles + j])
        if base < 0:
            raise KeyError(f"pair ({i}, {j}) not in this table")
        first, stop = self.row_ptr[base + k_i], self.row_ptr[base + k_i + 1]
        pairs = zip(self.lo[first:stop], self.hi[first:stop], strict=True)
        return [(int(a), int(b)) for a, b in pairs]


def inflated_radius(problem: CoordinationProblem, i: int, j: int) -> float:
    """Forbidden radius ``2 r_c + (h_i + h_j)/2`` [m] of pair ``(i, j)`` on the grid."""
    step = problem.step_lengths
    return float((problem.separation + 0.5 * (step[i] + step[j])) * (1.0 + RADIUS_ROUNDING))


def build_conflict_table(
    problem: CoordinationProblem, *, ordered_pairs: tuple[tuple[int, int], ...] | None = None
) -> ConflictTable:
    """Compute the forbidden intervals of the given ordered pairs (default: every ``i != j``).

    Parameters
    ----------
    problem : CoordinationProblem
        The paths and grid.
    ordered_pairs : tuple of (int, int), optional
        Pairs ``(i, j)`` whose rows (indexed by ``k_i``) are needed.

    Returns
    -------
    ConflictTable
    """
    n = problem.n_vehicles
    if ordered_pairs is None:
        ordered_pairs = tuple((i, j) for i in range(n) for j in range(n) if i != j)
    points = [problem.grid_points(i) for i in range(n)]
    pair_base = np.full(n * n, -1, dtype=np.int64)
    radius = np.zeros((n, n))
    ptr_parts: list[IntArray] = []
    lo_parts: list[IntArray] = []
    hi_parts: list[IntArray] = []
    n_rows_so_far = 0
    n_intervals_so_far = 0
    for i, j in ordered_pairs:
        radius[i, j] = inflated_radius(problem, i, j)
        row_ptr, lo, hi = pair_intervals(
            points[i],
            problem.paths[j],
            problem.arc_lengths[j],
            float(problem.step_lengths[j]),
            int(problem.n_steps[j]),
            float(radius[i, j]),
        )
        pair_base[i * n + j] = n_rows_so_far
        ptr_parts.append(row_ptr + n_intervals_so_far)
        lo_parts.append(lo)
        hi_parts.append(hi)
        n_rows_so_far += row_ptr.shape[0]
        n_intervals_so_far += lo.shape[0]
    empty = np.zeros(0, dtype=np.int64)
    return ConflictTable(
        n_vehicles=n,
        pair_base=pair_base,
        row_ptr=np.concatenate(ptr_parts) if ptr_parts else empty,
        lo=np.concatenate(lo_parts) if lo_parts else empty,
        hi=np.concatenate(hi_parts) if hi_parts else empty,
        radius=radius,
    )


def _where(problem: CoordinationProblem, vehicle: int, k: int) -> str:
    n_k = int(problem.n_steps[vehicle])
    point = problem.grid_points(vehicle)[min(max(k, 0), n_k)]
    label = "start" if k <= 0 else "goal" if k >= n_k else "path"
    place = f"({point[0]:.1f}, {point[1]:.1f}) m"
    return f"vehicle {problem.label(vehicle)}'s {label} at (north, east) = {place}"


def check_endpoints(problem: CoordinationProblem) -> None:
    """Raise if two starts or two goals are closer than ``2 r_c`` (no timing can help).

    Raises
    ------
    InfeasibleError
        Naming the pair and the places.
    """
    check_endpoint_clearance(
        tuple(problem.label(i) for i in range(problem.n_vehicles)),
        np.array([path[0] for path in problem.paths]),
        np.array([path[-1] for path in problem.paths]),
        problem.separation,
    )


def check_endpoint_clearance(
    names: tuple[str, ...], starts: FloatArray, goals: FloatArray, separation: float
) -> None:
    """Raise if two starts (or two goals) are closer than ``separation`` [m].

    ``starts`` and ``goals`` have shape ``(n, 2)``: north/east [m].

    Raises
    ------
    InfeasibleError
        Naming the pair and the places.
    """
    for label, points in (("start", starts), ("goal", goals)):
        for i in range(len(names)):
            for j in range(i + 1, len(names)):
                distance = float(np.hypot(*(points[i] - points[j])))
                if distance < separation:
                    raise InfeasibleError(
                        f"vehicles {names[i]} and {names[j]} both "
                        f"{'begin' if label == 'start' else 'end'} "
                        f"within 2 r_c = {separation:g} m of each other: "
                        f"{label}s at (north, east) = ({points[i][0]:.1f}, {points[i][1]:.1f}) "
                        f"and ({points[j][0]:.1f}, {points[j][1]:.1f}) m, {distance:.2f} m apart"
                    )


def check_pairwise_timing(problem: CoordinationProblem, table: ConflictTable) -> None:
    """Raise if some pair alone cannot be timed apart on the grid.

    A monotone path from ``(0, 0)`` to ``(n_i, n_j)`` through the free 2-D grid of each pair
    is necessary for any N-vehicle schedule. It fails typically when a vehicle's start lies
    within ``2 r_c`` of the other's path before the point the other must pass, or a goal on
    the other's path after it (the vehicle would have to wait there forever).

    Raises
    ------
    InfeasibleError
        Naming the pair and the two places where they get stuck.
    """
    n = problem.n_vehicles
    for i in range(n):
        for j in range(i + 1, n):
            base = int(table.pair_base[i * n + j])
            n_i = int(problem.n_steps[i])
            n_j = int(problem.n_steps[j])
            row_ptr = table.row_ptr[base : base + n_i + 2]
            reachable, row, col = pair_reachability(row_ptr, table.lo, table.hi, n_i, n_j)
            if not reachable:
                raise InfeasibleError(
                    f"vehicles {problem.label(i)} and {problem.label(j)} cannot be separated "
                    "by timing: "
                    f"{_where(problem, i, row)} and {_where(problem, j, col)} are within "
                    f"2 r_c = {problem.separation:g} m (plus grid margin "
                    f"{table.radius[i, j] - problem.separation:.3g} m) on every schedule"
                )


@dataclass(frozen=True, eq=False)
class PairHeuristic:
    """Exact makespan-to-go of every pair ``i < j`` alone, as an excess over the free bound.

    The free bound is ``max(n_i - k_i, n_j - k_j)``; rows are stored from their first to
    their last non-zero excess.

    Parameters
    ----------
    pair_base : ndarray of shape (n_vehicles ** 2,)
        Offset of pair ``(i, j)``'s rows in the row arrays; ``-1`` when the pair never
        interacts (its free bound is exact).
    row_first : ndarray
        First stored column ``k_j`` of each row.
    row_start : ndarray
        Position of each row's first value in ``excess``.
    row_len : ndarray
        Number of stored values of each row.
    excess : ndarray of uint16
        Excess values [time steps], capped at ``EXCESS_CAP``; ``DEAD_END`` marks nodes from
        which the pair cannot reach its goals.
    """

    pair_base: IntArray
    row_first: IntArray
    row_start: IntArray
    row_len: IntArray
    excess: npt.NDArray[np.uint16]


def build_pair_heuristic(
    problem: CoordinationProblem, table: ConflictTable, *, max_cells: int = MAX_HEURISTIC_CELLS
) -> PairHeuristic | None:
    """Backward dynamic programme on every pair's 2-D grid (see ``pair_cost_to_go``).

    Returns None when the pairs need more than ``max_cells`` cells together (the budget of
    :mod:`auvplan.deconfliction._budget`): estimated before anything is allocated (cells in
    the diagonal shadow of the forbidden sets, :func:`shadow_cells`), and enforced while
    computing (the programme stops at the budget).
    """
    n = problem.n_vehicles
    pairs = [(i, j) for i in range(n) for j in range(i + 1, n)]
    rows_of = {
        (i, j): table.row_ptr[table.pair_base[i * n + j] :][: int(problem.n_steps[i]) + 2]
        for i, j in pairs
    }
    estimate = sum(
        shadow_cells(rows_of[i, j], table.lo, table.hi, problem.n_steps[i], problem.n_steps[j])
        for i, j in pairs
    )
    if estimate > max_cells:
        return None
    base = np.full(n * n, -1, dtype=np.int64)
    firsts: list[IntArray] = []
    starts: list[IntArray] = []
    lengths: list[IntArray] = []
    values = np.empty(1 << 20, dtype=np.uint16)
    count = 0
    n_rows = 0
    for i, j in pairs:
        before = count
        first, start, length, values, count, n_cells = pair_cost_to_go(
            rows_of[i, j],
            table.lo,
            table.hi,
            int(problem.n_steps[i]),
            int(problem.n_steps[j]),
            values,
            count,
            max_cells,
        )
        max_cells -= n_cells
        if max_cells < 0:
            return None
        if count == before:
            continue  # the pair never interacts: the individual bound is exact
        base[i * n + j] = n_rows
        firsts.append(first)
        starts.append(start)
        lengths.append(length)
        n_rows += int(problem.n_steps[i]) + 1
    empty = np.zeros(0, dtype=np.int64)
    return PairHeuristic(
        pair_base=base,
        row_first=np.concatenate(firsts) if firsts else empty,
        row_start=np.concatenate(starts) if starts else empty,
        row_len=np.concatenate(lengths) if lengths else empty,
        excess=values[:count],
    )
