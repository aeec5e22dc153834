"""Start and goal poses, obstacles and communication ranges of a generated scenario.

Poses are placed on the cost grid the pre-planner will search, in the part of the water that
is free of no-go cells (land, no data, obstacle clearance) by a margin and connected to the
rest, so every vehicle's goal is reachable from its start. Three layouts:

* ``"random"``: independent start points and directions;
* ``"lanes"``: parallel lanes (as in the paper's scenario), sometimes crossing over to the
  mirrored lane;
* ``"rendezvous"``: goals on a small ring around a common point, starts all around it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

import numpy as np
from scipy import ndimage

from auvplan._typing import BoolArray, FloatArray, IntArray
from auvplan.planning import CircleObstacle, PolygonObstacle, blocked_cells
from auvplan.scenarios._terrain import DrawnTerrain
from auvplan.terrain import GridGeometry

LAYOUTS: Final = ("random", "lanes", "rendezvous")
#: Attempts per vehicle before a layout gives up on the terrain.
ATTEMPTS: Final = 200


@dataclass(frozen=True)
class FreeSpace:
    """Where poses may go on a cost grid.

    ``usable`` marks cells at least ``margin`` [m] from every no-go cell and the map edge, in
    the largest 8-connected free region; ``labels`` numbers the free regions (0 = no-go).
    """

    geometry: GridGeometry
    usable: BoolArray
    labels: IntArray

    def is_usable(self, point: FloatArray) -> bool:
        """True if ``point`` (north, east) [m] lies in a usable cell."""
        north, east = np.array([point[0]]), np.array([point[1]])
        if not bool(self.geometry.contains(north, east)[0]):
            return False
        row, col = self.geometry.to_index(north, east)
        return bool(self.usable[row[0], col[0]])

    def region(self, point: FloatArray) -> int:
        """Free-region label of the cell of ``point`` (0 when no-go or outside)."""
        north, east = np.array([point[0]]), np.array([point[1]])
        if not bool(self.geometry.contains(north, east)[0]):
            return 0
        row, col = self.geometry.to_index(north, east)
        return int(self.labels[row[0], col[0]])

    def random_point(self, rng: np.random.Generator) -> FloatArray:
        """A uniformly drawn point of a usable cell (jittered within it)."""
        cells = np.argwhere(self.usable)
        row, col = cells[int(rng.integers(len(cells)))]
        north, east = self.geometry.to_world(np.array([row]), np.array([col]))
        jitter = rng.uniform(-0.5, 0.5, 2) * (
            self.geometry.spacing_north,
            self.geometry.spacing_east,
        )
        return np.array([north[0], east[0]]) + jitter


def free_space(
    terrain: DrawnTerrain,
    *,
    obstacles: tuple[CircleObstacle | PolygonObstacle, ...] = (),
    safety_radius: float,
    margin: float,
) -> FreeSpace:
    """The free space of ``terrain`` with ``obstacles`` (blocked within ``safety_radius``)."""
    geometry = terrain.cost_geometry
    blocked = blocked_cells(terrain.cost, geometry, obstacles=obstacles, clearance=safety_radius)
    labels, n_regions = ndimage.label(~blocked, structure=np.ones((3, 3), dtype=bool))
    spacing = (geometry.spacing_north, geometry.spacing_east)
    distance = ndimage.distance_transform_edt(
        np.pad(~blocked, 1, constant_values=False), sampling=spacing
    )[1:-1, 1:-1]
    usable = distance >= margin + max(spacing)
    if n_regions:
        sizes = ndimage.sum_labels(usable, labels, index=np.arange(1, n_regions + 1))
        usable &= labels == 1 + int(np.argmax(sizes))
    return FreeSpace(geometry, np.asarray(usable, dtype=np.bool_), np.asarray(labels))


def _unit(angle: float) -> FloatArray:
    """Unit vector (north, east) of a heading [rad, clockwise from north]."""
    return np.array([math.cos(angle), math.sin(angle)])


def _far_from(point: FloatArray, others: list[FloatArray], separation: float) -> bool:
    return all(float(np.hypot(*(point - other))) >= separation for other in others)


def draw_poses(
    rng: np.random.Generator,
    space: FreeSpace,
    distances: FloatArray,
    *,
    layout: str,
    separation: float,
) -> tuple[FloatArray, FloatArray] | None:
    """Starts and goals ``(n_vehicles, 2)`` [m] at about ``distances`` apart, or None.

    Starts are pairwise at least ``separation`` [m] apart, and so are goals; every point is
    usable and each goal is in its start's free region. None when the layout does not fit.
    """
    for _ in range(ATTEMPTS // 10):
        if layout == "random":
            poses = _random(rng, space, distances, separation)
        elif layout == "lanes":
            poses = _lanes(rng, space, distances, separation)
        else:
            poses = _rendezvous(rng, space, distances, separation)
        if poses is not None:
            return poses
    return None


def _random(
    rng: np.random.Generator, space: FreeSpace, distances: FloatArray, separation: float
) -> tuple[FloatArray, FloatArray] | None:
    starts: list[FloatArray] = []
    goals: list[FloatArray] = []
    for distance in distances:
        for _ in range(ATTEMPTS):
            start = space.random_point(rng)
            goal = start + distance * _unit(rng.uniform(0.0, 2.0 * math.pi))
            if (
                space.is_usable(goal)
                and _far_from(start, starts, separation)
                and _far_from(goal, goals, separation)
            ):
                starts.append(start)
                goals.append(goal)
                break
        else:
            return None
    return np.array(starts), np.array(goals)


def _lanes(
    rng: np.random.Generator, space: FreeSpace, distances: FloatArray, separation: float
) -> tuple[FloatArray, FloatArray] | None:
    n_vehicles = distances.size
    direction_angle = rng.uniform(0.0, 2.0 * math.pi)
    direction, across = _unit(direction_angle), _unit(direction_angle + 0.5 * math.pi)
    spacing = separation * rng.uniform(1.0, 2.5)
    offsets = spacing * (np.arange(n_vehicles) - 0.5 * (n_vehicles - 1))
    goal_offsets = offsets[::-1] if rng.uniform() < 0.5 else offsets
    stagger = rng.uniform(-0.5, 0.5, n_vehicles) * spacing
    base = space.random_point(rng)
    starts = base + offsets[:, None] * across + stagger[:, None] * direction
    goals = base + goal_offsets[:, None] * across + (stagger + distances)[:, None] * direction
    if all(space.is_usable(point) for point in (*starts, *goals)):
        return starts, goals
    return None


def _rendezvous(
    rng: np.random.Generator, space: FreeSpace, distances: FloatArray, separation: float
) -> tuple[FloatArray, FloatArray] | None:
    n_vehicles = distances.size
    centre = space.random_point(rng)
    radius = max(separation, 1.5 * separation * n_vehicles / (2.0 * math.pi))
    phase = rng.uniform(0.0, 2.0 * math.pi)
    goals = np.array(
        [centre + radius * _unit(phase + 2.0 * math.pi * i / n_vehicles) for i in range(n_vehicles)]
    )
    if not all(space.is_usable(goal) for goal in goals):
        return None
    starts: list[FloatArray] = []
    for goal, distance in zip(goals, distances, strict=True):
        for _ in range(ATTEMPTS):
            start = goal + distance * _unit(rng.uniform(0.0, 2.0 * math.pi))
            if space.is_usable(start) and _far_from(start, starts, separation):
                starts.append(start)
                break
        else:
            return None
    return np.array(starts), goals


def draw_obstacles(
    rng: np.random.Generator,
    terrain: DrawnTerrain,
    starts: FloatArray,
    goals: FloatArray,
    *,
    safety_radius: float,
    margin: float,
) -> tuple[CircleObstacle | PolygonObstacle, ...]:
    """One or two obstacles across the vehicles' straight lines, clear of every start/goal.

    A circle (radius 5–15 % of the crossed line's length) or a polygon of 3–6 vertices
    inscribed in such a circle, centred near a random point 30–70 % along a random vehicle's
    line. An obstacle is dropped when it comes within ``safety_radius + margin`` [m] of a
    start or goal or cuts a vehicle's goal off from its start.
    """
    kept: list[CircleObstacle | PolygonObstacle] = []
    endpoints = np.vstack([starts, goals])
    for _ in range(int(rng.integers(1, 3))):
        i = int(rng.integers(len(starts)))
        line = goals[i] - starts[i]
        length = float(np.hypot(*line))
        radius = length * rng.uniform(0.05, 0.15)
        centre = starts[i] + rng.uniform(0.3, 0.7) * line + rng.normal(0.0, 0.5 * radius, 2)
        obstacle: CircleObstacle | PolygonObstacle
        if rng.uniform() < 0.6:
            obstacle = CircleObstacle(float(centre[0]), float(centre[1]), float(radius))
        else:
            n_vertices = int(rng.integers(3, 7))
            angles = (
                rng.uniform(0.0, 2.0 * math.pi) + 2.0 * math.pi * np.arange(n_vertices) / n_vertices
            )
            reach = radius * rng.uniform(0.7, 1.0, n_vertices)
            vertices = centre + reach[:, None] * np.column_stack([np.cos(angles), np.sin(angles)])
            obstacle = PolygonObstacle(vertices)
        clearance = np.hypot(*(endpoints - centre).T) - radius
        if np.min(clearance) < safety_radius + margin:
            continue
        space = free_space(
            terrain, obstacles=(*kept, obstacle), safety_radius=safety_radius, margin=0.0
        )
        if all(
            space.region(start) != 0 and space.region(start) == space.region(goal)
            for start, goal in zip(starts, goals, strict=True)
        ):
            kept.append(obstacle)
    return tuple(kept)


def draw_comm_pairs(
    rng: np.random.Generator, starts: FloatArray, goals: FloatArray, *, safety_radius: float
) -> list[tuple[int, int, float]]:
    """One or two vehicle pairs with a communication range [m] comfortably above their needs.

    The range is 1.5 x the largest distance of the pair when both fly their straight lines at
    proportional progress (which includes the start and goal distances) plus ``4 r_c``,
    rounded up to 10 m.
    """
    n_vehicles = len(starts)
    pairs = [(i, j) for i in range(n_vehicles) for j in range(i + 1, n_vehicles)]
    chosen = rng.choice(len(pairs), size=min(len(pairs), int(rng.integers(1, 3))), replace=False)
    progress = np.linspace(0.0, 1.0, 101)[:, None]
    result = []
    for index in sorted(int(k) for k in chosen):
        i, j = pairs[index]
        track_i = starts[i] + progress * (goals[i] - starts[i])
        track_j = starts[j] + progress * (goals[j] - starts[j])
        farthest = float(np.max(np.hypot(*(track_i - track_j).T)))
        result.append((i, j, 10.0 * math.ceil((1.5 * farthest + 4.0 * safety_radius) / 10.0)))
    return result
