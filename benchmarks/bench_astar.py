"""A* pre-planner vs scikit-image MCP / MCP_Geometric and pyastar2d on terrain cost maps.

Run once and print a table::

    .venv/bin/python benchmarks/bench_astar.py [--sizes 1000 2000] [--repeats 5]

Also usable by asv (class :class:`AstarSuite` with ``setup``, ``time_*`` and ``track_*``).

Cost maps are terrain-like (SPEC §1): a smoothed random seabed, its normalised gradient
magnitude ``M_I``, a 4 x 4 block mean as excitation ``M_E`` (upsampled back), and the shifted
cost ``ω + w cos(π/2 M_E)`` with the paper's ``ω = w = 10``; a few round islands are
impassable (``inf`` for every tool). Start and goal are near opposite corners.

Cost models compared (all return optimal paths of their own graph):

* paper model (cost of the cell entered): ``skimage.graph.MCP(fully_connected=True)`` — its
  cumulative cost includes the start cell, which we subtract; ``pyastar2d.astar_path(...,
  allow_diagonal=True)`` — same graph, float32 weights, heuristic = Chebyshev distance with
  rate 1 (so it runs both on the raw map, rate 1 « c_min = 10, and on the map divided by
  c_min, where its heuristic is as tight as ours); its path is re-costed in float64.
* crossed model (length x mean cost): ``skimage.graph.MCP_Geometric(sampling=...)``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy import ndimage

from auvplan.planning import EdgeModel, PlanningProblem, plan_astar

SEED = 20131023
SPACING = (4.0, 5.0)  # north, east [m]: anisotropic on purpose (crossed model)


def terrain_cost(n: int, seed: int = SEED) -> np.ndarray:
    """Seeded terrain-like shifted cost map of shape (n, n) with a few impassable islands."""
    rng = np.random.default_rng(seed)
    seabed = ndimage.gaussian_filter(rng.standard_normal((n, n)), n / 100.0)
    seabed += 0.3 * ndimage.gaussian_filter(rng.standard_normal((n, n)), n / 400.0)
    d_north, d_east = np.gradient(seabed, SPACING[0], SPACING[1])
    information = np.hypot(d_north, d_east)
    information /= information.max()
    excitation = ndimage.uniform_filter(information, size=4)
    cost = 10.0 + 10.0 * np.cos(0.5 * np.pi * np.clip(excitation / excitation.max(), 0, 1))
    rows, cols = np.indices((n, n))
    for _ in range(6):
        centre = rng.uniform(0.2 * n, 0.8 * n, 2)
        radius = rng.uniform(0.02 * n, 0.06 * n)
        cost[np.hypot(rows - centre[0], cols - centre[1]) < radius] = np.inf
    return np.asarray(cost, dtype=np.float64)


def endpoints(n: int) -> tuple[tuple[int, int], tuple[int, int]]:
    return (n // 50, n // 40), (n - 1 - n // 60, n - 1 - n // 45)


def paper_path_cost(cost: np.ndarray, path: np.ndarray) -> float:
    """PAPER-model cost of a cell path: sum of the costs of the cells entered (float64)."""
    return float(np.sum(cost[path[1:, 0], path[1:, 1]]))


def crossed_path_cost(cost: np.ndarray, path: np.ndarray) -> float:
    steps = np.diff(path, axis=0) * np.array(SPACING)
    length = np.hypot(steps[:, 0], steps[:, 1])
    c = cost[path[:, 0], path[:, 1]]
    return float(np.sum(length * 0.5 * (c[:-1] + c[1:])))


# --- the tools, each returning (path (n, 2), cost) -------------------------------------------


def run_ours(cost: np.ndarray, model: EdgeModel) -> tuple[np.ndarray, float]:
    start, goal = endpoints(cost.shape[0])
    result = plan_astar(PlanningProblem(cost, None, start, goal, *SPACING), edge_model=model)
    return result.cells, result.cost


def run_mcp(cost: np.ndarray) -> tuple[np.ndarray, float]:
    from skimage.graph import MCP

    start, goal = endpoints(cost.shape[0])
    mcp = MCP(cost, fully_connected=True)
    cumulative, _ = mcp.find_costs([start], [goal])
    path = np.array(mcp.traceback(goal))
    return path, float(cumulative[goal] - cost[start])


def run_mcp_geometric(cost: np.ndarray) -> tuple[np.ndarray, float]:
    from skimage.graph import MCP_Geometric

    start, goal = endpoints(cost.shape[0])
    mcp = MCP_Geometric(cost, fully_connected=True, sampling=SPACING)
    cumulative, _ = mcp.find_costs([start], [goal])
    path = np.array(mcp.traceback(goal))
    return path, float(cumulative[goal])


def run_pyastar2d(cost: np.ndarray, scale: float) -> tuple[np.ndarray, float]:
    import pyastar2d

    start, goal = endpoints(cost.shape[0])
    weights = (cost / scale).astype(np.float32)
    path = pyastar2d.astar_path(weights, start, goal, allow_diagonal=True)
    return np.asarray(path), paper_path_cost(cost, np.asarray(path))


# --- measurement ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Row:
    size: int
    model: str
    tool: str
    median_cpu_s: float
    median_wall_s: float
    cost: float
    n_cells: int


def time_once(run: Callable[[], tuple[np.ndarray, float]]) -> tuple[float, float]:
    """CPU time and wall time [s] of one call of ``run``.

    CPU time (``time.process_time``; all tools are single-threaded and in-process) is the
    fairer measure on a shared machine; wall time is shown alongside.
    """
    cpu_start, wall_start = time.process_time(), time.perf_counter()
    run()
    return time.process_time() - cpu_start, time.perf_counter() - wall_start


def tools(cost: np.ndarray) -> list[tuple[str, str, Callable[[], tuple[np.ndarray, float]]]]:
    c_min = float(cost[np.isfinite(cost)].min())
    out: list[tuple[str, str, Callable[[], tuple[np.ndarray, float]]]] = [
        ("paper", "auvplan A*", lambda: run_ours(cost, EdgeModel.PAPER)),
        ("paper", "skimage MCP", lambda: run_mcp(cost)),
        ("crossed", "auvplan A*", lambda: run_ours(cost, EdgeModel.CROSSED)),
        ("crossed", "skimage MCP_Geometric", lambda: run_mcp_geometric(cost)),
    ]
    try:
        import pyastar2d  # noqa: F401
    except ImportError:
        return out
    out.insert(2, ("paper", "pyastar2d (raw map)", lambda: run_pyastar2d(cost, 1.0)))
    out.insert(3, ("paper", "pyastar2d (map / c_min)", lambda: run_pyastar2d(cost, c_min)))
    return out


def measure(sizes: list[int], repeats: int) -> list[Row]:
    """Median times per tool; repeats are interleaved across tools so load noise hits all."""
    rows = []
    for n in sizes:
        cost = terrain_cost(n)
        candidates = tools(cost)
        outputs = [run() for _, _, run in candidates]  # warm-up: numba cache, imports
        cpu: list[list[float]] = [[] for _ in candidates]
        wall: list[list[float]] = [[] for _ in candidates]
        for _ in range(repeats):
            for i, (_, _, run) in enumerate(candidates):
                cpu_s, wall_s = time_once(run)
                cpu[i].append(cpu_s)
                wall[i].append(wall_s)
        for i, (model, tool, _) in enumerate(candidates):
            path, path_cost = outputs[i]
            rows.append(
                Row(
                    n,
                    model,
                    tool,
                    statistics.median(cpu[i]),
                    statistics.median(wall[i]),
                    path_cost,
                    len(path),
                )
            )
    return rows


def print_table(rows: list[Row]) -> None:
    header = (
        f"{'size':>6} {'model':<8} {'tool':<26} {'CPU [s]':>8} {'wall [s]':>8} {'ours/theirs':>11} "
        f"{'optimal cost':>16} {'rel. diff':>10} identical?"
    )
    print(header)
    print("-" * len(header))
    ours = {(r.size, r.model): r for r in rows if r.tool == "auvplan A*"}
    for r in rows:
        mine = ours[(r.size, r.model)]
        ratio = mine.median_cpu_s / r.median_cpu_s
        diff = (r.cost - mine.cost) / mine.cost
        identical = "yes" if abs(diff) <= 1e-9 else "NO"
        print(
            f"{r.size:>5}² {r.model:<8} {r.tool:<26} {r.median_cpu_s:>8.4f} "
            f"{r.median_wall_s:>8.4f} {ratio:>11.2f} "
            f"{r.cost:>16.6f} {diff:>10.1e} {identical}"
        )


class AstarSuite:
    """asv-style suite: time and expanded-cell count of both edge models."""

    params: ClassVar[list[int]] = [1000, 2000]
    param_names: ClassVar[list[str]] = ["size"]

    def setup(self, size: int) -> None:
        self.cost = terrain_cost(size)
        run_ours(self.cost, EdgeModel.PAPER)  # compile / load the numba cache

    def time_paper(self, size: int) -> None:  # noqa: ARG002 (asv passes the parameter)
        run_ours(self.cost, EdgeModel.PAPER)

    def time_crossed(self, size: int) -> None:  # noqa: ARG002
        run_ours(self.cost, EdgeModel.CROSSED)

    def track_expanded_paper(self, size: int) -> int:
        start, goal = endpoints(size)
        return plan_astar(PlanningProblem(self.cost, None, start, goal, *SPACING)).n_expanded

    def track_cost_paper(self, size: int) -> float:  # noqa: ARG002
        return run_ours(self.cost, EdgeModel.PAPER)[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1000, 2000])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print(
        f"median of {args.repeats} interleaved runs after a warm-up; "
        "ratio = median CPU time ours / theirs"
    )
    print_table(measure(args.sizes, args.repeats))


if __name__ == "__main__":
    main()
