"""Belief-space pre-planner (``search_belief``) on 1000² and 2000² grids vs A* and MCP_Geometric.

Run once and print a table::

    .venv/bin/python benchmarks/bench_navigation_search.py [--sizes 1000 2000] [--repeats 3]
    .venv/bin/python benchmarks/bench_navigation_search.py --quick   # 1000² only (smoke)

Issue target: "pre-planner speed with a budget: a 2000² cost grid, 1 vehicle, <= 5 s warm".

Case (seeded, synthetic): a 10 km x 10 km seabed built at the cost grid's resolution (2000²
cells of 5 m, or the same seabed on 1000² cells of 10 m), a featureless plain (depth 60-100 m,
a gentle slope) with eight rough features (seamounts and ridges, made with
``scipy.ndimage.gaussian_filter``, a smoothed noise texture on top) beside the straight line
from the start (north 4500 m, east 500 m) to the goal (north 5500 m, east 9450 m), ~9 km
apart, their centres 200-800 m off it. The cost grid is ones (edges cost their length, as in a
navigation-aware mission without current). The belief model is a mission's with a default
``[navigation]`` table (:func:`auvplan.mission.navigation.vehicle_navigation`): altimeter at
the surface, the Fisher map of :func:`auvplan.navigation.prediction.fisher_map` on the cost
grid's geometry, ``U = 0.6`` m/s, an update every ``T = 3`` s, initial σ 7 m per axis, the
budget applying after ``600 s · U``.

Rows: (a) ``fisher_map``; (b) ``search_belief`` without a budget (one bin: plain A* on 16
moves); (c) a budget of 0.6 x (b)'s peak predicted error; (d) 0.3 x that peak (may be
infeasible: reported); (e) ``bottleneck=True`` (the smallest feasible budget); (f) the
automatic mode, ``VehicleNavigation.route`` (energy ``L``) on ``plan_route(...,
belief=...)`` (one no-budget, one bottleneck and up to six budget searches); references:
auvplan's A* (``plan_astar``, crossed edges, 8 moves) and ``skimage.graph.MCP_Geometric``
(8 moves, same edge weights; skipped if scikit-image is missing) on the same cost grid.
pyastar2d is not compared: its diagonal moves cost one cell, not √2, so its paths are not
Euclidean shortest paths.

Timing: ``cold`` is the wall time of the first call in a fresh process (imports and the input
arrays loaded beforehand, the numba disk cache as it is; the ``cache`` column says whether the
compiled kernels were loaded from it or compiled); ``warm`` the median of ``--repeats`` calls
in one process after a warm-up on a small grid, interleaved across rows so that load noise hits
all of them (CPU time of the process, all threads, and wall time). Ratios are warm CPU time of
the row over that of the reference, from this run. The compile time is measured once, at the
first size, by the first call in a fresh process with an empty ``NUMBA_CACHE_DIR``. Memory:
``+MB`` is the peak resident memory during the cold call above the resident memory before it
(the kernel's label table included, which ``tracemalloc`` would not see); ``MB`` the process's
peak. ``labels``: labels the belief search created (for the automatic mode, summed over the
searches that returned a route; an infeasible budget raises inside ``plan_route`` and is not
counted), cells A* expanded. ``budget m``: the budget searched (for the automatic mode, the
bound of its priced searches, the shortest route's peak); ``route m``: the graph cost, i.e.
the length over cell centres (for the automatic mode the route's polyline length);
``peak σ``: the route's peak predicted radial error after settling.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from scipy import ndimage

HERE = Path(__file__).resolve()
SEED = 20240607
EXTENT = 10_000.0  # side of the square seabed [m]
START = (4500.0, 500.0)  # north, east [m]
GOAL = (5500.0, 9450.0)
SPEED = 0.6  # nominal speed U [m/s]
SETTLE_S = 600.0  # the default settle_s
FRACTIONS = {"budget 0.6": 0.6, "budget 0.3": 0.3}  # of the no-budget route's peak
TARGET_S = 5.0
TARGET_SIZE = 2000
KERNEL_MODULES = (
    "auvplan.planning._belief_kernel",
    "auvplan.planning._kernel",
    "auvplan.navigation._kernels",
    "auvplan.navigation._prediction_kernel",
    "auvplan.terrain.spline",
)
LABELS = {
    "fisher": "(a) fisher_map",
    "plain": "(b) search, no budget",
    "budget 0.6": "(c) search, budget 0.6 x peak",
    "budget 0.3": "(d) search, budget 0.3 x peak",
    "bottleneck": "(e) search, bottleneck",
    "automatic": "(f) automatic (priced searches)",
    "astar": "auvplan A* (8 moves)",
    "mcp": "skimage MCP_Geometric",
}


# --- the case ------------------------------------------------------------------------------


def seabed(n: int, seed: int = SEED) -> np.ndarray:
    """Depth [m] of the seeded plain with rough features, on n x n cells over 10 km."""
    spacing = EXTENT / n
    rng = np.random.default_rng(seed)
    axis = np.arange(n) * spacing
    depth = 60.0 + 40.0 * (0.3 * axis[:, None] + 0.7 * axis[None, :]) / EXTENT
    line = np.subtract(GOAL, START)
    normal = np.array([-line[1], line[0]]) / np.hypot(*line)
    kinds = ("seamount", "ridge") * 4
    along = np.linspace(0.06, 0.94, len(kinds)) + rng.uniform(-0.03, 0.03, len(kinds))
    textures = [np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(len(kinds))]
    for kind, fraction, texture in zip(kinds, along, textures, strict=True):
        offset = rng.choice([-1.0, 1.0]) * rng.uniform(200.0, 800.0)
        centre = np.asarray(START) + fraction * line + offset * normal
        height = rng.uniform(12.0, 30.0)
        if kind == "seamount":
            width = rng.uniform(150.0, 350.0)  # radius
            half_length, direction = width, np.array([1.0, 0.0])
        else:
            half_length, width = 0.5 * rng.uniform(800.0, 1600.0), rng.uniform(60.0, 120.0)
            angle = rng.uniform(0.0, np.pi)
            direction = np.array([np.cos(angle), np.sin(angle)])
        smoothing = 0.5 * width
        reach = half_length + width + 4.0 * smoothing
        r0, r1 = np.clip(np.searchsorted(axis, [centre[0] - reach, centre[0] + reach]), 0, n)
        c0, c1 = np.clip(np.searchsorted(axis, [centre[1] - reach, centre[1] + reach]), 0, n)
        d_north = axis[r0:r1, None] - centre[0]
        d_east = axis[None, c0:c1] - centre[1]
        if kind == "seamount":
            shape = np.hypot(d_north, d_east) <= width
        else:  # a thick segment
            t = np.clip(d_north * direction[0] + d_east * direction[1], -half_length, half_length)
            shape = np.hypot(d_north - t * direction[0], d_east - t * direction[1]) <= width / 2
        envelope = ndimage.gaussian_filter(shape.astype(np.float64), smoothing / spacing)
        envelope /= envelope.max()
        rough = ndimage.gaussian_filter(texture.standard_normal(envelope.shape), 20.0 / spacing)
        depth[r0:r1, c0:c1] -= height * envelope * (1.0 + 0.15 * rough / rough.std())
    return np.asarray(depth, np.float64)


# --- one process: one row cold, or every row warm ------------------------------------------


def _memory_kb(field: str) -> int:
    """``VmRSS`` / ``VmHWM`` of this process [KiB] (0 where /proc is missing)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith(field + ":"):
                return int(line.split()[1])
    except OSError:
        pass
    return 0


def _reset_peak() -> None:
    """Restart ``VmHWM`` from the current resident memory (Linux >= 4.0)."""
    with contextlib.suppress(OSError):
        Path("/proc/self/clear_refs").write_text("5")


def _cache_counts() -> tuple[int, int]:
    """Kernels loaded from the numba disk cache and kernels compiled, so far."""
    from numba.core.dispatcher import Dispatcher

    hits = misses = 0
    for name in KERNEL_MODULES:
        module = sys.modules.get(name)
        for value in vars(module).values() if module else ():
            if isinstance(value, Dispatcher):
                hits += sum(value.stats.cache_hits.values())
                misses += sum(value.stats.cache_misses.values())
    return hits, misses


class Case:
    """The inputs of every row at one size, and the call behind each row."""

    def __init__(
        self,
        depth: np.ndarray,
        fisher: np.ndarray | None,
        peak: float | None,
        endpoints: tuple[tuple[float, float], tuple[float, float]] = (START, GOAL),
        spacing: float | None = None,
    ) -> None:
        from auvplan.mission.tables import NavigationConfig
        from auvplan.navigation import process_noise_sigma
        from auvplan.planning import PlanningProblem
        from auvplan.planning.belief import BeliefModel
        from auvplan.terrain import BathymetryGrid, GridGeometry

        n = depth.shape[0]
        self.endpoints = endpoints
        spacing = EXTENT / n if spacing is None else spacing
        self.geometry = GridGeometry(n, n, spacing, spacing)
        self.grid = BathymetryGrid(depth, self.geometry, name="bench plain")
        self.config = NavigationConfig()
        self.settings = self.config.settings(vehicle_depth=0.0)
        self.cost = np.ones((n, n))
        cells = [self.geometry.to_index(np.array([p[0]]), np.array([p[1]])) for p in endpoints]
        start, goal = ((int(r[0]), int(c[0])) for r, c in cells)
        self.problem = PlanningProblem(
            self.cost, None, start, goal, self.geometry.spacing_north, self.geometry.spacing_east
        )
        self.peak = peak
        self.model: BeliefModel | None = None
        if fisher is not None:
            step = SPEED * self.settings.update_period
            noise = process_noise_sigma(self.settings.motion, np.array([[step, 0.0]]))[0]
            self.model = BeliefModel(
                fisher,
                updates_per_metre=1.0 / step,
                drift_rate=self.settings.motion.bias_sigma,
                process_variance=float(noise) ** 2,
                initial_sigma=self.settings.filter.initial_sigma,
                settle_distance=SETTLE_S * SPEED,
            )

    def call(self, kind: str) -> Callable[[], dict[str, Any]]:
        """The call of a row; it returns what the row reports besides times."""
        return {
            "fisher": self.fisher,
            "plain": lambda: self.search(None, bottleneck=False),
            "budget 0.6": lambda: self.search(FRACTIONS["budget 0.6"], bottleneck=False),
            "budget 0.3": lambda: self.search(FRACTIONS["budget 0.3"], bottleneck=False),
            "bottleneck": lambda: self.search(None, bottleneck=True),
            "automatic": self.automatic,
            "astar": self.astar,
            "mcp": self.mcp,
        }[kind]

    def fisher(self) -> dict[str, Any]:
        from auvplan.navigation.prediction import fisher_map

        self.fisher_values = fisher_map(self.grid, self.geometry, self.settings.sensor)
        return {}

    def search(self, fraction: float | None, *, bottleneck: bool) -> dict[str, Any]:
        from auvplan.errors import InputError
        from auvplan.planning.belief import UNBOUNDED_BINS, search_belief

        assert self.model is not None
        model, budget = self.model, None
        if fraction is not None:
            assert self.peak is not None
            budget = fraction * self.peak
            model = self.budget_model(budget)
        record: dict[str, Any] = {
            "budget": budget,
            "bins": UNBOUNDED_BINS if bottleneck else model.n_bins,
        }
        try:
            found = search_belief(self.problem, model, bottleneck=bottleneck)
        except InputError as error:  # more labels than model.max_labels
            return {**record, "outcome": "too many labels", "error": str(error)}
        record["labels"] = found.n_labels
        if not found.path.success:
            return {**record, "outcome": "infeasible"}
        return {**record, "outcome": "found", "cost": found.path.cost, "peak": found.peak}

    def budget_model(self, budget: float) -> Any:
        from auvplan.planning.belief import BeliefModel

        assert self.model is not None
        m = self.model
        return BeliefModel(
            m.fisher, m.updates_per_metre, m.drift_rate, m.process_variance, m.initial_sigma,
            budget, m.settle_distance, m.error_weight, m.bin_width, m.max_labels,
        )  # fmt: skip

    def automatic(self) -> dict[str, Any]:
        from auvplan.errors import InputError
        from auvplan.mission.navigation import VehicleNavigation
        from auvplan.planning import EdgeModel, Route, path_length, plan_route
        from auvplan.planning.belief import BeliefModel

        assert self.model is not None
        labels = []

        def one(belief: BeliefModel, bottleneck: bool) -> Route:
            route = plan_route(
                self.cost, self.geometry, *self.endpoints, edge_model=EdgeModel.CROSSED,
                belief=belief, bottleneck=bottleneck,
            )  # fmt: skip
            labels.append(route.n_expanded)
            return route

        vehicle = VehicleNavigation(
            "auv", self.model, lambda length: length, 1.0,
            math.dist(*self.endpoints), None,
            float(self.config.max_energy_increase), float(self.config.min_error_reduction),
        )  # fmt: skip
        try:
            route, choice = vehicle.route(one, True)  # the seabed has no obstacle
        except InputError as error:
            return {"outcome": "too many labels", "labels": sum(labels), "error": str(error)}
        return {
            "outcome": "energy-only" if choice.budget_m is None else "budget",
            "budget": choice.budget_m,
            "searches": choice.searches,
            "labels": sum(labels),
            "cost": path_length(route.points),
            "peak": choice.peak_m,
            "rms": choice.rms_m,
            "energy_only_rms": choice.energy_only_rms_m,
            "energy_increase": choice.energy_increase,
        }

    def astar(self) -> dict[str, Any]:
        from auvplan.planning import EdgeModel, plan_astar

        found = plan_astar(self.problem, edge_model=EdgeModel.CROSSED)
        return {"outcome": "found", "cost": found.cost, "labels": found.n_expanded}

    def mcp(self) -> dict[str, Any]:
        from skimage.graph import MCP_Geometric

        spacing = (self.geometry.spacing_north, self.geometry.spacing_east)
        mcp = MCP_Geometric(self.cost, fully_connected=True, sampling=spacing)
        cumulative, _ = mcp.find_costs([self.problem.start], [self.problem.goal])
        return {"outcome": "found", "cost": float(cumulative[self.problem.goal])}


def _timed(call: Callable[[], dict[str, Any]]) -> tuple[dict[str, Any], float, float]:
    cpu, wall = time.process_time(), time.perf_counter()
    out = call()
    return out, time.process_time() - cpu, time.perf_counter() - wall


def child(kind: str, data: Path, peak: float | None, repeats: int, kinds: list[str]) -> None:
    """Measure one row cold (``kind``) or every row warm (``kind == "warm"``); print JSON."""
    started = time.perf_counter()
    import auvplan.mission.navigation
    import auvplan.planning  # noqa: F401

    imports_s = time.perf_counter() - started
    fisher = np.load(data / "fisher.npy") if kind != "fisher" else None
    case = Case(np.load(data / "depth.npy"), fisher, peak)
    if kind != "warm":
        hits, misses = _cache_counts()
        _reset_peak()
        before = _memory_kb("VmRSS")
        record, cpu_s, wall_s = _timed(case.call(kind))
        record.update(
            cold_s=wall_s, cold_cpu_s=cpu_s, imports_s=imports_s,
            rss_increase_mb=(_memory_kb("VmHWM") - before) / 1024,
            peak_mb=_memory_kb("VmHWM") / 1024,
            loaded=_cache_counts()[0] - hits, compiled=_cache_counts()[1] - misses,
        )  # fmt: skip
        if kind == "fisher":
            np.save(data / "fisher.npy", case.fisher_values)
        print(json.dumps(record), flush=True)
        return
    assert fisher is not None
    corner = slice(0, 64)  # warm-up: every row once, on a 64² corner
    spacing = case.geometry.spacing_north
    tiny = Case(
        case.grid.depth[corner, corner].copy(), fisher[corner, corner].copy(), 10.0,
        ((5 * spacing, 5 * spacing), (60 * spacing, 50 * spacing)), spacing,
    )  # fmt: skip
    for name in kinds:
        tiny.call(name)()
    cpu: dict[str, list[float]] = {name: [] for name in kinds}
    wall: dict[str, list[float]] = {name: [] for name in kinds}
    for _ in range(repeats):
        for name in kinds:
            _, cpu_s, wall_s = _timed(case.call(name))
            cpu[name].append(cpu_s)
            wall[name].append(wall_s)
    medians = {
        name: {"cpu_s": statistics.median(cpu[name]), "wall_s": statistics.median(wall[name])}
        for name in kinds
    }
    print(json.dumps(medians), flush=True)


# --- the parent: one process per measurement -----------------------------------------------


def run_child(
    kind: str, data: Path, *, peak: float | None = None, repeats: int = 1,
    kinds: tuple[str, ...] = (), numba_cache: Path | None = None,
) -> dict[str, Any]:  # fmt: skip
    """One measurement in a fresh process; its JSON record (``error`` if it failed)."""
    command = [sys.executable, str(HERE), "--child", kind, "--data", str(data)]
    command += ["--repeats", str(repeats), "--kinds", *kinds]
    if peak is not None:
        command += ["--peak", repr(peak)]
    env = dict(os.environ)
    if numba_cache is not None:
        env["NUMBA_CACHE_DIR"] = str(numba_cache)
    done = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
    if done.returncode != 0:
        lines = done.stderr.strip().splitlines()
        return {"error": lines[-1] if lines else f"exit status {done.returncode}"}
    record: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return record


def available_kinds() -> list[str]:
    kinds = list(LABELS)
    try:
        import skimage.graph  # noqa: F401
    except ImportError:
        kinds.remove("mcp")
    return kinds


def measure(
    n: int, repeats: int, kinds: list[str], compile_times: bool
) -> tuple[dict[str, dict[str, Any]], dict[str, dict[str, float]], dict[str, Any]]:
    """Cold records and warm medians of every row at size ``n`` (and compile times)."""
    cold: dict[str, dict[str, Any]] = {}
    compiled: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="auvplan_bench_nav_") as tmp:
        data = Path(tmp)
        np.save(data / "depth.npy", seabed(n))
        cold["fisher"] = run_child("fisher", data)
        if "error" in cold["fisher"]:
            return cold, {}, compiled
        cold["plain"] = run_child("plain", data)
        peak = cold["plain"].get("peak")
        for kind in kinds:
            if kind not in cold:
                cold[kind] = run_child(kind, data, peak=peak)
            print(f"{n}²: {kind} cold {cold[kind].get('cold_s', float('nan')):.2f} s", flush=True)
        warm = run_child("warm", data, peak=peak, repeats=repeats, kinds=tuple(kinds))
        print(f"{n}²: warm runs done", flush=True)
        if compile_times:
            for kind in ("fisher", "plain", "astar"):
                with tempfile.TemporaryDirectory(prefix="numba_empty_") as empty:
                    compiled[kind] = run_child(kind, data, peak=peak, numba_cache=Path(empty))
    return cold, ({} if "error" in warm else warm), compiled


def _number(value: Any, fmt: str) -> str:
    return format(value, fmt) if isinstance(value, int | float) else "-"


def _outcome(record: dict[str, Any]) -> str:
    if "error" in record and "outcome" not in record:
        return f"failed: {record['error']}"
    outcome = str(record.get("outcome", ""))
    if "searches" in record:
        outcome += f", {record['searches']} searches"
        if record.get("rms") is not None:
            outcome += (
                f", RMS {record['rms']:.1f} m (energy-only {record['energy_only_rms']:.1f}), "
                f"+{100 * record['energy_increase']:.1f} % length"
            )
    return outcome


def print_table(
    results: dict[int, tuple[dict[str, dict[str, Any]], dict[str, dict[str, float]]]],
) -> None:
    header = (
        f"{'size':>6} {'row':<30} {'budget m':>8} {'bins':>4} {'cold s':>7} {'cache':>9} "
        f"{'warm CPU':>8} {'warm wall':>9} {'x A*':>6} {'x MCP':>6} {'labels':>10} "
        f"{'+MB':>6} {'MB':>6} {'route m':>8} {'peak σ':>6}  outcome"
    )
    print(header)
    print("-" * len(header))
    for n, (cold, warm) in results.items():
        for kind, record in cold.items():
            times = warm.get(kind, {})
            ratios = []
            for reference in ("astar", "mcp"):
                ref = warm.get(reference, {}).get("cpu_s")
                mine = times.get("cpu_s")
                ratios.append(mine / ref if mine is not None and ref else None)
            cache = "-"
            if "loaded" in record:
                cache = f"{record['loaded']}L/{record['compiled']}C"
            print(
                f"{n:>5}² {LABELS[kind]:<30} {_number(record.get('budget'), '8.2f'):>8} "
                f"{_number(record.get('bins'), '4d'):>4} {_number(record.get('cold_s'), '7.2f')} "
                f"{cache:>9} {_number(times.get('cpu_s'), '8.2f'):>8} "
                f"{_number(times.get('wall_s'), '9.2f'):>9} {_number(ratios[0], '6.1f'):>6} "
                f"{_number(ratios[1], '6.1f'):>6} {_number(record.get('labels'), '10d'):>10} "
                f"{_number(record.get('rss_increase_mb'), '6.0f'):>6} "
                f"{_number(record.get('peak_mb'), '6.0f'):>6} "
                f"{_number(record.get('cost'), '8.1f'):>8} {_number(record.get('peak'), '6.2f'):>6}"
                f"  {_outcome(record)}"
            )


def print_compile(n: int, cold: dict[str, dict[str, Any]], compiled: dict[str, Any]) -> None:
    for kind, record in compiled.items():
        if "error" in record or "error" in cold.get(kind, {"error": 1}):
            print(f"compile, {LABELS[kind]}: failed: {record.get('error')}")
            continue
        print(
            f"compile ({n}², empty NUMBA_CACHE_DIR), {LABELS[kind]}: first call "
            f"{record['cold_s']:.2f} s ({record['compiled']} kernels compiled) vs "
            f"{cold[kind]['cold_s']:.2f} s from the disk cache: compile ≈ "
            f"{record['cold_s'] - cold[kind]['cold_s']:.2f} s"
        )


def print_verdict(
    results: dict[int, tuple[dict[str, dict[str, Any]], dict[str, dict[str, float]]]],
) -> None:
    if TARGET_SIZE not in results:
        print(f"verdict: not measured at {TARGET_SIZE}² (the target's size); run without --quick")
        return
    cold, warm = results[TARGET_SIZE]
    budget = warm.get("budget 0.6")
    automatic = warm.get("automatic", {}).get("wall_s")
    if budget is None:
        print(f"verdict: the budget search at {TARGET_SIZE}² failed: {cold['budget 0.6']}")
        return
    met = "MET" if budget["wall_s"] <= TARGET_S else "MISSED"
    print(
        f"verdict: {TARGET_SIZE}² search with a budget (0.6 x peak), 1 vehicle, warm: "
        f"{budget['wall_s']:.1f} s wall ({budget['cpu_s']:.1f} s CPU) vs <= {TARGET_S:g} s: {met} "
        f"({budget['wall_s'] / TARGET_S:.1f}x the target); the automatic mode "
        f"{_number(automatic, '.1f')} s"
    )


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1000, TARGET_SIZE])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="1000² only (smoke)")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    parser.add_argument("--data", type=Path, help=argparse.SUPPRESS)
    parser.add_argument("--peak", type=float, help=argparse.SUPPRESS)
    parser.add_argument("--kinds", nargs="*", default=[], help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        child(args.child, args.data, args.peak, args.repeats, args.kinds)
        return 0
    sizes = [1000] if args.quick else args.sizes
    kinds = available_kinds()
    load = os.getloadavg()[0]
    print(
        f"{len(os.sched_getaffinity(0))} CPU(s), load average {load:.1f} at the start; "
        f"warm = median of {args.repeats} interleaved runs; ratios = warm CPU time / reference's"
        + ("" if "mcp" in kinds else "; scikit-image missing: no MCP_Geometric row"),
        flush=True,
    )
    results = {}
    compile_report: tuple[int, dict[str, dict[str, Any]], dict[str, Any]] | None = None
    for i, n in enumerate(sizes):
        cold, warm, compiled = measure(n, args.repeats, kinds, compile_times=i == 0)
        results[n] = (cold, warm)
        if compiled:
            compile_report = (n, cold, compiled)
    print(f"load average {os.getloadavg()[0]:.1f} at the end\n")
    print_table(results)
    print(
        "cache: kernels loaded (L) from the numba disk cache / compiled (C) in the cold call; "
        "+MB: peak resident memory of the cold call above the memory before it; MB: process peak"
    )
    if compile_report is not None:
        print_compile(*compile_report)
    print_verdict(results)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
