"""Benchmarks of temporal deconfliction (paper Sec. III-B and beyond).

Run once and print a table::

    .venv/bin/python benchmarks/bench_deconfliction.py

Also usable with asv (classes with ``setup``, ``time_*`` and ``track_*``).

Scenario: ``n_vehicles`` paths of ``duration`` seconds at 1 m/s, gently curved (dense
polylines, 1 m vertex spacing), spread in heading around a common centre and crossing it
within a few seconds of each other — every pair has a real conflict. ``r_c = 2.5 m``.
"""

from __future__ import annotations

import time

import numpy as np

from auvplan._typing import FloatArray
from auvplan.deconfliction import CoordinationProblem, CoordinationResult, deconflict
from auvplan.errors import AuvplanError

SAFETY_RADIUS = 2.5  # m
SPEED = 1.0  # m/s


def crossing_scenario(
    n_vehicles: int,
    duration: float,
    time_step: float,
    rng: np.random.Generator,
    *,
    spread: float = 1.0,
) -> CoordinationProblem:
    """Paths through a common centre (each line offset by up to ``spread`` metres)."""
    length = SPEED * duration
    paths: list[FloatArray] = []
    for i in range(n_vehicles):
        heading = np.pi * i / n_vehicles + rng.uniform(-0.1, 0.1)
        # the vehicle passes the centre after a random fraction near one half of its path
        before = length * rng.uniform(0.45, 0.55)
        s = np.linspace(-before, length - before, int(length) + 1)
        bend = 0.02 * length * np.sin(np.pi * (s + before) / length) * rng.uniform(-1, 1)
        offset = rng.uniform(-spread, spread)
        north = s * np.cos(heading) - (bend + offset) * np.sin(heading)
        east = s * np.sin(heading) + (bend + offset) * np.cos(heading)
        paths.append(np.column_stack([north, east]))
    return CoordinationProblem(
        paths=tuple(paths),
        safety_radius=SAFETY_RADIUS,
        cruise_speeds=np.full(n_vehicles, SPEED),
        time_step=time_step,
    )


# (label, n_vehicles, duration [s], spread [m], method, coarsening)
CASES = (
    ("paper 4v 60s one point", 4, 60.0, 1.0, "astar", 1),
    ("paper 4v 60s one point", 4, 60.0, 1.0, "astar", 25),
    ("paper 4v 60s one point", 4, 60.0, 1.0, "astar", 50),
    ("paper 4v 60s one point", 4, 60.0, 1.0, "prioritized", 1),
    ("paper 4v 60s one point", 4, 60.0, 1.0, "auto", 1),
    ("paper 4v 60s spread", 4, 60.0, 10.0, "astar", 1),
    ("paper 4v 60s spread", 4, 60.0, 10.0, "astar", 50),
    ("paper 4v 60s spread", 4, 60.0, 10.0, "prioritized", 1),
    ("paper 4v 60s spread", 4, 60.0, 10.0, "auto", 1),
    ("8v 60s", 8, 60.0, 1.0, "prioritized", 1),
    ("8v 600s", 8, 600.0, 1.0, "prioritized", 1),
    ("16v 600s", 16, 600.0, 1.0, "prioritized", 1),
)
TIME_STEP = 0.01  # s, the paper's gridding
MAX_EXPANDED = 1_000_000


def run_case(
    problem: CoordinationProblem, method: str, coarsening: int
) -> tuple[float, CoordinationResult | str]:
    start = time.perf_counter()
    try:
        result: CoordinationResult | str = deconflict(
            problem, method=method, coarsening=coarsening, max_expanded=MAX_EXPANDED
        )
    except AuvplanError as error:
        result = f"{type(error).__name__}: {error}"
    return time.perf_counter() - start, result


class DeconflictionSuite:
    """asv-style suite: A* on a paper-sized problem, prioritised on 16 vehicles x 600 s."""

    params = (("astar", "prioritized"),)
    param_names = ("method",)

    def setup(self, method: str) -> None:
        if method == "astar":  # the paper's size, pairwise conflicts at distinct places
            self.problem = crossing_scenario(4, 60.0, 0.01, np.random.default_rng(3), spread=10.0)
        else:
            self.problem = crossing_scenario(16, 600.0, 0.01, np.random.default_rng(3))
        deconflict(self.problem, method=method)  # compile

    def time_deconflict(self, method: str) -> None:
        deconflict(self.problem, method=method)

    def track_expanded(self, method: str) -> int:
        return deconflict(self.problem, method=method).n_expanded

    def track_total_delay(self, method: str) -> float:
        return float(deconflict(self.problem, method=method).delays.sum())


def main() -> None:
    warm = crossing_scenario(3, 40.0, 0.1, np.random.default_rng(3))
    for method in ("astar", "prioritized"):
        deconflict(warm, method=method)  # numba compilation outside the timings
    header = (
        f"{'case (dt = 0.01 s)':<24} {'method':<12} {'coarse':>6} {'wall [s]':>9} "
        f"{'expanded':>10} {'makespan [s]':>12} {'added delay [s]':>15} {'max delay [s]':>13} "
        f"{'certified sep [m]':>17}"
    )
    print(header)
    print("-" * len(header))
    for label, n_vehicles, duration, spread, method, coarsening in CASES:
        problem = crossing_scenario(
            n_vehicles, duration, TIME_STEP, np.random.default_rng(3), spread=spread
        )
        wall, result = run_case(problem, method, coarsening)
        row = f"{label:<24} {method:<12} {coarsening:>6d} {wall:>9.3f} "
        if isinstance(result, str):
            print(row + result[:90])
            continue
        print(
            row + f"{result.n_expanded:>10d} {result.makespan:>12.2f} "
            f"{result.delays.sum():>15.2f} {result.delays.max():>13.2f} "
            f"{result.min_separation:>8.3f} >= {problem.separation:g}"
        )
        if result.fallback:
            print(f"{'':<24} -> ran {result.method}: {result.fallback}")


if __name__ == "__main__":
    main()
