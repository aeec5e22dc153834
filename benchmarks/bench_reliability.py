"""Reliability of ``auvplan plan`` on the public seeded scenario family (issue 11).

Run::

    .venv/bin/python benchmarks/bench_reliability.py N [--first-seed S] [--jobs 1]
        [--timeout 1800] [--max-horizon-s T] [--output DIR] [--data-dir DIR]
        [--edge-model navigation|paper|crossed] [--fleet auto|coupled|decomposed]
        [--vehicle TYPE] [--headings-all-round]

For seeds ``S .. S+N-1`` (with ``--max-horizon-s``, seeds whose horizon is longer are skipped
and the following seeds taken instead, until N scenarios ran), each scenario of
:func:`auvplan.scenarios.generate` is written to ``DIR/seed_NNNN/`` and planned with
``auvplan plan mission.toml -o DIR/seed_NNNN/plan --no-figures`` in a subprocess (killed after
the timeout). Exit code, the last line of stderr, wall time and the child's peak RSS
(``os.wait4``) are recorded; on exit 0 and 3 the plan is checked independently
(:func:`auvplan.scenarios.check`). A run is a success when the optimiser CONVERGED and every
check passes. Failure classes: ``exit 2 (bug)`` (a valid mission refused as a user error),
``exit 3 (<status>)``, ``timeout``, ``traceback (<exception>)``, ``check failed (<kinds>)``.

Prints the success rate, a table of failure classes with counts and seeds, and the median and
95th percentile of wall time and peak memory; writes the rows to ``DIR/results.json`` and
``DIR/results.csv``. ``--edge-model`` plans every scenario on those routes instead of its own
draw (the family draws the paper's and the crossed edge model; ``navigation`` is the default
of a mission that names none); ``--fleet`` solves every fleet coupled or vehicle by vehicle.
``--vehicle`` flies every scenario with that vehicle type instead of MEDUSAs (e.g.
``remus100``), and ``--headings-all-round`` draws each start heading uniformly in
``(−180°, 180°]`` (seeded by the scenario's seed) instead of about the line to the goal.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import json
import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from auvplan.cli.scenarios import scenario_folder
from auvplan.errors import AuvplanError
from auvplan.scenarios import Scenario, check, generate
from auvplan.scenarios.family import VEHICLE_NAMES

#: Seeds looked at per requested scenario before giving up on the horizon filter.
SEARCH_FACTOR = 50


@dataclass
class Row:
    """One benchmark run (a row of results.csv)."""

    seed: int
    terrain: str
    n_vehicles: int
    horizon_s: float
    dt_s: float
    description: str
    exit_code: int | None = None
    timed_out: bool = False
    wall_s: float = float("nan")
    peak_rss_mb: float = float("nan")
    last_stderr: str = ""
    status: str = ""
    failure_class: str = ""
    check_failures: list[str] = field(default_factory=list)
    min_separation_margin_m: float | None = None
    max_position_defect_m: float | None = None
    max_arrival_error_m: float | None = None

    @property
    def success(self) -> bool:
        return self.failure_class == "success"


def select_scenarios(
    n: int, first_seed: int, max_horizon: float | None, data_dir: Path | None
) -> list[Scenario]:
    """``n`` scenarios from ``first_seed`` on (skipping horizons above ``max_horizon``)."""
    chosen: list[Scenario] = []
    for seed in range(first_seed, first_seed + SEARCH_FACTOR * n):
        scenario = generate(seed, data_dir=data_dir)
        if max_horizon is None or scenario.horizon_s <= max_horizon:
            chosen.append(scenario)
        if len(chosen) == n:
            break
    return chosen


def run_plan(mission: Path, output: Path, timeout: float) -> tuple[int | None, bool, float, float]:
    """``(exit code, timed out, wall time [s], peak RSS [MB])`` of one ``auvplan plan`` run."""
    command = [
        sys.executable, "-m", "auvplan.cli.main", "plan", str(mission), "-o", str(output),
        "--no-figures",
    ]  # fmt: skip
    folder = mission.parent
    with (folder / "stdout.log").open("w") as out, (folder / "stderr.log").open("w") as err:
        started = time.perf_counter()
        process = subprocess.Popen(command, stdout=out, stderr=err, start_new_session=True)
        timed_out = False
        while True:
            pid, status, usage = os.wait4(process.pid, os.WNOHANG)
            if pid:
                break
            if time.perf_counter() - started > timeout:
                os.killpg(process.pid, signal.SIGKILL)
                pid, status, usage = os.wait4(process.pid, 0)
                timed_out = True
                break
            time.sleep(0.2)
        wall = time.perf_counter() - started
    process.returncode = os.waitstatus_to_exitcode(status)
    code = None if timed_out else process.returncode
    return code, timed_out, wall, usage.ru_maxrss / 1024.0  # ru_maxrss is in KiB on Linux


def _normalised(message: str) -> str:
    """A stderr line with numbers and vehicle names blanked, to group similar failures."""
    message = message.removeprefix("auvplan: error: ").removeprefix("auvplan: ")
    message = re.sub(r"[-+]?\d+(\.\d+)?(e[-+]?\d+)?", "#", message)
    message = re.sub(r"\b(" + "|".join(VEHICLE_NAMES) + r")\b", "<v>", message)
    return message[:90]


def classify(row: Row, stderr: str) -> str:
    """The failure class of a finished run (``"success"`` when it is one)."""
    if row.timed_out:
        return "timeout"
    if "Traceback (most recent call last)" in stderr:
        return f"traceback ({row.last_stderr.split(':')[0]})"
    if row.exit_code == 2:
        return f"exit 2 (bug): {_normalised(row.last_stderr)}"
    if row.exit_code == 3:
        return f"exit 3 ({row.status or _normalised(row.last_stderr)})"
    if row.exit_code != 0:
        return f"exit {row.exit_code}: {_normalised(row.last_stderr)}"
    if row.check_failures:
        kinds = sorted({failure.split(":")[0] for failure in row.check_failures})
        return f"check failed ({', '.join(kinds)})"
    return "success" if row.status == "CONVERGED" else f"exit 0 ({row.status})"


def run_scenario(
    scenario: Scenario,
    root: Path,
    timeout: float,
    edge_model: str | None = None,
    fleet: str | None = None,
    vehicle: str | None = None,
    headings_all_round: bool = False,
) -> Row:
    """Write, plan and check one scenario (its routes' ``edge_model``, its ``solver.fleet``
    and its vehicles' ``type`` replaced if given; start headings drawn all round if asked)."""
    for table, key, value in (("planner", "edge_model", edge_model), ("solver", "fleet", fleet)):
        if value is not None:
            entries = {**scenario.mission.get(table, {}), key: value}
            scenario = dataclasses.replace(scenario, mission={**scenario.mission, table: entries})
    if vehicle is not None or headings_all_round:
        rng = np.random.default_rng(scenario.seed)
        vehicles = []
        for table in scenario.mission["vehicle"]:
            start = dict(table["start"])
            if headings_all_round:
                start["heading_deg"] = round(float(rng.uniform(-180.0, 180.0)), 1)
            vehicles.append({**table, "start": start, "type": vehicle or table["type"]})
        scenario = dataclasses.replace(scenario, mission={**scenario.mission, "vehicle": vehicles})
    folder = scenario_folder(root, scenario.seed)
    mission = scenario.write(folder)
    row = Row(
        scenario.seed,
        scenario.terrain,
        scenario.n_vehicles,
        scenario.horizon_s,
        scenario.dt_s,
        scenario.description,
    )
    output = folder / "plan"
    row.exit_code, row.timed_out, row.wall_s, row.peak_rss_mb = run_plan(mission, output, timeout)
    stderr = (folder / "stderr.log").read_text(encoding="utf-8", errors="replace")
    lines = [line for line in stderr.splitlines() if line.strip()]
    row.last_stderr = lines[-1] if lines else ""
    if row.exit_code in (0, 3):
        try:
            report = check(output, mission=mission)
        except (AuvplanError, OSError, KeyError, ValueError) as error:
            row.check_failures = [f"check error: {error}"]
        else:
            row.status = report.status
            row.check_failures = [f"{f.kind}: {f.message}" for f in report.failures]
            margins = [d - report.separation_limit_m for d in report.min_separation_m.values()]
            row.min_separation_margin_m = min(margins, default=None)
            row.max_position_defect_m = max(report.max_position_defect_m.values())
            row.max_arrival_error_m = max(report.arrival_error_m.values())
    row.failure_class = classify(row, stderr)
    return row


def report(rows: Sequence[Row], out: Any = sys.stdout) -> None:
    """Print the success rate, failure classes, and wall-time / memory percentiles."""
    n = len(rows)
    successes = sum(row.success for row in rows)
    print(
        f"\nsuccess (CONVERGED and all checks pass): {successes}/{n} = {successes / n:.0%}",
        file=out,
    )
    classes: dict[str, list[int]] = {}
    for row in rows:
        if not row.success:
            classes.setdefault(row.failure_class, []).append(row.seed)
    if classes:
        width = max(len(name) for name in classes)
        print(f"\n{'failure class':<{width}}  count  seeds", file=out)
        for name, seeds in sorted(classes.items(), key=lambda item: -len(item[1])):
            print(f"{name:<{width}}  {len(seeds):5d}  {', '.join(map(str, seeds))}", file=out)
    wall = np.array([row.wall_s for row in rows])
    memory = np.array([row.peak_rss_mb for row in rows])
    print(
        f"\nwall time [s]:     median {np.median(wall):8.1f}   95th percentile "
        f"{np.percentile(wall, 95):8.1f}\npeak memory [MB]:  median {np.median(memory):8.1f}   "
        f"95th percentile {np.percentile(memory, 95):8.1f}",
        file=out,
    )


def write_results(rows: Sequence[Row], root: Path, settings: dict[str, Any]) -> None:
    """``results.json`` (settings + rows) and ``results.csv`` (one row per scenario)."""
    records = [asdict(row) | {"success": row.success} for row in rows]
    (root / "results.json").write_text(
        json.dumps({"settings": settings, "rows": records}, indent=1), encoding="utf-8"
    )
    with (root / "results.csv").open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(records[0]))
        writer.writeheader()
        writer.writerows(
            {**record, "check_failures": " | ".join(record["check_failures"])} for record in records
        )


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("n", type=int, help="number of scenarios")
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--jobs", type=int, default=1, help="plans run at once")
    parser.add_argument("--timeout", type=float, default=1800.0, help="per plan [s]")
    parser.add_argument("--max-horizon-s", type=float, default=None, help="skip longer missions")
    parser.add_argument("--output", type=Path, default=Path("out/bench_reliability"))
    parser.add_argument("--data-dir", type=Path, default=None, help="real bathymetry grids")
    parser.add_argument(
        "--edge-model",
        choices=("navigation", "paper", "crossed"),
        default=None,
        help="plan every scenario with these routes (default: each scenario's own draw)",
    )
    parser.add_argument(
        "--fleet",
        choices=("auto", "coupled", "decomposed"),
        default=None,
        help="solve every scenario's fleet so (solver.fleet; default: the mission's own)",
    )
    parser.add_argument("--vehicle", default=None, help="fly every scenario with this type")
    parser.add_argument(
        "--headings-all-round", action="store_true", help="start headings drawn uniformly"
    )
    args = parser.parse_args(argv)
    scenarios = select_scenarios(args.n, args.first_seed, args.max_horizon_s, args.data_dir)
    args.output.mkdir(parents=True, exist_ok=True)
    print(
        f"{len(scenarios)} scenarios, seeds {[s.seed for s in scenarios]}, timeout "
        f"{args.timeout:g} s, {args.jobs} job(s)",
        flush=True,
    )

    def one(scenario: Scenario) -> Row:
        row = run_scenario(
            scenario, args.output, args.timeout, args.edge_model, args.fleet, args.vehicle,
            args.headings_all_round,
        )  # fmt: skip
        print(
            f"seed {row.seed:4d}  {row.failure_class:<40.40s} {row.wall_s:7.1f} s "
            f"{row.peak_rss_mb:7.0f} MB  {row.description}",
            flush=True,
        )
        return row

    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        rows = list(pool.map(one, scenarios))
    settings = {k: str(v) if isinstance(v, Path) else v for k, v in vars(args).items()}
    write_results(rows, args.output, settings)
    report(rows)
    print(f"\nrows: {args.output / 'results.json'}, {args.output / 'results.csv'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
