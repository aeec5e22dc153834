"""Planning: the A* pre-planner on terrain cost maps, obstacles and path smoothing (stage 1)."""

from __future__ import annotations

from auvplan.planning.astar import plan_astar
from auvplan.planning.problem import EdgeModel, PathResult, PlanningProblem, SearchStatus

__all__ = ["EdgeModel", "PathResult", "PlanningProblem", "SearchStatus", "plan_astar"]
