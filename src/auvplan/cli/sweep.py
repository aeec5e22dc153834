"""``auvplan sweep MISSION -o DIR --vary KEY=v1,v2,... [--seeds A..B]``: sweeps on dask."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

from auvplan.cli.evaluate import add_navigation_options, navigation_request
from auvplan.cli.plan import EXIT_NOT_CONVERGED, STAGES

if TYPE_CHECKING:  # the command line imports the sweep package only when it runs
    from auvplan.api.sweep import SweepOutcome
    from auvplan.sweep import ParetoView, SweepProgress


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
        "family; with a mission file the plan does not depend on the seed: each mission is "
        "planned once, and with --evaluate evaluated with every seed (one row per seed)",
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
    """Check the flags, run the sweep, print its summary and return the exit code."""
    from auvplan.api.sweep import SCENARIOS, sweep_to_folder
    from auvplan.errors import InputError

    if args.mission == SCENARIOS and args.seeds is None:
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
    outcome = sweep_to_folder(
        args.mission, args.output, vary=args.vary, seeds=args.seeds, stage=args.stage,
        scheduler=args.scheduler, workers=args.workers, figures=args.figures,
        navigation=navigation_request(args) if args.evaluate else None,
        data_dir=args.data_dir, progress=lambda total: _progress(total, quiet=args.quiet),
    )  # fmt: skip
    if not args.quiet:
        _print_summary(outcome)
    if outcome.all_failed:
        print(f"auvplan: every run of the sweep failed (see {outcome.written[0]})", file=sys.stderr)
        return EXIT_NOT_CONVERGED
    return 0


def _print_summary(outcome: SweepOutcome) -> None:
    """Failed evaluations, the counts, the trade-off and the files written."""
    counts = outcome.counts
    for record in outcome.records:
        if record.navigation_error:
            print(f"navigation of {record.run_id} failed: {record.navigation_error}")
    statuses = ", ".join(f"{count} {status}" for status, count in counts["status"].items())
    print(
        f"sweep: {counts['runs']} runs ({counts['ran']} ran, {counts['skipped']} skipped "
        f"as finished before, {counts['failed']} failed), {counts['planned']} planned: "
        f"{statuses}; {outcome.wall_s:.1f} s"
    )
    if outcome.trade_off is not None:
        _print_trade_off(outcome.trade_off, outcome.view)
    print("wrote: " + ", ".join(str(path) for path in outcome.written))


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


@contextmanager
def _progress(total: int, *, quiet: bool) -> Iterator[Callable[[SweepProgress], None] | None]:
    """A rich progress bar on a terminal, one line per ended run otherwise, nothing if quiet."""
    if quiet:
        yield None
    elif not sys.stderr.isatty():
        yield _plain_line
    else:
        from auvplan.api.sweep import progress_bar

        with progress_bar(total) as update:
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
    print(f"[{done}/{event.total}] {event.record.description}", flush=True)
