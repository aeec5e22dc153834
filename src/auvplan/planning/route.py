"""World-level pre-planning of one vehicle's route on a cost map (paper Sec. III, stage 1).

:func:`plan_route` takes world coordinates (north/east in metres), checks them, rasterises the
obstacles, runs :func:`~auvplan.planning.astar.plan_astar` and returns the optimal grid path
both as cells of the cost grid and as world points.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from auvplan._typing import BoolArray, FloatArray, IntArray
from auvplan.errors import InfeasibleError, InputError
from auvplan.planning.astar import plan_astar
from auvplan.planning.belief import BeliefModel, search_belief
from auvplan.planning.obstacles import (
    Obstacle,
    OperatingArea,
    distance_to_obstacle,
    obstacle_mask,
)
from auvplan.planning.problem import EdgeModel, PlanningProblem, SearchStatus
from auvplan.terrain.grid import GridGeometry


@dataclass(frozen=True)
class Route:
    """An optimal pre-planned route of one vehicle.

    Parameters
    ----------
    cells : ndarray of int64, shape (n_cells, 2)
        ``[row, col]`` of the cost grid from the start cell to the goal cell (8-connected).
    points : ndarray of shape (n_points, 2)
        ``[north, east]`` [m]: the exact start, the centres of the intermediate cells, the
        exact goal. ``n_points = max(n_cells, 2)`` (start and goal in one cell give two points).
    cost : float
        Graph cost of the cell path (see :class:`~auvplan.planning.problem.EdgeModel`).
    status : SearchStatus
        ``EXACT`` (failures raise instead).
    message : str
        Human-readable outcome.
    n_expanded : int
        Cells expanded by A*.
    name : str
        Vehicle name.
    edge_model : EdgeModel
        Edge model used.
    predicted_error : ndarray of shape (n_cells,), optional
        Predicted 1-σ radial TAN error [m] at each cell (belief-space routes).
    peak_error : float, optional
        Its largest value after the settling distance [m].
    """

    cells: IntArray
    points: FloatArray
    cost: float
    status: SearchStatus
    message: str
    n_expanded: int
    name: str
    edge_model: EdgeModel
    predicted_error: FloatArray | None = None
    peak_error: float | None = None

    @property
    def success(self) -> bool:
        """True when the route is optimal (always, since failures raise)."""
        return self.status is SearchStatus.EXACT


def blocked_cells(
    cost: FloatArray,
    geometry: GridGeometry,
    *,
    obstacles: Sequence[Obstacle] = (),
    clearance: float = 0.0,
) -> BoolArray:
    """No-go cells: non-finite cost (land, no data) or within ``clearance`` [m] of an obstacle.

    Parameters
    ----------
    cost : ndarray of shape (n_rows, n_cols)
        Cost map; NaN/inf cells are no-go.
    geometry : GridGeometry
        Geometry of ``cost``.
    obstacles : sequence of CircleObstacle, PolygonObstacle or OperatingArea
        Obstacles in world coordinates.
    clearance : float
        Extra distance [m] kept from obstacles.

    Returns
    -------
    ndarray of bool, shape (n_rows, n_cols)

    Examples
    --------
    >>> grid = GridGeometry(2, 3, 1.0, 1.0)
    >>> cost = np.array([[1.0, np.nan, 1.0], [1.0, 1.0, 1.0]])
    >>> from auvplan.planning.obstacles import CircleObstacle
    >>> blocked_cells(cost, grid, obstacles=[CircleObstacle(1.0, 2.0, 0.3)]).astype(int)
    array([[0, 1, 0],
           [0, 0, 1]])
    """
    _check_shape(cost, geometry)
    return np.asarray(
        ~np.isfinite(cost) | obstacle_mask(geometry, obstacles, clearance=clearance),
        dtype=np.bool_,
    )


def blocked_lookup(
    geometry: GridGeometry, blocked: BoolArray
) -> Callable[[FloatArray, FloatArray], BoolArray]:
    """Point test ``is_blocked(north, east)`` for :func:`~auvplan.planning.smoothing.smooth_path`.

    True where a point lies in a no-go cell; points outside the grid count as blocked.

    Parameters
    ----------
    geometry : GridGeometry
        Geometry of ``blocked``.
    blocked : ndarray of bool, shape (n_rows, n_cols)
        No-go cells (e.g. from :func:`blocked_cells`).

    Returns
    -------
    callable
        ``is_blocked(north, east) -> ndarray of bool`` for arrays of points [m].

    Examples
    --------
    >>> grid = GridGeometry(2, 2, 1.0, 1.0)
    >>> is_blocked = blocked_lookup(grid, np.array([[False, True], [False, False]]))
    >>> is_blocked(np.array([0.1, 0.2, 5.0]), np.array([0.0, 0.9, 0.0])).tolist()
    [False, True, True]
    """
    if blocked.shape != geometry.shape:
        raise InputError(f"blocked mask shape {blocked.shape} != grid shape {geometry.shape}")

    def is_blocked(north: FloatArray, east: FloatArray) -> BoolArray:
        row, col = geometry.to_index(north, east)
        inside = np.asarray(geometry.contains(north, east), dtype=np.bool_)
        out = np.ones(np.shape(row), dtype=np.bool_)
        out[inside] = blocked[row[inside], col[inside]]
        return out

    return is_blocked


def plan_route(
    cost: FloatArray,
    geometry: GridGeometry,
    start: tuple[float, float],
    goal: tuple[float, float],
    *,
    obstacles: Sequence[Obstacle] = (),
    obstacle_names: Sequence[str] = (),
    clearance: float = 0.0,
    edge_model: EdgeModel = EdgeModel.PAPER,
    move_factor: FloatArray | None = None,
    name: str = "vehicle",
    belief: BeliefModel | None = None,
    bottleneck: bool = False,
) -> Route:
    r"""Optimal 8-connected route of one vehicle from ``start`` to ``goal`` on a cost map.

    Parameters
    ----------
    cost : ndarray of shape (n_rows, n_cols)
        Shifted cost map :math:`\omega + w M_C` (> 0; NaN/inf = land or no data).
    geometry : GridGeometry
        Geometry of ``cost`` (the one owner of the cell <-> world mapping).
    start, goal : tuple of float
        ``(north, east)`` [m] in the grid's world frame.
    obstacles : sequence of CircleObstacle, PolygonObstacle or OperatingArea
        Impassable regions; cells within ``clearance`` of them are blocked.
    obstacle_names : sequence of str
        Labels of the first obstacles in error messages; the others are ``"obstacle K"``
        (``K`` their index in ``obstacles``).
    clearance : float
        Distance [m] kept from obstacles, ``>= 0``.
    edge_model : EdgeModel
        Edge weights of the grid graph.
    move_factor : ndarray of shape (8, n_rows, n_cols), or None
        Factors of the moves' weights (:class:`~auvplan.planning.problem.PlanningProblem`),
        e.g. :func:`auvplan.mission.current.current_move_factor`.
    name : str
        Vehicle name used in error messages and stored in the result.
    belief : BeliefModel, optional
        Search the belief space instead (:func:`~auvplan.planning.belief.search_belief`, on
        the crossed edge model with ``cost`` as the per-metre energy proxy): the cheapest route
        whose predicted TAN error meets the model's budget.
    bottleneck : bool
        With ``belief``: the route of the smallest peak predicted error instead.

    Returns
    -------
    Route

    Raises
    ------
    InputError
        Malformed cost map, start/goal not finite or outside the map.
    InfeasibleError
        Start/goal on land or no-data, inside an obstacle or within ``clearance`` of one, or
        goal unreachable. Every message is one line that names the vehicle.
    BudgetInfeasible
        With ``belief``: the goal is reachable, but not within its navigation budget.

    Examples
    --------
    >>> grid = GridGeometry(3, 4, 10.0, 10.0)
    >>> route = plan_route(np.ones((3, 4)), grid, (1.0, 2.0), (19.0, 28.0), name="auv1")
    >>> route.cells.tolist()
    [[0, 0], [1, 1], [2, 2], [2, 3]]
    >>> route.points[[0, -1]].tolist()
    [[1.0, 2.0], [19.0, 28.0]]
    """
    blocked_nan = ~np.isfinite(_check_shape(cost, geometry))
    mask = obstacle_mask(geometry, obstacles, clearance=clearance)
    cells = {}
    for label, point in (("start", start), ("goal", goal)):
        cells[label] = _endpoint_cell(
            label, point, geometry, blocked_nan, mask, obstacles, obstacle_names, clearance, name
        )
    try:
        problem = PlanningProblem(
            cost,
            mask,
            cells["start"],
            cells["goal"],
            geometry.spacing_north,
            geometry.spacing_east,
            move_factor,
        )
    except InputError as error:
        raise InputError(f"{name}: {error}") from error
    sigma, peak = None, None
    if belief is None:
        result = plan_astar(problem, edge_model=edge_model)
    else:
        found = search_belief(problem, belief, bottleneck=bottleneck)
        result, sigma, peak = found.path, found.sigma, found.peak
        if not result.success and math.isfinite(belief.max_error) and not bottleneck:
            raise BudgetInfeasible(f"{name}: {result.message}")
    if not result.success:
        raise InfeasibleError(
            f"{name}: goal ({goal[0]:g}, {goal[1]:g}) m is unreachable from start "
            f"({start[0]:g}, {start[1]:g}) m (land, no-data cells and obstacles separate them"
            f"{'; or the current bars the way' if move_factor is not None else ''})"
        )
    north, east = geometry.to_world(result.cells[:, 0], result.cells[:, 1])
    points = np.column_stack((north, east))
    if len(points) == 1:
        points = np.vstack((points, points))
    points[0] = start
    points[-1] = goal
    return Route(
        result.cells,
        points,
        result.cost,
        result.status,
        f"{name}: {result.message}",
        result.n_expanded,
        name,
        EdgeModel.CROSSED if belief is not None else edge_model,
        sigma,
        peak,
    )


class BudgetInfeasible(InfeasibleError):
    """The goal is reachable, but no route keeps the predicted TAN error within the budget."""


def _check_shape(cost: FloatArray, geometry: GridGeometry) -> FloatArray:
    if not isinstance(cost, np.ndarray) or cost.shape != geometry.shape:
        raise InputError(
            f"cost map shape {np.shape(cost)} does not match grid shape {geometry.shape}"
        )
    return cost


def _endpoint_cell(
    label: str,
    point: tuple[float, float],
    geometry: GridGeometry,
    blocked_nan: BoolArray,
    mask: BoolArray,
    obstacles: Sequence[Obstacle],
    obstacle_names: Sequence[str],
    clearance: float,
    name: str,
) -> tuple[int, int]:
    """Cell of a start/goal point, or a one-line error naming the vehicle and the reason.

    When obstacles block the point's cell, the error names the nearest of them.
    """
    north, east = float(point[0]), float(point[1])
    where = f"{name}: {label} ({north:g}, {east:g}) m"
    if not (np.isfinite(north) and np.isfinite(east)):
        raise InputError(f"{where} is not finite")
    if not geometry.contains(np.array(north), np.array(east)):
        low_n, high_n = geometry.north_bounds
        low_e, high_e = geometry.east_bounds
        raise InputError(
            f"{where} is outside the map (north {low_n:g} … {high_n:g} m, "
            f"east {low_e:g} … {high_e:g} m)"
        )
    row_array, col_array = geometry.to_index(np.array(north), np.array(east))
    row, col = int(row_array), int(col_array)
    if blocked_nan[row, col]:
        raise InfeasibleError(f"{where} is on land or a no-data cell (cell [{row}, {col}])")
    if mask[row, col]:
        distances = [
            float(distance_to_obstacle(obstacle, np.array(north), np.array(east)))
            for obstacle in obstacles
        ]
        nearest = int(np.argmin(distances))
        label = obstacle_names[nearest] if nearest < len(obstacle_names) else f"obstacle {nearest}"
        area = isinstance(obstacles[nearest], OperatingArea)
        if distances[nearest] < 0.0:
            inside = f"outside the {label}" if area else f"inside obstacle {label!r}"
            raise InfeasibleError(f"{where} is {inside}")
        what = f"the boundary of the {label}" if area else f"obstacle {label!r}"
        raise InfeasibleError(
            f"{where} is within the clearance {clearance:g} m of {what} "
            f"({distances[nearest]:.3g} m from it; cell [{row}, {col}] is blocked)"
        )
    return row, col
