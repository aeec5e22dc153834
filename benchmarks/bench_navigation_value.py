"""What terrain-aided navigation is worth on long transits (issue 23, item 6).

Run::

    .venv/bin/python benchmarks/bench_navigation_value.py N [--first S] [--runs R]
        [--particles P] [--output DIR] [--data-dir D] [--jobs J] [--timeout T]

For seeds ``S .. S+N-1`` of the transit family (:func:`auvplan.scenarios.generate` with
``kind="transit"``: 1-3 h, 2-8 km, 1-4 MEDUSAs over a plain with rough features beside the
lines, a flat plain, or a real grid), one after another, each scenario is written to
``DIR/seed_NNNN/`` and

1. planned with ``auvplan plan mission.toml -o DIR/seed_NNNN/plan --compare-energy-only
   --no-figures -q --jobs J`` in a subprocess (wall time and exit code recorded; exit 3 means
   the plan was written but a constraint is unmet: it is still evaluated when its
   trajectories exist);
2. navigated with ``auvplan evaluate DIR/seed_NNNN/plan --runs R --particles P --no-figure
   -q``;
3. read back from ``navigation.json`` (per plan ``energy_J``, ``rmse_m``, and when present
   ``error_p95_m`` and ``predicted_rmse_m``) and ``summary.json`` (the plan's arrival error
   per vehicle, the plan statuses).

One row per seed: terrain and features (flat / offset / real), vehicles, distance, horizon,
the energy of the energy-only plan and of the mission's (terrain-aware) plan and its change,
the TAN RMSE of both and its change, each plan's 95th-percentile error, the plan's largest
goal (arrival) error, the plan's predicted and simulated RMSE, and the exit codes. Then the
medians of the RMSE and energy changes over all seeds, over seeds with features (offset and
real terrain) and over flat seeds; how many feature seeds cut the RMSE by at least 30 % for
at most 10 % more energy (issue 13's target); how many flat seeds stay within 1 % energy;
and the median ``|predicted / simulated - 1|`` over every evaluated plan. Rows are written to
``DIR/results.csv`` and ``DIR/results.json``.

Slow: a seed takes minutes (the optimiser over 1800-5400 steps per vehicle, twice, then
``2 x R x n_vehicles`` particle-filter runs).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import signal
import statistics
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from auvplan.cli.scenarios import scenario_folder
from auvplan.scenarios import Scenario, generate

#: ``navigation.json`` keys of the mission's plan and of the energy-only reference.
PLAN, ENERGY_ONLY = "terrain_aware", "energy_only"
#: Issue 13's target: the TAN RMSE cut by this fraction at most this energy increase.
TARGET_RMSE_CUT, TARGET_ENERGY_INCREASE = 0.30, 0.10
#: Flat seeds should cost no more (nor less) energy than this fraction.
FLAT_ENERGY_TOLERANCE = 0.01
#: Exit code of ``auvplan plan`` for a plan written with a constraint unmet.
EXIT_NOT_CONVERGED = 3


@dataclass
class Row:
    """One seed (a row of results.csv); energies [kJ], errors [m], changes [%]."""

    seed: int
    terrain: str
    features: str
    n_vehicles: int
    distance_km: float
    horizon_h: float
    description: str
    plan_exit: int | None = None
    plan_wall_s: float = float("nan")
    plan_status: str = ""
    energy_only_status: str = ""
    evaluate_exit: int | None = None
    evaluate_wall_s: float = float("nan")
    last_stderr: str = ""
    energy_only_kJ: float | None = None
    plan_kJ: float | None = None
    energy_change_pct: float | None = None
    rmse_energy_only_m: float | None = None
    rmse_plan_m: float | None = None
    rmse_change_pct: float | None = None
    p95_energy_only_m: float | None = None
    p95_plan_m: float | None = None
    goal_error_m: float | None = None
    predicted_energy_only_m: float | None = None
    predicted_plan_m: float | None = None
    ensemble_energy_only_m: float | None = None
    ensemble_plan_m: float | None = None
    goal_errors_m: dict[str, float] = field(default_factory=dict)

    @property
    def flat(self) -> bool:
        return self.features == "flat"

    def prediction_errors(self) -> list[float]:
        """``|predicted / simulated - 1|`` of each plan with both numbers.

        The predicted 1-σ radial error is the root of the expected squared error, so it is
        compared with the simulated root-mean-square error over every run and update
        (``error_rms_m``), not with the mean of the runs' RMSE (lower by Jensen's inequality).
        """
        pairs = (
            (self.predicted_plan_m, self.ensemble_plan_m),
            (self.predicted_energy_only_m, self.ensemble_energy_only_m),
        )
        return [abs(p / s - 1.0) for p, s in pairs if p is not None and s]

    def meets_target(self) -> bool:
        """RMSE cut by >= 30 % at <= 10 % more energy."""
        return (
            self.rmse_change_pct is not None
            and self.energy_change_pct is not None
            and self.rmse_change_pct <= -100.0 * TARGET_RMSE_CUT
            and self.energy_change_pct <= 100.0 * TARGET_ENERGY_INCREASE
        )


def _number(value: Any) -> float | None:
    return float(value) if isinstance(value, int | float) else None


def _change(new: float | None, old: float | None) -> float | None:
    """``100 (new / old - 1)`` [%], None when either is missing or ``old`` is 0."""
    return None if new is None or not old else 100.0 * (new / old - 1.0)


def _run(command: list[str], log: Path, timeout: float) -> tuple[int | None, float]:
    """``(exit code or None on timeout, wall time [s])`` of a subprocess, output in ``log``."""
    started = time.perf_counter()
    with log.open("w") as out:
        process = subprocess.Popen(command, stdout=out, stderr=subprocess.STDOUT)
        try:
            code: int | None = process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            process.send_signal(signal.SIGTERM)  # plan deletes its staging files on SIGTERM
            try:
                process.wait(timeout=30.0)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
            code = None
    return code, time.perf_counter() - started


def run_seed(scenario: Scenario, root: Path, args: argparse.Namespace) -> Row:
    """Write, plan, evaluate and read back one scenario."""
    assert scenario.distance_m is not None
    assert scenario.features is not None
    folder = scenario_folder(root, scenario.seed)
    mission = scenario.write(folder)
    row = Row(
        scenario.seed,
        scenario.terrain,
        scenario.features,
        scenario.n_vehicles,
        scenario.distance_m / 1e3,
        scenario.horizon_s / 3600.0,
        scenario.description,
    )
    output = folder / "plan"
    cli = [sys.executable, "-m", "auvplan.cli.main"]
    row.plan_exit, row.plan_wall_s = _run(
        [*cli, "plan", str(mission), "-o", str(output), "--compare-energy-only", "--no-figures",
         "-q", "--jobs", str(args.jobs)],
        folder / "plan.log",
        args.timeout,
    )  # fmt: skip
    lines = (folder / "plan.log").read_text(encoding="utf-8", errors="replace").splitlines()
    row.last_stderr = next((line for line in reversed(lines) if line.strip()), "")
    summary_path = output / "summary.json"
    if row.plan_exit in (0, EXIT_NOT_CONVERGED) and summary_path.is_file():
        _read_summary(row, json.loads(summary_path.read_text(encoding="utf-8")))
        if (output / "trajectories.csv").is_file():
            row.evaluate_exit, row.evaluate_wall_s = _run(
                [
                    *cli,
                    "evaluate",
                    str(output),
                    "--runs",
                    str(args.runs),
                    "--particles",
                    str(args.particles),
                    "--no-figure",
                    "-q",
                ],
                folder / "evaluate.log",
                args.timeout,
            )
    navigation_path = output / "navigation.json"
    if row.evaluate_exit == 0 and navigation_path.is_file():
        _read_navigation(row, json.loads(navigation_path.read_text(encoding="utf-8")))
    return row


def _read_summary(row: Row, summary: dict[str, Any]) -> None:
    """Statuses, energies and the plan's per-vehicle arrival error from summary.json."""
    plan, reference = summary.get("optimization", {}), summary.get("energy_only", {})
    row.plan_status = str(plan.get("plan_status", ""))
    row.energy_only_status = str(reference.get("plan_status", ""))
    for record, attribute in ((plan, "plan_kJ"), (reference, "energy_only_kJ")):
        total = _number(record.get("total_energy_J"))
        setattr(row, attribute, None if total is None else total / 1e3)
    row.goal_errors_m = {
        name: float(vehicle["arrival_error_m"])
        for name, vehicle in plan.get("vehicles", {}).items()
        if _number(vehicle.get("arrival_error_m")) is not None
    }
    row.goal_error_m = max(row.goal_errors_m.values(), default=None)
    row.energy_change_pct = _change(row.plan_kJ, row.energy_only_kJ)


def _read_navigation(row: Row, navigation: dict[str, Any]) -> None:
    """Energies, RMSEs, 95th percentiles and predictions of both plans from navigation.json."""
    plans = navigation.get("plans", {})
    for label, suffix in ((PLAN, "plan"), (ENERGY_ONLY, "energy_only")):
        record = plans.get(label)
        if record is None:
            continue
        energy = _number(record.get("energy_J"))
        if energy is not None:
            setattr(row, f"{suffix}_kJ", energy / 1e3)
        setattr(row, f"rmse_{suffix}_m", _number(record.get("rmse_m")))
        setattr(row, f"p95_{suffix}_m", _number(record.get("error_p95_m")))
        setattr(row, f"predicted_{suffix}_m", _number(record.get("predicted_rmse_m")))
        setattr(row, f"ensemble_{suffix}_m", _number(record.get("error_rms_m")))
    row.energy_change_pct = _change(row.plan_kJ, row.energy_only_kJ)
    row.rmse_change_pct = _change(row.rmse_plan_m, row.rmse_energy_only_m)


def _cell(value: float | None, digits: int = 1, sign: bool = False) -> str:
    if value is None or math.isnan(value):
        return "n/a"
    return f"{value:+.{digits}f}" if sign else f"{value:.{digits}f}"


COLUMNS: tuple[tuple[str, int, Callable[[Row], str]], ...] = (
    ("seed", 5, lambda r: str(r.seed)),
    ("terrain", 14, lambda r: f"{r.terrain}/{r.features}"),
    ("veh", 3, lambda r: str(r.n_vehicles)),
    ("km", 5, lambda r: f"{r.distance_km:.2f}"),
    ("h", 4, lambda r: f"{r.horizon_h:.2f}"),
    ("E eo kJ", 8, lambda r: _cell(r.energy_only_kJ)),
    ("E plan kJ", 9, lambda r: _cell(r.plan_kJ)),
    ("dE %", 6, lambda r: _cell(r.energy_change_pct, sign=True)),
    ("RMSE eo", 7, lambda r: _cell(r.rmse_energy_only_m, 2)),
    ("RMSE plan", 9, lambda r: _cell(r.rmse_plan_m, 2)),
    ("dRMSE %", 7, lambda r: _cell(r.rmse_change_pct, sign=True)),
    ("p95 eo", 6, lambda r: _cell(r.p95_energy_only_m, 2)),
    ("p95 plan", 8, lambda r: _cell(r.p95_plan_m, 2)),
    ("goal m", 6, lambda r: _cell(r.goal_error_m, 2)),
    ("pred/sim", 11, lambda r: f"{_cell(r.predicted_plan_m, 2)}/{_cell(r.ensemble_plan_m, 2)}"),
    ("exit", 6, lambda r: f"{_exit(r.plan_exit)}/{_exit(r.evaluate_exit)}"),
)


def _exit(code: int | None) -> str:
    return "-" if code is None else str(code)


def print_table(rows: Sequence[Row], out: Any = sys.stdout) -> None:
    """One line per seed (energy-only ``eo`` vs the mission's plan)."""
    print("  ".join(f"{name:>{width}}" for name, width, _ in COLUMNS), file=out)
    for row in rows:
        print("  ".join(f"{cell(row):>{width}}" for _, width, cell in COLUMNS), file=out)


def _median(values: Sequence[float | None]) -> float | None:
    present = [value for value in values if value is not None]
    return statistics.median(present) if present else None


def summarise(rows: Sequence[Row]) -> dict[str, Any]:
    """Medians by group, the success counts and the median prediction error."""
    groups = {
        "all": list(rows),
        "features": [row for row in rows if not row.flat],
        "flat": [row for row in rows if row.flat],
    }
    featured, flat = groups["features"], groups["flat"]
    within = [
        row
        for row in flat
        if row.energy_change_pct is not None
        and abs(row.energy_change_pct) <= 100.0 * FLAT_ENERGY_TOLERANCE
    ]
    return {
        "medians": {
            name: {
                "n": len(group),
                "rmse_change_pct": _median([row.rmse_change_pct for row in group]),
                "energy_change_pct": _median([row.energy_change_pct for row in group]),
            }
            for name, group in groups.items()
        },
        "target_met": [row.seed for row in featured if row.meets_target()],
        "n_features": len(featured),
        "flat_within_1pct": [row.seed for row in within],
        "n_flat": len(flat),
        "median_prediction_error": _median(
            [error for row in rows for error in row.prediction_errors()]
        ),
    }


def report(summary: dict[str, Any], out: Any = sys.stdout) -> None:
    """The summary rows."""
    print("\nmedians (change of the mission's plan over the energy-only plan):", file=out)
    for name, values in summary["medians"].items():
        print(
            f"  {name:<9} n = {values['n']:3d}   TAN RMSE "
            f"{_cell(values['rmse_change_pct'], sign=True):>6} %   energy "
            f"{_cell(values['energy_change_pct'], sign=True):>6} %",
            file=out,
        )
    met, n_features = summary["target_met"], summary["n_features"]
    print(
        f"RMSE cut >= {TARGET_RMSE_CUT:.0%} at energy <= +{TARGET_ENERGY_INCREASE:.0%}: "
        f"{len(met)}/{n_features} seeds with features {met}",
        file=out,
    )
    within, n_flat = summary["flat_within_1pct"], summary["n_flat"]
    print(
        f"flat seeds within {FLAT_ENERGY_TOLERANCE:.0%} energy: {len(within)}/{n_flat} {within}",
        file=out,
    )
    print(
        f"median |predicted / simulated RMSE - 1|: {_cell(summary['median_prediction_error'], 3)}",
        file=out,
    )


def write_results(
    rows: Sequence[Row], summary: dict[str, Any], root: Path, settings: dict[str, Any]
) -> None:
    """``results.json`` (settings, rows, summary) and ``results.csv`` (one row per seed)."""
    records = [asdict(row) | {"meets_target": row.meets_target(), "flat": row.flat} for row in rows]
    document = {"settings": settings, "rows": records, "summary": summary}
    (root / "results.json").write_text(json.dumps(document, indent=1), encoding="utf-8")
    with (root / "results.csv").open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(records[0]))
        writer.writeheader()
        writer.writerows(
            {
                key: json.dumps(value) if isinstance(value, dict) else value
                for key, value in record.items()
            }
            for record in records
        )


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("n", type=int, help="number of seeds")
    parser.add_argument("--first", type=int, default=0, help="first seed (default 0)")
    parser.add_argument("--runs", type=int, default=50, help="Monte-Carlo runs (default 50)")
    parser.add_argument(
        "--particles", type=int, default=5000, help="particles per filter (default 5000)"
    )
    parser.add_argument("--output", type=Path, default=Path("out/bench_navigation_value"))
    parser.add_argument("--data-dir", type=Path, default=None, help="real bathymetry grids")
    parser.add_argument(
        "--jobs", type=int, choices=(1, 2), default=2, help="processes of each plan (default 2)"
    )
    parser.add_argument(
        "--timeout", type=float, default=4 * 3600.0, help="per plan and per evaluation [s]"
    )
    args = parser.parse_args(argv)
    if args.n < 1:
        parser.error("N must be >= 1")
    args.output.mkdir(parents=True, exist_ok=True)
    seeds = range(args.first, args.first + args.n)
    scenarios = [generate(seed, data_dir=args.data_dir, kind="transit") for seed in seeds]
    print(
        f"{len(scenarios)} transit seeds {seeds.start}..{seeds.stop - 1}, {args.runs} runs, "
        f"plan --jobs {args.jobs}, output {args.output}",
        flush=True,
    )
    rows = []
    for scenario in scenarios:
        print(f"seed {scenario.seed:4d}: {scenario.description}", flush=True)
        row = run_seed(scenario, args.output, args)
        print(
            f"seed {row.seed:4d}: plan exit {_exit(row.plan_exit)} ({row.plan_status or '-'}) "
            f"in {row.plan_wall_s:.0f} s, evaluate exit {_exit(row.evaluate_exit)} in "
            f"{row.evaluate_wall_s:.0f} s; energy {_cell(row.energy_change_pct, sign=True)} %, "
            f"TAN RMSE {_cell(row.rmse_change_pct, sign=True)} %"
            + ("" if row.plan_exit in (0, EXIT_NOT_CONVERGED) else f"; {row.last_stderr}"),
            flush=True,
        )
        rows.append(row)
    print()
    print_table(rows)
    summary = summarise(rows)
    report(summary)
    settings = {k: str(v) if isinstance(v, Path) else v for k, v in vars(args).items()}
    write_results(rows, summary, args.output, settings)
    print(f"\nrows: {args.output / 'results.json'}, {args.output / 'results.csv'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
