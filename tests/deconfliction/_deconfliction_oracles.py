"""Slow, independent oracles for the deconfliction tests (loops, no auvplan kernels)."""

from __future__ import annotations

import heapq
import itertools

import numpy as np

from auvplan._typing import FloatArray
from auvplan.deconfliction import CoordinationProblem, CoordinationResult


def polyline_point(path: FloatArray, s: float) -> FloatArray:
    """Point at arc length ``s`` by walking the segments (no np.interp)."""
    s = min(max(s, 0.0), float(np.sum(np.hypot(*np.diff(path, axis=0).T))))
    for a, b in itertools.pairwise(path):
        length = float(np.hypot(*(b - a)))
        if s <= length or np.array_equal(b, path[-1]):
            return a + (b - a) * (min(s, length) / length if length > 0 else 0.0)
        s -= length
    return path[-1].copy()


def distance_to_polyline(path: FloatArray, point: FloatArray) -> float:
    best = np.inf
    for a, b in itertools.pairwise(path):
        d = b - a
        t = np.clip(np.dot(point - a, d) / np.dot(d, d), 0.0, 1.0) if np.dot(d, d) > 0 else 0.0
        best = min(best, float(np.hypot(*(a + t * d - point))))
    return best


def dense_min_separation(
    problem: CoordinationProblem, result: CoordinationResult, n_per_step: int = 8
) -> float:
    """Minimum pairwise distance on a resampling ``n_per_step`` times finer than the result."""
    fine = np.linspace(0.0, result.time[-1], (result.time.size - 1) * n_per_step + 1)
    positions = []
    for i, path in enumerate(problem.paths):
        s = [law_at(result, i, float(t)) for t in fine]
        positions.append(np.array([polyline_point(path, v) for v in s]))
    best = np.inf
    for i, j in itertools.combinations(range(problem.n_vehicles), 2):
        best = min(best, float(np.hypot(*(positions[i] - positions[j]).T).min()))
    return best


def law_at(result: CoordinationResult, vehicle: int, t: float) -> float:
    """Arc length at ``t``: linear between samples, or integrated from the linear speed."""
    m = min(int(np.searchsorted(result.time, t, side="right")) - 1, result.time.size - 2)
    t0, t1 = result.time[m], result.time[m + 1]
    s0, s1 = result.progress[vehicle, m], result.progress[vehicle, m + 1]
    if result.speeds is None or np.isnan(result.speeds[vehicle, m]):
        return float(s0 + (s1 - s0) * (t - t0) / (t1 - t0))
    v0, v1 = result.speeds[vehicle, m], result.speeds[vehicle, m + 1]
    acceleration = (v1 - v0) / (t1 - t0)
    return float(s0 + v0 * (t - t0) + 0.5 * acceleration * (t - t0) ** 2)


def grid_collides(problem: CoordinationProblem, k: tuple[int, ...]) -> bool:
    """The grid's forbidden set, from its definition: distance <= 2 r_c + (h_i + h_j) / 2."""
    points = []
    for i, k_i in enumerate(k):
        s = problem.path_lengths[i] if k_i >= problem.n_steps[i] else k_i * problem.step_lengths[i]
        points.append(polyline_point(problem.paths[i], float(s)))
    for i, j in itertools.combinations(range(len(k)), 2):
        limit = problem.separation + 0.5 * (problem.step_lengths[i] + problem.step_lengths[j])
        if np.hypot(*(points[i] - points[j])) <= limit:
            return True
    return False


def brute_force_optimum(problem: CoordinationProblem) -> tuple[int, int] | None:
    """Dijkstra over the whole coordination grid: lexicographic (makespan, waits) in steps."""
    goal = tuple(int(n) for n in problem.n_steps)
    start = tuple(0 for _ in goal)
    if grid_collides(problem, start):
        return None
    best: dict[tuple[int, ...], tuple[int, int]] = {start: (0, 0)}
    queue: list[tuple[int, int, tuple[int, ...]]] = [(0, 0, start)]
    while queue:
        steps, waits, node = heapq.heappop(queue)
        if best[node] < (steps, waits):
            continue
        if node == goal:
            return steps, waits
        active = [i for i, k in enumerate(node) if k < goal[i]]
        for r in range(1, len(active) + 1):
            for subset in itertools.combinations(active, r):
                child = list(node)
                for i in subset:
                    child[i] += 1
                key = tuple(child)
                cost = (steps + 1, waits + len(active) - r)
                if key in best and best[key] <= cost:
                    continue
                if grid_collides(problem, key):
                    continue
                best[key] = cost
                heapq.heappush(queue, (cost[0], cost[1], key))
    return None
