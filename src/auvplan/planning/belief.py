r"""Belief-space pre-planning: the cheapest grid path whose predicted TAN error meets a budget.

The state of the search is a cell and the predicted position covariance of the vehicle
there (:mod:`auvplan.navigation.prediction`: dead-reckoning drift grows it, soundings of
informative seabed shrink it). Edges cost what they cost a vehicle — the crossed-edge energy
proxy ``ℓ f (c_u + c_v) / 2`` of :class:`~auvplan.planning.problem.EdgeModel` ``CROSSED``
(length [m] times the move factor, e.g. the time ratio in a current, times the cell costs,
1 for a pure energy proxy) — plus an optional soft term ``λ ∫ σ² ds`` on the predicted
radial error σ. A hard budget forbids every move after the first ``settle_distance`` metres
whose σ exceeds ``max_error``.

Moves: the 8 king moves and, without move factors, the 8 knight moves too (16-connected: a
straight line costs at most 2.7 % more than its length, against 8.2 % on 8 moves, so that
routes that turn off the axes to reach informative seabed are not charged for the grid).
Label setting with dominance (Bry & Roy's RRBT on a grid): at each cell, a label is kept
only if its σ, quantised to bins (0.5 m, or 1/16 of a larger budget), is lower than that of
every cheaper label there (:mod:`auvplan.planning._belief_kernel`). With a consistent A*
heuristic (Euclidean distance times the least cost per metre; the budget and the soft term
only add cost or remove moves) the first label to reach the goal is the cheapest path of the
quantised state space; at most ``n_bins`` labels per cell are expanded. Without a budget or
a soft term the search is plain A* (one bin).

``bottleneck=True`` instead minimises the peak σ after settling (the smallest budget any
path can meet): labels leave the heap in order of their peak.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.planning._belief_kernel import FOUND, TOO_MANY_LABELS, belief_search
from auvplan.planning.problem import MOVES, PathResult, PlanningProblem, SearchStatus

#: Bins of σ when there is no budget to bound them (σ above the last bin share it).
UNBOUNDED_BINS: Final = 160
#: Most bins of σ under a budget: the bins widen to ``max_error / MAX_BUDGET_BINS`` for large
#: budgets (σ resolved to 6 % of the budget; fewer labels per cell).
MAX_BUDGET_BINS: Final = 16
#: Width of the ring of impassable cells around the grid (knight moves jump two cells).
_PAD: Final = 2


@dataclass(frozen=True)
class BeliefModel:
    """What the search needs to predict the TAN error move by move.

    Parameters
    ----------
    fisher : ndarray of shape (n_rows, n_cols, 3)
        Per-update Fisher information ``F_nn, F_ne, F_ee`` [1/m²] of each cell
        (:func:`auvplan.navigation.prediction.fisher_map`).
    updates_per_metre : float
        TAN updates per metre travelled, ``1 / (U T)`` [1/m].
    drift_rate : float
        Growth of the per-axis error by dead-reckoning drift per metre [m/m].
    process_variance : float
        White variance the filter adds per update [m²].
    initial_sigma : float
        Per-axis error at the start [m].
    max_error : float
        Budget on the radial σ [m] after ``settle_distance`` (``inf``: none).
    settle_distance : float
        Distance [m] from the start within which the budget does not apply.
    error_weight : float
        Soft weight λ [cost per m² of σ² per metre travelled].
    bin_width : float
        Quantisation of σ [m] for dominance (at least; see :attr:`width`).
    max_labels : int
        Labels created before the search gives up (bounds the memory, 88 B per label).
    """

    fisher: FloatArray
    updates_per_metre: float
    drift_rate: float
    process_variance: float
    initial_sigma: float
    max_error: float = math.inf
    settle_distance: float = 0.0
    error_weight: float = 0.0
    bin_width: float = 0.5
    max_labels: int = 40_000_000

    def __post_init__(self) -> None:
        for name in ("updates_per_metre", "drift_rate", "process_variance", "error_weight"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise InputError(f"belief model {name} must be finite and >= 0, got {value}")
        for name in ("initial_sigma", "bin_width", "max_error"):
            if not getattr(self, name) > 0.0:
                raise InputError(f"belief model {name} must be > 0, got {getattr(self, name)}")

    @property
    def width(self) -> float:
        """Width [m] of the σ bins: ``bin_width``, or a budget's :data:`MAX_BUDGET_BINS`-th."""
        if math.isfinite(self.max_error):
            return max(self.bin_width, self.max_error / MAX_BUDGET_BINS)
        return self.bin_width

    @property
    def n_bins(self) -> int:
        """Bins of σ: up to the budget, else :data:`UNBOUNDED_BINS` (1 for plain A*)."""
        if math.isfinite(self.max_error):
            return math.ceil(self.max_error / self.width) + 1
        return UNBOUNDED_BINS if self.error_weight > 0.0 else 1


@dataclass(frozen=True)
class BeliefPath:
    """Result of :func:`search_belief`.

    The path, its predicted σ [m] at each cell, its peak σ after settling [m] and the labels
    created.
    """

    path: PathResult
    sigma: FloatArray
    peak: float
    n_labels: int


def search_belief(
    problem: PlanningProblem, model: BeliefModel, *, bottleneck: bool = False
) -> BeliefPath:
    """The cheapest path of ``problem`` under ``model``'s budget (module notes).

    ``problem.cost`` is the per-metre energy proxy of each cell (1 for length), its
    ``move_factor`` the moves' factors. ``bottleneck``: minimise the peak σ instead (the
    budget is then ignored).

    Raises
    ------
    InputError
        If the Fisher map does not match the grid, or the search would need more than
        ``model.max_labels`` labels.

    Examples
    --------
    On a featureless grid the budget-free search is the straight path:

    >>> model = BeliefModel(np.zeros((1, 5, 3)), 0.1, 0.01, 0.0, 1.0)
    >>> found = search_belief(PlanningProblem(np.ones((1, 5)), None, (0, 0), (0, 4)), model)
    >>> found.path.cells[:, 1].tolist(), round(float(found.sigma[-1]), 4)  # √(2 (1 + 0.04²))
    ([0, 1, 2, 3, 4], 1.4153)
    """
    if model.fisher.shape != (*problem.shape, 3):
        raise InputError(f"Fisher map shape {model.fisher.shape} does not match {problem.shape}")
    width = problem.shape[1] + 2 * _PAD
    cells = np.where(np.isnan(problem.cost), np.inf, problem.cost)
    if problem.blocked is not None:
        cells = np.where(problem.blocked, np.inf, cells)
    factor, stride = np.ones((len(MOVES), 1)), 0
    if problem.move_factor is not None:
        factor = _padded(
            np.where(np.isnan(problem.move_factor), np.inf, problem.move_factor), np.inf
        )
        factor, stride = factor.reshape(len(MOVES), -1), 1
    start = (problem.start[0] + _PAD) * width + problem.start[1] + _PAD
    goal = (problem.goal[0] + _PAD) * width + problem.goal[1] + _PAD
    code, flat, sigma, cost, peak, n_labels = belief_search(
        _padded(cells, np.inf).ravel(), width, start, goal,
        float(problem.spacing_north), float(problem.spacing_east), factor, stride,
        len(MOVES) if stride else 2 * len(MOVES), _heuristic(problem).ravel(),
        _padded_fisher(model.fisher),
        model.updates_per_metre, model.drift_rate**2, model.process_variance,
        model.initial_sigma**2, math.inf if bottleneck else model.max_error,
        model.settle_distance, model.error_weight,
        model.bin_width if bottleneck else model.width,
        UNBOUNDED_BINS if bottleneck else model.n_bins, bottleneck, model.max_labels,
    )  # fmt: skip
    if code == TOO_MANY_LABELS:
        raise InputError(
            f"the navigation search needs more than {model.max_labels} labels; use a coarser "
            "grid (maps.block) or a looser navigation budget"
        )
    if code != FOUND:
        result = PathResult(
            np.empty((0, 2), np.int64), math.inf, SearchStatus.UNREACHABLE,
            f"no path from {problem.start} to {problem.goal} meets the navigation budget "
            f"({n_labels} labels)", n_labels,
        )  # fmt: skip
        return BeliefPath(result, np.empty(0), math.inf, int(n_labels))
    rows, cols = np.divmod(flat, width)
    path = np.column_stack((rows - _PAD, cols - _PAD)).astype(np.int64)
    result = PathResult(
        path, float(cost), SearchStatus.EXACT,
        f"path of {len(path)} cells, cost {cost:.6g}, predicted error {sigma[-1]:.2f} m at "
        f"the goal, peak {peak:.2f} m ({n_labels} labels)", int(n_labels),
    )  # fmt: skip
    return BeliefPath(result, sigma, float(peak), int(n_labels))


def _padded(values: FloatArray, fill: float) -> FloatArray:
    """``values`` ``(..., n_rows, n_cols)`` in a ring of :data:`_PAD` cells of ``fill``."""
    padding = [(0, 0)] * (values.ndim - 2) + [(_PAD, _PAD), (_PAD, _PAD)]
    return np.pad(values, padding, constant_values=fill)


def _padded_fisher(fisher: FloatArray) -> FloatArray:
    """``fisher`` ``(n_rows, n_cols, 3)`` in a ring of :data:`_PAD` zero cells, flat per cell."""
    rows, cols, _ = fisher.shape
    padded = np.zeros((rows + 2 * _PAD, cols + 2 * _PAD, 3))
    padded[_PAD:-_PAD, _PAD:-_PAD] = fisher
    return padded.reshape(-1, 3)


def _heuristic(problem: PlanningProblem) -> FloatArray:
    """Euclidean distance to the goal [m] times the least cost per metre of any move.

    A lower bound of every path's cost whatever the move set (king or knight moves), and
    consistent: a move of length ℓ costs at least ``c_min f_min ℓ`` and changes the distance
    by at most ℓ. Evaluated on the padded grid (the ring's cells are impassable: never read).
    """
    passable = np.isfinite(problem.cost) & problem.passable
    rate = float(np.min(problem.cost[passable])) if np.any(passable) else 0.0
    if problem.move_factor is not None:
        factors = problem.move_factor[np.isfinite(problem.move_factor)]
        rate *= float(np.min(factors)) if factors.size else 0.0
    rows, cols = problem.shape
    north = (np.arange(-_PAD, rows + _PAD) - problem.goal[0]) * problem.spacing_north
    east = (np.arange(-_PAD, cols + _PAD) - problem.goal[1]) * problem.spacing_east
    distance = np.hypot(north[:, None], east[None, :])
    distance *= rate
    return np.asarray(distance, np.float64)
