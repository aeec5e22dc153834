"""Planning: the A* pre-planner on terrain cost maps, obstacles and path smoothing (stage 1)."""

from __future__ import annotations

from auvplan.planning.astar import heuristic_map, plan_astar
from auvplan.planning.obstacles import (
    CircleObstacle,
    PolygonObstacle,
    distance_to_obstacle,
    obstacle_mask,
)
from auvplan.planning.problem import EdgeModel, PathResult, PlanningProblem, SearchStatus

__all__ = [
    "CircleObstacle",
    "EdgeModel",
    "PathResult",
    "PlanningProblem",
    "PolygonObstacle",
    "SearchStatus",
    "distance_to_obstacle",
    "heuristic_map",
    "obstacle_mask",
    "plan_astar",
]
