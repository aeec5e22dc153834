"""Planning: the A* pre-planner on terrain cost maps, obstacles and path smoothing (stage 1)."""

from __future__ import annotations

from auvplan import _numba_cache  # noqa: F401 (damaged numba cache files heal: first)
from auvplan.planning.astar import heuristic_map, plan_astar
from auvplan.planning.obstacles import (
    CircleObstacle,
    Obstacle,
    OperatingArea,
    PolygonObstacle,
    distance_to_obstacle,
    obstacle_mask,
)
from auvplan.planning.problem import EdgeModel, PathResult, PlanningProblem, SearchStatus
from auvplan.planning.route import Route, blocked_cells, blocked_lookup, plan_route
from auvplan.planning.skirt import skirt_discs
from auvplan.planning.smoothing import (
    path_headings,
    path_length,
    resample_at_spacing,
    resample_polyline,
    smooth_path,
)

__all__ = [
    "CircleObstacle",
    "EdgeModel",
    "Obstacle",
    "OperatingArea",
    "PathResult",
    "PlanningProblem",
    "PolygonObstacle",
    "Route",
    "SearchStatus",
    "blocked_cells",
    "blocked_lookup",
    "distance_to_obstacle",
    "heuristic_map",
    "obstacle_mask",
    "path_headings",
    "path_length",
    "plan_astar",
    "plan_route",
    "resample_at_spacing",
    "resample_polyline",
    "skirt_discs",
    "smooth_path",
]
