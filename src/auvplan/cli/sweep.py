"""``auvplan sweep MISSION -o DIR --vary KEY=v1,v2,... [--seeds A..B]``: sweeps on dask."""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

from auvplan.cli.evaluate import add_navigation_options, navigation_request
from auvplan.cli.plan import EXIT_NOT_CONVERGED, STAGES

if TYPE_CHECKING:  # the command line imports the sweep package only when it runs
    from auvplan.scenarios import Scenario
    from auvplan.sweep import (
        MissionBase,
        NavigationOptions,
        ParetoView,
        RunRecord,
        SweepProgress,
        SweepRun,
        VaryAxis,
    )

#: ``MISSION`` naming the public scenario family instead of a file.
SCENARIOS = "scenarios"


def register(subparsers: argparse._SubParsersAction[Any]) -> None:
    """Add the ``sweep`` verb."""
    parser = subparsers.add_parser(
        "sweep",
        help="plan a mission over a grid of parameter values, in parallel on dask",
        description="Plan every combination of the --vary values (x the --seeds) in parallel "
        "on a dask.distributed cluster (a local one by default). Each run writes the normal "
        "plan output into DIR/runs/<run-id>/; DIR/sweep.csv and sweep.json hold one row per "
        "run and DIR/pareto.png the energy/navigation trade-off. Runs finished by an earlier "
        "invocation are skipped (run the same command again to resume); failed runs are rows, "
        "not the end of the sweep. Exit code 0 when the sweep ran, 3 when every run failed, "
        "2 for a user error. Needs: pip install 'auvplan[sweep]'.",
    )
    parser.add_argument(
        "mission",
        metavar="MISSION",
        help="mission file (TOML), or the word 'scenarios' with --seeds for the public "
        "seeded scenario family (one generated mission per seed, written to DIR/scenarios/)",
    )
    parser.add_argument("-o", "--output", type=Path, required=True, help="output directory")
    parser.add_argument(
        "--vary",
        action="append",
        default=[],
        metavar="KEY=V1,V2,...",
        help="a mission key (as in 'auvplan keys': table.key, vehicle[1].start.speed) and "
        "its values, TOML-typed; repeat for more keys (the grid is their product)",
    )
    parser.add_argument(
        "--seeds",
        metavar="SEEDS",
        help="seeds, e.g. 0..49 or 0,3,7: with 'scenarios' each seed is a mission of the "
        "family; with a mission file the seed is only recorded in each row (for later "
        "Monte-Carlo evaluations), the plan does not depend on it",
    )
    cluster = parser.add_mutually_exclusive_group()
    cluster.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="address of a running dask scheduler (tcp://host:8786) instead of a local "
        "cluster; its workers must import auvplan and see DIR at the same path",
    )
    cluster.add_argument(
        "--workers",
        type=int,
        metavar="N",
        help="worker processes of the local cluster (default: the number of cores)",
    )
    parser.add_argument("--stage", choices=STAGES, default="full", help="stop each run here")
    parser.add_argument("--figures", action="store_true", help="also write each run's figures")
    navigation = parser.add_argument_group(
        "navigation (--evaluate)",
        "fly each plan through the terrain-aided navigation simulator, as 'auvplan evaluate' "
        "does, and put its TAN RMSE into the table and pareto.png; the Monte-Carlo seed is the "
        "row's seed (--seeds), else 0",
    )
    navigation.add_argument(
        "--evaluate",
        action="store_true",
        help="write navigation.json into every run folder (those with one of the same "
        "settings are kept)",
    )
    add_navigation_options(navigation)
    parser.add_argument(
        "--data-dir",
        type=Path,
        default=None,
        help="with 'scenarios': folder of the real bathymetry grids, holding at least one of "
        "them (as 'auvplan scenarios')",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Validate every run, run the sweep, write the table and the figure."""
    from auvplan.errors import InputError
    from auvplan.sweep import build_runs, parse_seeds, require_dask

    scenarios = args.mission == SCENARIOS
    if scenarios and args.seeds is None:
        raise InputError("sweeping 'scenarios' needs --seeds (e.g. --seeds 0..49)")
    if not args.vary and args.seeds is None:
        raise InputError("nothing to sweep: give --vary KEY=V1,V2,... and/or --seeds")
    if args.workers is not None and args.workers < 1:
        raise InputError(f"--workers must be at least 1, got {args.workers}")
    if args.evaluate and args.stage != "full":
        raise InputError(f"--evaluate needs the full plan, not --stage {args.stage}")
    if args.data_dir is not None:
        from auvplan.scenarios import check_data_dir

        check_data_dir(args.data_dir)
    navigation = _navigation(args)
    require_dask()
    seeds: tuple[int | None, ...] = (None,) if args.seeds is None else parse_seeds(args.seeds)
    base_of, scenario_files = _bases(args, seeds, scenarios=scenarios)
    axes, runs = build_runs(args.vary, seeds, base_of, stage=args.stage)

    def write_scenarios() -> None:  # only once every run is valid and the cluster answers
        for base, scenario in scenario_files:
            scenario.write(base.base_dir)

    started = time.perf_counter()
    records = _run(args, runs, navigation, on_ready=write_scenarios)
    return _finish(args, axes, records, seeds, time.perf_counter() - started, navigation)


def _bases(
    args: argparse.Namespace, seeds: tuple[int | None, ...], *, scenarios: bool
) -> tuple[Callable[[int | None], MissionBase], list[tuple[MissionBase, Scenario]]]:
    """The base mission of each seed and the scenario files to write before the runs."""
    from auvplan.sweep import mission_file_base, scenario_bases

    if not scenarios:
        base = mission_file_base(Path(args.mission))
        return (lambda _seed: base), []
    bases = scenario_bases([s for s in seeds if s is not None], args.output, data_dir=args.data_dir)
    return (lambda seed: bases[seed][0]), list(bases.values())


def _navigation(args: argparse.Namespace) -> NavigationOptions | None:
    """The evaluation of ``--evaluate``: local workers share the cores, remote ones get 1 each."""
    if not args.evaluate:
        return None
    threads = 1
    if args.scheduler is None:
        from auvplan.navigation.montecarlo import available_cpus

        cpus = available_cpus()
        threads = max(1, cpus // (args.workers or cpus))
    return navigation_request(args).options(None, seed=0, threads=threads)


def _run(
    args: argparse.Namespace,
    runs: Sequence[SweepRun],
    navigation: NavigationOptions | None,
    *,
    on_ready: Callable[[], None],
) -> list[RunRecord]:
    from auvplan.sweep import RunOptions, run_sweep

    write_figures = None
    if args.figures:
        from auvplan.viz.report import save_mission_figures

        write_figures = save_mission_figures
    options = RunOptions(
        stage=args.stage,
        write_figures=write_figures,
        quiet_logs=args.scheduler is None,
        navigation=navigation,
    )
    with _progress(len(runs), quiet=args.quiet) as progress:
        return run_sweep(
            runs, args.output, options=options, scheduler=args.scheduler,
            n_workers=args.workers, progress=progress, on_ready=on_ready,
        )  # fmt: skip


def _finish(
    args: argparse.Namespace,
    axes: Sequence[VaryAxis],
    records: Sequence[RunRecord],
    seeds: tuple[int | None, ...],
    wall_s: float,
    navigation: NavigationOptions | None,
) -> int:
    """Write sweep.csv/json and the Pareto files, print the summary, return the exit code."""
    from auvplan.io.output import staged_output_file
    from auvplan.sweep import (
        add_run_columns,
        json_rows,
        navigation_columns,
        pareto_view,
        sweep_frame,
        trade_off,
        write_pareto_table,
        write_sweep_files,
    )

    keys = [axis.key for axis in axes]
    frame = add_run_columns(sweep_frame(records, keys), navigation_columns)
    view = pareto_view(frame, keys, seeds_are_missions=args.mission == SCENARIOS)
    spec = {
        "mission": args.mission if args.mission == SCENARIOS else str(Path(args.mission).resolve()),
        "vary": {axis.key: list(axis.values) for axis in axes},
        "seeds": None if seeds == (None,) else list(seeds),
        "stage": args.stage,
        "scheduler": args.scheduler,
        "workers": args.workers,
        "figures": args.figures,
        "navigation": None if navigation is None else navigation.settings_document,
    }
    counts = _counts(records)
    output = args.output.resolve()
    best = None if view is None else trade_off(view)
    written = write_sweep_files(
        frame, output, spec=spec, counts=counts, wall_time_s=wall_s,
        pareto=None if view is None else json_rows(view.points), trade_off=best,
    )  # fmt: skip
    if view is not None:
        from auvplan.viz.sweep import plot_pareto

        with staged_output_file(output / "pareto.png") as staging:
            plot_pareto(view).savefig(staging, dpi=150)
        written.append(output / "pareto.png")
        written += write_pareto_table(
            view.points, output, label_key=view.label_key, objective=view.objective
        )
    if not args.quiet:
        for record in records:
            if record.navigation_error:
                print(f"navigation of {record.run_id} failed: {record.navigation_error}")
        statuses = ", ".join(f"{count} {status}" for status, count in counts["status"].items())
        print(
            f"sweep: {counts['runs']} runs ({counts['ran']} ran, {counts['skipped']} skipped "
            f"as finished before, {counts['failed']} failed): {statuses}; {wall_s:.1f} s"
        )
        if best is not None:
            _print_trade_off(best, view)
        print("wrote: " + ", ".join(str(path) for path in written))
    if counts["runs"] and counts["failed"] == counts["runs"]:
        print(f"auvplan: every run of the sweep failed (see {written[0]})", file=sys.stderr)
        return EXIT_NOT_CONVERGED
    return 0


def _print_trade_off(best: dict[str, dict[str, Any] | None], view: ParetoView | None) -> None:
    """One line each: the best point within +10 % energy, the cheapest reaching -30 %."""
    if view is None or view.points["improvement"].isna().all():
        return
    from auvplan.sweep import TAN_COLUMN

    objective = "TAN RMSE" if view.objective == TAN_COLUMN else "terrain information"

    def describe(point: dict[str, Any] | None) -> str:
        if point is None:
            return "none"
        where = f"{view.label_key} = {point['label']}" + (
            f" ({point['group']})" if point["group"] else ""
        )
        return (
            f"{where}: {objective} {100 * point['improvement']:.1f} % better for "
            f"{100 * point['energy_increase']:+.1f} % energy"
        )

    within, reaching = best["best_within_budget"], best["cheapest_reaching_target"]
    print(f"vs the energy-only plan, best within +10 % energy: {describe(within)}")
    print(f"cheapest plan with {objective} >= 30 % better: {describe(reaching)}")


def _counts(records: Sequence[RunRecord]) -> dict[str, Any]:
    statuses = Counter(record.status for record in records).most_common()
    return {
        "runs": len(records),
        "ran": sum(not record.skipped for record in records),
        "skipped": sum(record.skipped for record in records),
        "failed": sum(record.failed for record in records),
        "status": dict(statuses),
    }


@contextmanager
def _progress(total: int, *, quiet: bool) -> Iterator[Callable[[SweepProgress], None] | None]:
    """A rich progress bar on a terminal, one line per ended run otherwise, nothing if quiet."""
    if quiet:
        yield None
        return
    if not sys.stderr.isatty():
        yield _plain_line
        return
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    console = Console(stderr=True)
    with Progress(
        TextColumn("sweep"), BarColumn(), MofNCompleteColumn(), TextColumn("{task.fields[counts]}"),
        TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(), console=console,
    ) as bar:  # fmt: skip
        task = bar.add_task("sweep", total=total, counts="starting the cluster")

        def update(event: SweepProgress) -> None:
            if event.record is None:  # the start: runs finished before count as done
                bar.update(task, total=total - event.skipped)
            elif event.record.failed:
                bar.console.print(f"failed {_describe(event.record)}")
            ok = event.finished - event.failed
            bar.update(
                task,
                completed=event.finished,
                counts=f"{ok} finished, {event.failed} failed, {event.running} running"
                + (f", {event.skipped} skipped" if event.skipped else ""),
            )

        yield update


def _plain_line(event: SweepProgress) -> None:
    if event.record is None:
        print(
            f"sweep: {event.total} runs, {event.skipped} finished before, "
            f"{event.total - event.skipped} to run",
            flush=True,
        )
        return
    done = event.skipped + event.finished
    print(f"[{done}/{event.total}] {_describe(event.record)}", flush=True)


def _describe(record: RunRecord) -> str:
    wall = "" if record.wall_s is None else f" {record.wall_s:.1f} s"
    reason = f": {record.reason}" if record.reason else ""
    return f"{record.run_id}: {record.status}{wall}{reason}"
