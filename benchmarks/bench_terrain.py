"""Benchmarks of the terrain stage: information/excitation/cost maps and geographic resampling.

Run once and print a table::

    .venv/bin/python benchmarks/bench_terrain.py

Also usable with asv (classes with ``setup``, ``time_*`` and ``track_*``). Terrain: the
seeded synthetic volcanic bank generator stretched to ``n x n`` nodes at 4 m spacing (so the
relief, crater and fractal roughness are realistic), with 5 % NaN holes. Target (issue 2):
maps of a 2000 x 2000 grid in < 1 s.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable

import numpy as np

from auvplan.terrain import (
    BathymetryGrid,
    MapParameters,
    compute_terrain_maps,
    synthetic_bank,
)
from auvplan.terrain.resample import project_geographic_grid

SIZES = (1000, 2000)
REPEATS = 5


def seeded_terrain(n: int, *, seed: int = 11) -> BathymetryGrid:
    """An ``n x n`` synthetic bank at 4 m spacing with 5 % of cells set to NaN (land)."""
    extent = 4.0 * (n - 1)
    bank = synthetic_bank(seed=seed, extent_north=extent, extent_east=extent, spacing=4.0)
    depth = bank.depth.copy()
    depth[np.random.default_rng(seed).random(depth.shape) < 0.05] = np.nan
    return BathymetryGrid(depth, bank.geometry, None, None, bank.name)


def median_time(function: Callable[[], object], repeats: int = REPEATS) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


class TerrainMapsSuite:
    """asv-style suite: the full map pipeline on n x n terrain."""

    params = (SIZES,)
    param_names = ("n",)

    def setup(self, n: int) -> None:
        self.grid = seeded_terrain(n)

    def time_compute_terrain_maps(self, _n: int) -> None:
        compute_terrain_maps(self.grid, MapParameters())

    def track_mean_cost(self, _n: int) -> float:
        return float(np.nanmean(compute_terrain_maps(self.grid).cost))


class GeographicResampleSuite:
    """asv-style suite: lon/lat grid -> local metric grid (pyproj + bilinear)."""

    params = (SIZES,)
    param_names = ("n",)

    def setup(self, n: int) -> None:
        self.lat = 36.79 + (1.0 / 10800.0) * np.arange(n)
        self.lon = -121.83 + (1.0 / 10800.0) * np.arange(n)
        self.depth = seeded_terrain(n).depth

    def time_project_geographic_grid(self, _n: int) -> None:
        project_geographic_grid(self.depth, self.lat, self.lon)

    def track_nan_fraction(self, _n: int) -> float:
        grid = project_geographic_grid(self.depth, self.lat, self.lon)
        return float(np.isnan(grid.depth).mean())


def main() -> None:
    print(f"median of {REPEATS} runs; terrain: synthetic bank at 4 m with 5 % NaN holes")
    print(
        f"{'n x n':>11}  {'maps [s]':>9}  {'resample [s]':>12}  {'mean cost':>9}  {'NaN cost':>8}"
    )
    for n in SIZES:
        maps_suite = TerrainMapsSuite()
        maps_suite.setup(n)
        maps_time = median_time(lambda s=maps_suite, n=n: s.time_compute_terrain_maps(n))
        maps = compute_terrain_maps(maps_suite.grid)
        resample_suite = GeographicResampleSuite()
        resample_suite.setup(n)
        resample_time = median_time(
            lambda s=resample_suite, n=n: s.time_project_geographic_grid(n), repeats=3
        )
        print(
            f"{n:>5} x {n:<5}  {maps_time:9.3f}  {resample_time:12.3f}  "
            f"{np.nanmean(maps.cost):9.3f}  {np.isnan(maps.cost).mean():8.3f}"
        )


if __name__ == "__main__":
    main()
