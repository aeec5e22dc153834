"""Benchmark of the navigation simulator: 100 Monte-Carlo runs x 5000 particles x a 1-hour mission.

Run once and print a table::

    .venv/bin/python benchmarks/bench_navigation.py

Also usable with asv (classes with ``setup``, ``time_*`` and ``track_*``). Terrain: the seeded
synthetic volcanic bank stretched to 2 km x 2 km at 4 m; track: one hour at 0.5 m/s around an
ellipse over the bank's flank. Rows: the default altimeter at the default 3 s update period,
the same at 1 s, and the multibeam (11 beams). ``wall`` is elapsed time with every CPU the
process may use; ``cpu`` the CPU time of all threads; ``ns/pu`` the CPU time per particle and
update. Target (issue 13): 100 runs x 5000 particles x 1 hour "in seconds" on 2 cores.
"""

from __future__ import annotations

import os
import time

import numpy as np

from auvplan.navigation import (
    NavigationSettings,
    ParticleFilterOptions,
    SensorModel,
    Track,
    run_monte_carlo,
)
from auvplan.terrain import BathymetryGrid, synthetic_bank

N_RUNS = 100
N_PARTICLES = 5000
DURATION_S = 3600.0
CASES = {
    "altimeter, 3 s": NavigationSettings(),
    "altimeter, 1 s": NavigationSettings(update_period=1.0),
    "multibeam, 3 s": NavigationSettings(sensor=SensorModel.multibeam()),
}


def terrain() -> BathymetryGrid:
    """The synthetic bank over 2 km x 2 km at 4 m spacing."""
    return synthetic_bank(seed=11, extent_north=2000.0, extent_east=2000.0, spacing=4.0)


def hour_track() -> Track:
    """One hour at 0.5 m/s (1.8 km) on an ellipse around the map centre, sampled at 0.5 s."""
    time_s = np.arange(0.0, DURATION_S + 0.25, 0.5)
    angle = 2.0 * np.pi * time_s / DURATION_S
    north = 1000.0 + 350.0 * np.sin(angle)
    east = 1000.0 + 220.0 * np.cos(angle)
    heading = np.arctan2(np.gradient(east), np.gradient(north))
    return Track(time_s, np.column_stack([north, east]), heading)


class NavigationSuite:
    """asv-style suite: the Monte-Carlo runner on the one-hour track."""

    params = (list(CASES),)
    param_names = ("case",)

    def setup(self, case: str) -> None:
        self.grid = terrain()
        self.track = hour_track()
        base = CASES[case]
        self.settings = NavigationSettings(
            sensor=base.sensor,
            filter=ParticleFilterOptions(n_particles=N_PARTICLES),
            update_period=base.update_period,
        )
        run_monte_carlo(self.grid, self.track, self.settings, n_runs=1, seed=0)  # compile

    def time_monte_carlo(self, _case: str) -> None:
        run_monte_carlo(self.grid, self.track, self.settings, n_runs=N_RUNS, seed=1)

    def track_mean_rmse(self, _case: str) -> float:
        result = run_monte_carlo(self.grid, self.track, self.settings, n_runs=N_RUNS, seed=1)
        return float(np.mean(result.rmse))


def main() -> None:
    print(
        f"{N_RUNS} runs x {N_PARTICLES} particles x {DURATION_S / 3600:g} h on "
        f"{len(os.sched_getaffinity(0))} CPU(s); synthetic bank 2 km x 2 km at 4 m"
    )
    print(
        f"{'case':<16} {'updates':>7} {'wall [s]':>9} {'cpu [s]':>8} {'ns/pu':>6} "
        f"{'RMSE [m]':>9} {'DR RMSE [m]':>11}"
    )
    for case in CASES:
        suite = NavigationSuite()
        suite.setup(case)
        wall, cpu = time.perf_counter(), time.process_time()
        result = run_monte_carlo(suite.grid, suite.track, suite.settings, n_runs=N_RUNS, seed=1)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        n_updates = result.time.size
        per_update = cpu / (N_RUNS * N_PARTICLES * n_updates) * 1e9
        print(
            f"{case:<16} {n_updates:7d} {wall:9.1f} {cpu:8.1f} {per_update:6.1f} "
            f"{np.mean(result.rmse):9.2f} {np.mean(result.dead_reckoning_rmse):11.2f}"
        )


if __name__ == "__main__":
    main()
