r"""Optimal 8-neighbour A* on a cost grid: the hot loop of the pre-planner (paper Sec. III).

Both edge models of :class:`~auvplan.planning.problem.EdgeModel` return the true optimum of
their graph, because their heuristics are admissible and consistent:

``PAPER``
    :math:`h(v) = c_{min} \cdot \max(|r_v - r_g|, |c_v - c_g|)`, the minimum passable cell cost
    times the Chebyshev distance in cells. Every move changes the Chebyshev distance by at most
    one and costs at least :math:`c_{min}`, so :math:`h(u) \le w(u, v) + h(v)` (consistent) and
    :math:`h(g) = 0`. The paper uses the Euclidean distance in cells, which is admissible only
    when every cost is :math:`\ge \sqrt 2` (hence its :math:`\omega \ge \sqrt 2`); our
    heuristic needs no such condition and is tighter for :math:`\omega \ge \sqrt 2`
    (:math:`c_{min} \max(a, b) \ge \sqrt 2 \max(a, b) \ge \sqrt{a^2 + b^2}`), so A* expands
    fewer cells.
``CROSSED``
    :math:`h(v) = c_{min} \cdot L_{oct}(v, g)` with the octile distance in metres on the
    (possibly anisotropic) grid, :math:`L_{oct} = k \ell_d + (a - k)\Delta_n + (b - k)\Delta_e`,
    :math:`k = \min(a, b)`, :math:`\ell_d = \sqrt{\Delta_n^2 + \Delta_e^2}`. :math:`L_{oct}`
    is the exact shortest-path length of the 8-connected grid, a metric on it, and every edge
    costs at least :math:`c_{min}` times its length, so the heuristic is consistent; it is at
    least the issue's :math:`c_{min} \cdot` Euclidean distance.

Speed: the open list is a bucket queue (Dial's algorithm with Dinitz's rule, see
:mod:`auvplan.planning._kernel`) with O(1) pushes and pops. It is exact when the heuristic is
scaled by :math:`\alpha < 1` (every reduced edge weight is then at least
:math:`(1 - \alpha) c_{min} \ell_{min}`, the bucket width). We use :math:`\alpha = 0.9`
(paper) and :math:`0.75` (crossed), lowered when the cost range would need more than
:data:`MAX_BUCKETS` buckets; when even :math:`\alpha = 0` (Dijkstra) would, a binary heap
with the full heuristic (:math:`\alpha = 1`) is used. The choice changes the number of cells
expanded (and which of several equally cheap paths is returned), never the optimal cost.
The kernels are compiled by numba and cached on disk; the first call in a fresh environment
compiles them (a few seconds).
"""

from __future__ import annotations

from typing import Final, Literal

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.planning._kernel import astar_buckets, astar_heap, finite_range, heuristic_grid
from auvplan.planning.problem import MOVES, EdgeModel, PathResult, PlanningProblem, SearchStatus

#: Largest number of buckets of the bucket queue before falling back to the binary heap.
MAX_BUCKETS: Final = 256
#: Heuristic scale for the bucket queue per edge model (tuned on terrain cost maps).
_ALPHA: Final = {EdgeModel.PAPER: 0.9, EdgeModel.CROSSED: 0.75}
#: Relative safety margin on the bucket width against rounding in ``f = g + h``.
_WIDTH_MARGIN: Final = 1e-9


def plan_astar(problem: PlanningProblem, *, edge_model: EdgeModel = EdgeModel.PAPER) -> PathResult:
    r"""Find an optimal 8-connected path from ``problem.start`` to ``problem.goal``.

    Parameters
    ----------
    problem : PlanningProblem
        Cost grid, blocked cells, start and goal (validated on construction).
    edge_model : EdgeModel
        ``PAPER`` (cost of the cell entered) or ``CROSSED`` (edge length [m] times the mean of
        the two cells' costs).

    Returns
    -------
    PathResult
        ``cells`` ``(n, 2)`` ``[row, col]`` from start to goal, the path's graph cost and
        ``SearchStatus.EXACT``; or an empty path, ``inf`` and ``SearchStatus.UNREACHABLE``.

    Notes
    -----
    Graph cost of a path :math:`v_0 \dots v_n` is :math:`\sum_{i=1}^{n} c_{v_i}` (paper) or
    :math:`\sum_{i=1}^{n} \ell_{v_{i-1} v_i} (c_{v_{i-1}} + c_{v_i}) / 2` (crossed).

    Examples
    --------
    >>> cost = np.ones((3, 4))
    >>> cost[1, 1:3] = np.nan
    >>> result = plan_astar(PlanningProblem(cost, None, (1, 0), (1, 3)))
    >>> result.status.name, result.cost
    ('EXACT', 3.0)
    >>> result.cells.tolist()
    [[1, 0], [0, 1], [0, 2], [1, 3]]
    """
    return search_grid(problem, edge_model=edge_model, queue="auto")


def heuristic_map(problem: PlanningProblem, *, edge_model: EdgeModel) -> FloatArray:
    r"""The admissible, consistent A* heuristic at every cell (full strength, :math:`\alpha = 1`).

    Parameters
    ----------
    problem : PlanningProblem
        Grid and goal; :math:`c_{min}` is the smallest cost of a passable cell (times the
        smallest move factor, if any).
    edge_model : EdgeModel
        ``PAPER``: :math:`c_{min}` times the Chebyshev distance to the goal in cells.
        ``CROSSED``: :math:`c_{min}` times the octile distance to the goal in metres.

    Returns
    -------
    ndarray of shape (n_rows, n_cols)
        Lower bound of the cost-to-go (dimensionless graph cost). The kernels use
        :math:`\alpha` times this map (see the module docstring).

    Examples
    --------
    >>> problem = PlanningProblem(np.full((2, 3), 2.0), None, (0, 0), (1, 2))
    >>> heuristic_map(problem, edge_model=EdgeModel.PAPER)
    array([[4., 2., 2.],
           [4., 2., 0.]])
    """
    cost_min, _ = finite_range(np.where(problem.passable, problem.cost, np.inf).ravel())
    if problem.move_factor is not None:
        cost_min *= finite_range(_padded_factor(problem)[0].ravel())[0]
    n_rows, n_cols = problem.shape
    return heuristic_grid(
        n_rows,
        n_cols,
        int(problem.goal[0]),
        int(problem.goal[1]),
        edge_model is EdgeModel.CROSSED,
        cost_min,
        float(problem.spacing_north),
        float(problem.spacing_east),
    )


def search_grid(
    problem: PlanningProblem,
    *,
    edge_model: EdgeModel,
    queue: Literal["auto", "buckets", "heap"],
) -> PathResult:
    """:func:`plan_astar` with an explicit open-list choice (for tests and benchmarks).

    ``"buckets"`` raises :class:`~auvplan.errors.InputError` when the cost range needs more
    than :data:`MAX_BUCKETS` buckets even for Dijkstra (``alpha = 0``).
    """
    if not isinstance(edge_model, EdgeModel):
        raise InputError(f"edge_model must be an EdgeModel, got {edge_model!r}")
    if queue not in ("auto", "buckets", "heap"):
        raise InputError(f"queue must be 'auto', 'buckets' or 'heap', got {queue!r}")
    n_rows, n_cols = problem.shape
    if (n_rows + 2) * (n_cols + 2) >= 2**31 - 1:
        raise InputError(f"grid {n_rows} x {n_cols} is too large (more than 2**31 cells)")
    padded = _padded_cost(problem)
    factor, factor_stride = _padded_factor(problem)
    factor_min, factor_max = finite_range(factor.ravel())
    width = n_cols + 2
    start = (problem.start[0] + 1) * width + problem.start[1] + 1
    goal = (problem.goal[0] + 1) * width + problem.goal[1] + 1
    cost_min, cost_max = finite_range(padded.ravel())
    if factor_min < np.inf:  # edge weights range over [c_min f_min, c_max f_max]
        cost_min, cost_max = cost_min * factor_min, cost_max * factor_max
    crossed = edge_model is EdgeModel.CROSSED
    spacing_north, spacing_east = float(problem.spacing_north), float(problem.spacing_east)
    layout = (
        None
        if queue == "heap"
        else _bucket_layout(cost_min, cost_max, edge_model, spacing_north, spacing_east)
    )
    if layout is None and queue == "buckets":
        raise InputError(
            f"cost range [{cost_min:g}, {cost_max:g}] needs more than {MAX_BUCKETS} buckets"
        )
    if layout is None:
        path, cost, n_expanded = astar_heap(
            padded.ravel(), width, start, goal, crossed, spacing_north, spacing_east, cost_min,
            factor, factor_stride,
        )  # fmt: skip
    else:
        alpha, n_buckets, bucket_width = layout
        path, cost, n_expanded = astar_buckets(
            padded.ravel(),
            width,
            start,
            goal,
            crossed,
            spacing_north,
            spacing_east,
            alpha * cost_min,
            factor,
            factor_stride,
            n_buckets,
            bucket_width,
        )
    if path.size == 0:
        return PathResult(
            np.empty((0, 2), np.int64),
            float("inf"),
            SearchStatus.UNREACHABLE,
            f"goal {problem.goal} is unreachable from start {problem.start} "
            f"({n_expanded} cells expanded)",
            int(n_expanded),
        )
    rows, cols = np.divmod(path, width)
    cells = np.column_stack((rows - 1, cols - 1)).astype(np.int64)
    return PathResult(
        cells,
        float(cost),
        SearchStatus.EXACT,
        f"optimal path of {len(cells)} cells, cost {float(cost):.6g} "
        f"({n_expanded} of {n_rows * n_cols} cells expanded)",
        int(n_expanded),
    )


def _bucket_layout(
    cost_min: float,
    cost_max: float,
    edge_model: EdgeModel,
    spacing_north: float,
    spacing_east: float,
) -> tuple[float, int, float] | None:
    r"""``(alpha, n_buckets, width)`` of the bucket queue, or ``None`` if too many buckets.

    Width :math:`\Delta = (1 - \alpha) c_{min} \ell_{min}` (shrunk by a relative
    :data:`_WIDTH_MARGIN`), count :math:`\lceil \ell_{max} (c_{max} + \alpha c_{min}) /
    \Delta \rceil + 2`.
    """
    if edge_model is EdgeModel.CROSSED:
        length_min = min(spacing_north, spacing_east)
        length_max = float(np.hypot(spacing_north, spacing_east))
    else:
        length_min = length_max = 1.0
    for alpha in (_ALPHA[edge_model], 0.5, 0.0):
        width = (1.0 - alpha) * cost_min * length_min * (1.0 - _WIDTH_MARGIN)
        n_buckets = int(np.ceil(length_max * (cost_max + alpha * cost_min) / width)) + 2
        if n_buckets <= MAX_BUCKETS:
            return alpha, n_buckets, width
    return None


def _padded_factor(problem: PlanningProblem) -> tuple[FloatArray, int]:
    """Move factors ``(8, n_padded)`` with NaN as ``inf``, and their stride (module notes).

    Without factors: a ``(8, 1)`` array of ones and stride 0.
    """
    if problem.move_factor is None:
        return np.ones((len(MOVES), 1)), 0
    n_rows, n_cols = problem.shape
    padded = np.full((len(MOVES), n_rows + 2, n_cols + 2), np.inf)
    padded[:, 1:-1, 1:-1] = np.where(np.isnan(problem.move_factor), np.inf, problem.move_factor)
    return padded.reshape(len(MOVES), -1), 1


def _padded_cost(problem: PlanningProblem) -> FloatArray:
    """Cost grid with a one-cell ring of ``inf``; blocked cells become ``inf`` (NaN stays)."""
    n_rows, n_cols = problem.shape
    padded = np.full((n_rows + 2, n_cols + 2), np.inf)
    inner = padded[1:-1, 1:-1]
    inner[...] = problem.cost
    if problem.blocked is not None:
        np.copyto(inner, np.inf, where=problem.blocked)
    return padded
