"""``auvplan replan OUTPUT_DIR --at SECONDS [--states STATES.csv] -o NEW_DIR``."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from auvplan.cli.figure_options import add_figure_options
from auvplan.cli.plan import exit_code, print_report


def seconds(text: str) -> float:
    """A finite time in seconds (argparse type)."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}")
    return value


def register(subparsers: Any) -> None:
    """Add the ``replan`` verb."""
    parser = subparsers.add_parser(
        "replan",
        help="plan the rest of a plan from where its vehicles are at a given time",
        description="Replan the plan of OUTPUT_DIR from time --at (seconds into the plan): "
        "the vehicles listed in --states start from those states, the others where the plan "
        "has them; the goals, the horizon's end and the constraints are kept. Exit code 3 "
        "when the new plan is not usable (a vehicle can no longer make it, or a constraint "
        "is violated); the folder is written.",
    )
    parser.add_argument("folder", type=Path, help="output folder of the plan to replan")
    parser.add_argument(
        "--at", type=seconds, required=True, help="time into the plan [s] the new plan starts at"
    )
    parser.add_argument(
        "--states",
        type=Path,
        default=None,
        help="CSV of the vehicles' states at --at: vehicle,north,east,heading_deg,speed (or "
        "lat,lon for north,east); vehicles not listed start where the plan has them",
    )
    parser.add_argument("-o", "--output", type=Path, required=True, help="new output folder")
    parser.add_argument(
        "--no-figures", action="store_true", help="write no figures (report.html has tables only)"
    )
    parser.add_argument(
        "--jobs",
        type=int,
        default=None,
        help="cores: 2 (the default on 2+ cores) runs the optimiser on two threads (a "
        "decomposed fleet in two processes); 1 uses one (default also from $AUVPLAN_JOBS)",
    )
    add_figure_options(parser)
    parser.set_defaults(run=run_replan)


def run_replan(args: argparse.Namespace) -> int:
    """Replan ``folder`` into ``--output``, print the report, and choose the exit code."""
    from auvplan.api.replanning import replan_to_folder

    saved = replan_to_folder(
        args.folder,
        args.at,
        args.states,
        args.output,
        progress=not args.quiet,
        figures=not args.no_figures,
        figure_format=args.figure_format,
        dpi=args.dpi,
        jobs=args.jobs,
    )
    if not args.quiet:
        print_report(saved.result, saved.written)
    return exit_code(saved.result.problem)
