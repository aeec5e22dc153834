"""Replanning against planning from scratch: 4 MEDUSAs for an hour, replanned at 30 min.

The mission is ``fleet-4-3600-1`` of :mod:`_fleet` (four MEDUSAs on crossing lanes, 1 h,
``dt_s`` 1 s). The 10-minute case is planned first to fill the kernel cache (the same
vehicles and settings), then the mission is planned (timed: the plan from scratch) and
saved; the saved folder is replanned at ``t = 1800 s`` with vehicle ``v0`` 30 m east of where
its plan has it (``auvplan.load(folder).replan``: the folder is read, its mission pre-planned
again and its stage-2 schedule read from ``summary.json``, then the rest is optimised), and
the plan in memory is replanned the same way (no stage 1 again). No timed run writes files
or figures. Target: the replan within 25 % of the plan from scratch. Run as a script
(minutes; ``nice`` it on a shared machine)::

    nice .venv/bin/python benchmarks/bench_replan.py           # 4 MEDUSAs x 1 h at 30 min
    nice .venv/bin/python benchmarks/bench_replan.py --quick   # 4 MEDUSAs x 10 min at 5 min
    nice .venv/bin/python benchmarks/bench_replan.py --fleet16 # 16 MEDUSAs x 1 h, decomposed

It prints one JSON line per measurement and a summary table of wall and CPU (process, all
threads) seconds; on a loaded shared machine the CPU ratio is the steadier one.
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

import auvplan
from _fleet import lane_mission  # the script's folder is on sys.path

#: The missions (vehicles, horizon [s], dt [s]) and their replanning times [s].
CASES = {
    "full": ((4, 3600.0, 1.0), 1800.0),
    "quick": ((4, 600.0, 1.0), 300.0),
    "fleet16": ((16, 3600.0, 1.0), 1800.0),
}
#: The vehicle moved and by how much (north, east) [m].
MOVED = ("v0", 0.0, 30.0)
TARGET = 0.25


def _outcome(plan: auvplan.MissionPlan, started: tuple[float, float], label: str) -> dict[str, Any]:
    """The run's record; ``started``: ``(perf_counter, process_time)`` when it began [s]."""
    assert plan.result is not None
    optimized = plan.result.plan
    return {
        "run": label,
        "wall_s": time.perf_counter() - started[0],
        "cpu_s": time.process_time() - started[1],
        "timings_s": plan.result.timings,
        "status": plan.status,
        "problem": plan.result.problem,
        "iterations": None if optimized is None else optimized.result.n_iter,
        "objective_J": None if optimized is None else optimized.costs.total,
        "energy_J": None if optimized is None else float(np.sum(optimized.energy)),
        "schedule": plan.summary.get("replan", {}).get("schedule"),
    }


def _clocks() -> tuple[float, float]:
    """Wall and process (CPU, all threads) clocks now [s]."""
    return time.perf_counter(), time.process_time()


def states_file(plan: auvplan.MissionPlan, at: float, folder: Path) -> Path:
    """``STATES.csv`` with :data:`MOVED`'s vehicle moved from its plan's state at ``at`` [s]."""
    name, north, east = MOVED
    frame = plan.to_dataframe()
    row = frame[(frame["vehicle"] == name) & (np.isclose(frame["t"], at))].iloc[0]
    path = folder / "states.csv"
    path.write_text(
        "vehicle,north,east,heading_deg,speed\n"
        f"{name},{row['north'] + north},{row['east'] + east},{row['heading']},{row['u']}\n"
    )
    return path


def measure(case: tuple[int, float, float], at: float, scratch: Path) -> list[dict[str, Any]]:
    """Plan ``case`` from scratch, save, replan at ``at`` from the folder and in memory."""
    warm = scratch / "warm"
    warm.mkdir()
    auvplan.plan(lane_mission(*CASES["quick"][0], warm), progress=False)  # the kernel cache
    mission = lane_mission(*case, scratch)
    started = _clocks()
    parent = auvplan.plan(mission, progress=False)
    records = [_outcome(parent, started, "plan from scratch")]
    folder = scratch / "parent"
    parent.save(folder, figures=False)
    states = states_file(parent, at, scratch)
    started = _clocks()
    replanned = auvplan.load(folder).replan(at, states, progress=False)
    records.append(_outcome(replanned, started, "replan from folder"))
    started = _clocks()
    in_memory = parent.replan(at, states, progress=False)
    records.append(_outcome(in_memory, started, "replan in memory"))
    return records


def report(case: tuple[int, float, float], at: float, records: list[dict[str, Any]]) -> None:
    """Print each record as a JSON line and the table of wall-time ratios."""
    for record in records:
        print(json.dumps(record), flush=True)
    scratch, scratch_cpu = records[0]["wall_s"], records[0]["cpu_s"]
    n, horizon, dt = case
    print(
        f"\n{n} MEDUSAs x {horizon:g} s (dt {dt:g} s), replanned at {at:g} s with {MOVED[0]} "
        f"moved ({MOVED[1]:g}, {MOVED[2]:g}) m; target replan <= {TARGET:.0%} of scratch"
    )
    for record in records:
        print(
            f"  {record['run']:<20s} {record['wall_s']:8.1f} s  {record['wall_s'] / scratch:6.1%}"
            f"  (CPU {record['cpu_s']:6.1f} s {record['cpu_s'] / scratch_cpu:6.1%})"
            f"  {record['status']}  {record['iterations']} it  objective "
            f"{record['objective_J']:.0f} J  schedule {record['schedule']}"
        )


if __name__ == "__main__":
    flags = [arg.removeprefix("--") for arg in sys.argv[1:]]
    case, at = CASES[next((flag for flag in flags if flag in CASES), "full")]
    with tempfile.TemporaryDirectory() as work:
        report(case, at, measure(case, at, Path(work)))
