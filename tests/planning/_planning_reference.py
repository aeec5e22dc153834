"""Slow, obviously-correct oracles for the planning tests (loops, no shared code with src)."""

from __future__ import annotations

import math

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

MOVES = [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)]


def is_passable(cost: np.ndarray, blocked: np.ndarray | None, row: int, col: int) -> bool:
    if not math.isfinite(float(cost[row, col])):
        return False
    return blocked is None or not bool(blocked[row, col])


def edge_weight(
    cost: np.ndarray,
    u: tuple[int, int],
    v: tuple[int, int],
    model: str,
    spacing_north: float,
    spacing_east: float,
) -> float:
    """Weight of the move u -> v: cost of v (paper) or length x mean cost (crossed)."""
    if model == "paper":
        return float(cost[v])
    d_north = (v[0] - u[0]) * spacing_north
    d_east = (v[1] - u[1]) * spacing_east
    return math.sqrt(d_north**2 + d_east**2) * 0.5 * (float(cost[u]) + float(cost[v]))


def build_graph(
    cost: np.ndarray,
    blocked: np.ndarray | None,
    model: str,
    spacing_north: float = 1.0,
    spacing_east: float = 1.0,
    factor: np.ndarray | None = None,
) -> csr_matrix:
    """Directed 8-connected grid graph as a sparse matrix; node = row * n_cols + col.

    ``factor[k, r, c]`` multiplies the weight of move ``MOVES[k]`` into cell ``(r, c)``; a
    non-finite factor drops the edge.
    """
    n_rows, n_cols = cost.shape
    sources, targets, weights = [], [], []
    for row in range(n_rows):
        for col in range(n_cols):
            if not is_passable(cost, blocked, row, col):
                continue
            for k, (d_row, d_col) in enumerate(MOVES):
                r, c = row + d_row, col + d_col
                if 0 <= r < n_rows and 0 <= c < n_cols and is_passable(cost, blocked, r, c):
                    scale = 1.0 if factor is None else float(factor[k, r, c])
                    if not math.isfinite(scale):
                        continue
                    sources.append(row * n_cols + col)
                    targets.append(r * n_cols + c)
                    weights.append(
                        scale
                        * edge_weight(cost, (row, col), (r, c), model, spacing_north, spacing_east)
                    )
    n = n_rows * n_cols
    return csr_matrix((weights, (sources, targets)), shape=(n, n))


def dijkstra_cost(graph: csr_matrix, n_cols: int, start: tuple[int, int]) -> np.ndarray:
    """Optimal cost from ``start`` to every node (inf if unreachable)."""
    return np.asarray(dijkstra(graph, directed=True, indices=start[0] * n_cols + start[1]))


def cost_to_go(graph: csr_matrix, n_cols: int, goal: tuple[int, int]) -> np.ndarray:
    """Optimal cost from every node to ``goal`` (Dijkstra on the reversed graph)."""
    return np.asarray(dijkstra(graph.T.tocsr(), directed=True, indices=goal[0] * n_cols + goal[1]))


def path_cost(
    cost: np.ndarray,
    cells: np.ndarray,
    model: str,
    spacing_north: float = 1.0,
    spacing_east: float = 1.0,
) -> float:
    total = 0.0
    for i in range(1, len(cells)):
        u = (int(cells[i - 1, 0]), int(cells[i - 1, 1]))
        v = (int(cells[i, 0]), int(cells[i, 1]))
        total += edge_weight(cost, u, v, model, spacing_north, spacing_east)
    return total


def point_to_rectangle_distance(
    north: float, east: float, north_range: tuple[float, float], east_range: tuple[float, float]
) -> float:
    """Euclidean distance from a point to an axis-aligned rectangle (0 inside)."""
    d_north = max(north_range[0] - north, 0.0, north - north_range[1])
    d_east = max(east_range[0] - east, 0.0, east - east_range[1])
    return math.hypot(d_north, d_east)


def segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """Distance from point p to segment ab."""
    ab = b - a
    t = 0.0 if not np.any(ab) else float(np.clip(np.dot(p - a, ab) / np.dot(ab, ab), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * ab)))
