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

SAFETY_RADIUS = 2.5  # m
SPEED = 1.0  # m/s


def crossing_scenario(
    n_vehicles: int, duration: float, time_step: float, rng: np.random.Generator
) -> CoordinationProblem:
    """Paths through a common centre, staggered so that they conflict there."""
    length = SPEED * duration
    paths: list[FloatArray] = []
    for i in range(n_vehicles):
        heading = np.pi * i / n_vehicles + rng.uniform(-0.1, 0.1)
        # the vehicle passes the centre after a random fraction near one half of its path
        before = length * rng.uniform(0.45, 0.55)
        s = np.linspace(-before, length - before, int(length) + 1)
        bend = 0.02 * length * np.sin(np.pi * (s + before) / length) * rng.uniform(-1, 1)
        offset = rng.uniform(-1.0, 1.0)
        north = s * np.cos(heading) - (bend + offset) * np.sin(heading)
        east = s * np.sin(heading) + (bend + offset) * np.cos(heading)
        paths.append(np.column_stack([north, east]))
    return CoordinationProblem(
        paths=tuple(paths),
        safety_radius=SAFETY_RADIUS,
        cruise_speeds=np.full(n_vehicles, SPEED),
        time_step=time_step,
    )


CASES = (
    # (label, n_vehicles, duration [s], time_step [s], methods)
    ("paper: 4 veh, 60 s", 4, 60.0, 0.01, ("astar", "prioritized")),
    ("8 veh, 60 s", 8, 60.0, 0.01, ("prioritized",)),
    ("8 veh, 600 s", 8, 600.0, 0.01, ("prioritized",)),
    ("16 veh, 600 s", 16, 600.0, 0.01, ("prioritized",)),
)


def run_case(problem: CoordinationProblem, method: str) -> tuple[float, CoordinationResult]:
    start = time.perf_counter()
    result = deconflict(problem, method=method)
    return time.perf_counter() - start, result


class DeconflictionSuite:
    """asv-style suite: one paper-sized and one 16-vehicle problem."""

    params = (("astar", "prioritized"),)
    param_names = ("method",)

    def setup(self, method: str) -> None:
        n_vehicles = 4 if method == "astar" else 16
        duration = 60.0 if method == "astar" else 600.0
        self.problem = crossing_scenario(n_vehicles, duration, 0.01, np.random.default_rng(3))
        deconflict(self.problem, method=method)  # compile

    def time_deconflict(self, method: str) -> None:
        deconflict(self.problem, method=method)

    def track_expanded(self, method: str) -> int:
        return deconflict(self.problem, method=method).n_expanded

    def track_total_delay(self, method: str) -> float:
        return float(deconflict(self.problem, method=method).delays.sum())


def main() -> None:
    rng = np.random.default_rng(3)
    warm = crossing_scenario(3, 40.0, 0.1, rng)
    for method in ("astar", "prioritized"):
        deconflict(warm, method=method)  # numba compilation outside the timings
    header = (
        f"{'case':<20} {'method':<12} {'wall [s]':>9} {'expanded':>10} {'makespan [s]':>13} "
        f"{'added delay [s]':>16} {'max delay [s]':>14} {'sep >= 2rc [m]':>15}"
    )
    print(header)
    print("-" * len(header))
    for label, n_vehicles, duration, time_step, methods in CASES:
        problem = crossing_scenario(n_vehicles, duration, time_step, np.random.default_rng(3))
        for method in methods:
            wall, result = run_case(problem, method)
            print(
                f"{label:<20} {method:<12} {wall:>9.3f} {result.n_expanded:>10d} "
                f"{result.makespan:>13.2f} {result.delays.sum():>16.2f} "
                f"{result.delays.max():>14.2f} {result.min_separation:>8.3f} >= "
                f"{problem.separation:g}"
            )


if __name__ == "__main__":
    main()
