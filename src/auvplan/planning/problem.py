r"""Grid search problem and result types of the A* pre-planner (paper Sec. III, stage 1).

A :class:`PlanningProblem` is a cost grid (the shifted cost map :math:`\tilde M_C = \omega +
w M_C` of SPEC §1, one value per cell, non-finite = impassable), an optional boolean mask of
blocked cells (obstacles), and a start and goal cell. The graph is the 8-connected grid; the
weight of an edge is fixed by the :class:`EdgeModel`:

``EdgeModel.PAPER``
    moving from cell :math:`u` into a neighbour :math:`v` costs :math:`c_v`, for straight and
    diagonal moves alike (the paper's model). The start cell's cost is never paid.
``EdgeModel.CROSSED``
    the edge between two neighbouring cell centres costs its length in metres times the mean
    cost of the two cells it crosses, :math:`\ell_{uv} (c_u + c_v) / 2`, with
    :math:`\ell = \Delta_{north}`, :math:`\Delta_{east}` or
    :math:`\sqrt{\Delta_{north}^2 + \Delta_{east}^2}` (scikit-image's ``MCP_Geometric``).

An optional ``move_factor`` of shape ``(8, n_rows, n_cols)`` multiplies the weight of the move
:data:`MOVES` ``[k]`` into each cell (e.g. the ratio ``U_w / s`` of through-water to ground
speed in a current; ``inf`` or NaN: that move cannot be made).

Diagonal moves are allowed whenever the cell entered is passable, whatever its two orthogonal
neighbours are (no corner-cutting rule, as in scikit-image's MCP and pyastar2d). Obstacles are
rasterised with a clearance (:func:`auvplan.planning.obstacles.obstacle_mask`) so that a
diagonal squeeze between two blocked cells still keeps that clearance from the obstacle.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Final

import numpy as np

from auvplan._typing import BoolArray, FloatArray, IntArray
from auvplan.errors import InputError

#: The 8 moves ``(d_row, d_col)`` of the grid graph, in the order of ``move_factor``.
MOVES: Final = ((-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1))


class EdgeModel(enum.Enum):
    """Edge weight of the 8-connected grid graph (see the module docstring)."""

    PAPER = "paper"
    CROSSED = "crossed"


class SearchStatus(enum.Enum):
    """Outcome of a grid search (in the manner of OMPL's ``PlannerStatus``).

    ``EXACT``: an optimal path to the goal was found. ``UNREACHABLE``: no path exists.
    ``INVALID_START`` / ``INVALID_GOAL``: the endpoint is outside the grid or impassable; these
    are reported by callers that check endpoints per vehicle before building a
    :class:`PlanningProblem` (whose constructor raises :class:`~auvplan.errors.InputError`).
    """

    EXACT = "exact"
    UNREACHABLE = "unreachable"
    INVALID_START = "invalid start"
    INVALID_GOAL = "invalid goal"


@dataclass(frozen=True)
class PlanningProblem:
    """A start-to-goal search on an 8-connected cost grid.

    Parameters
    ----------
    cost : ndarray of shape (n_rows, n_cols)
        Cost per cell (dimensionless for ``EdgeModel.PAPER``; per metre for
        ``EdgeModel.CROSSED``), ``> 0`` where finite. NaN or inf marks an impassable cell.
    blocked : ndarray of bool, shape (n_rows, n_cols), or None
        Extra impassable cells (obstacles), or ``None`` for none.
    start, goal : tuple of int
        ``(row, col)`` of the start and goal cells; both must be in bounds and passable.
    spacing_north, spacing_east : float
        Cell spacing [m] (used by ``EdgeModel.CROSSED`` only), both ``> 0``.
    move_factor : ndarray of shape (8, n_rows, n_cols), or None
        Factor of the weight of move ``MOVES[k]`` into each cell, ``> 0`` (inf or NaN: the
        move is impossible); ``None``: 1 everywhere.

    Raises
    ------
    InputError
        On a malformed cost array, a non-positive finite cost, a mask of the wrong shape, or a
        start/goal outside the grid or on an impassable cell (the message names which).

    Examples
    --------
    >>> problem = PlanningProblem(np.ones((3, 4)), None, (0, 0), (2, 3))
    >>> problem.shape
    (3, 4)
    >>> int(problem.passable.sum())
    12
    """

    cost: FloatArray
    blocked: BoolArray | None
    start: tuple[int, int]
    goal: tuple[int, int]
    spacing_north: float = 1.0
    spacing_east: float = 1.0
    move_factor: FloatArray | None = None

    def __post_init__(self) -> None:
        cost = self.cost
        if not isinstance(cost, np.ndarray) or cost.ndim != 2 or cost.size == 0:
            raise InputError(f"cost must be a non-empty 2-D array, got shape {np.shape(cost)}")
        if cost.dtype != np.float64:
            raise InputError(f"cost must have dtype float64, got {cost.dtype}")
        if np.any(cost <= 0.0):  # NaN compares false; -inf is rejected
            raise InputError(
                f"cost must be > 0, NaN or +inf, got minimum {float(np.nanmin(cost))!r}"
            )
        if self.blocked is not None and (
            not isinstance(self.blocked, np.ndarray)
            or self.blocked.dtype != np.bool_
            or self.blocked.shape != cost.shape
        ):
            raise InputError(
                f"blocked must be a bool array of shape {cost.shape}, got "
                f"{getattr(self.blocked, 'dtype', type(self.blocked))} "
                f"of shape {np.shape(self.blocked)}"
            )
        if not (self.spacing_north > 0.0 and self.spacing_east > 0.0):
            raise InputError(
                f"spacing must be > 0, got {self.spacing_north!r} x {self.spacing_east!r} m"
            )
        factor = self.move_factor
        if factor is not None and (
            not isinstance(factor, np.ndarray)
            or factor.dtype != np.float64
            or factor.shape != (len(MOVES), *cost.shape)
        ):
            raise InputError(
                f"move_factor must be a float64 array of shape {(len(MOVES), *cost.shape)}, "
                f"got {getattr(factor, 'dtype', type(factor))} of shape {np.shape(factor)}"
            )
        if factor is not None and np.any(factor <= 0.0):
            raise InputError(f"move_factor must be > 0, got minimum {float(np.nanmin(factor))!r}")
        for name, cell in (("start", self.start), ("goal", self.goal)):
            row, col = int(cell[0]), int(cell[1])
            if not (0 <= row < cost.shape[0] and 0 <= col < cost.shape[1]):
                raise InputError(f"{name} cell {cell} is outside the {cost.shape} grid")
            is_blocked = self.blocked is not None and bool(self.blocked[row, col])
            if is_blocked or not np.isfinite(cost[row, col]):
                raise InputError(f"{name} cell {cell} is impassable (non-finite cost or blocked)")

    @property
    def shape(self) -> tuple[int, int]:
        """``(n_rows, n_cols)`` of the grid."""
        return (int(self.cost.shape[0]), int(self.cost.shape[1]))

    @property
    def passable(self) -> BoolArray:
        """Boolean mask of passable cells: finite cost and not blocked."""
        passable = np.isfinite(self.cost)
        if self.blocked is not None:
            passable &= ~self.blocked
        return np.asarray(passable, dtype=np.bool_)


@dataclass(frozen=True)
class PathResult:
    """Result of :func:`auvplan.planning.plan_astar`.

    Parameters
    ----------
    cells : ndarray of int64, shape (n_cells, 2)
        ``[row, col]`` of the path from start to goal (8-connected); shape ``(0, 2)`` when no
        path exists.
    cost : float
        Graph cost of the path (sum of its edge weights); ``inf`` when no path exists.
    status : SearchStatus
        ``EXACT`` or ``UNREACHABLE``.
    message : str
        Human-readable outcome.
    n_expanded : int
        Number of cells expanded (closed) by the search.
    """

    cells: IntArray
    cost: float
    status: SearchStatus
    message: str
    n_expanded: int

    @property
    def success(self) -> bool:
        """True when an optimal path was found."""
        return self.status is SearchStatus.EXACT
