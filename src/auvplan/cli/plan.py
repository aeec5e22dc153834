"""``auvplan plan MISSION.toml -o DIR`` and ``auvplan demo [-o DIR]``."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from auvplan.cli.export import add_export_options
from auvplan.cli.figure_options import add_figure_options

STAGES = ("preplan", "deconflict", "full")
#: Exit code when the plan did not converge or breaks a constraint (user errors exit with 2).
EXIT_NOT_CONVERGED = 3


def register(subparsers: Any) -> None:
    """Add the ``plan`` and ``demo`` verbs."""
    plan = subparsers.add_parser(
        "plan",
        help="plan a mission from a TOML file",
        description="Run the pipeline (maps + A*, deconfliction, PRONTO) on a mission file.",
    )
    plan.add_argument("mission", type=Path, help="mission file (TOML)")
    _add_common(plan, default_output=None)
    add_export_options(plan, required=False)
    plan.set_defaults(run=run_plan)

    demo = subparsers.add_parser(
        "demo",
        help="plan the built-in default mission (the paper's scenario)",
        description="Two MEDUSAs cross the eastern rim of the synthetic volcanic bank.",
    )
    _add_common(demo, default_output=Path("out/demo"))
    demo.set_defaults(run=run_demo)


def _add_common(parser: argparse.ArgumentParser, *, default_output: Path | None) -> None:
    parser.add_argument(
        "-o",
        "--output",
        type=Path,
        required=default_output is None,
        default=default_output,
        help="output directory"
        + ("" if default_output is None else f" (default {default_output})"),
    )
    parser.add_argument("--stage", choices=STAGES, default="full", help="stop after this stage")
    parser.add_argument(
        "--jobs",
        type=int,
        default=None,
        help="processes: 2 (the default on 2+ cores) compiles the optimiser's kernels on a "
        "first run and draws half the figures in a second process, and runs the optimiser on "
        "two threads (or a decomposed fleet in two processes); 1 uses one core only "
        "(default also from $AUVPLAN_JOBS)",
    )
    parser.add_argument(
        "--compare-energy-only",
        action="store_true",
        help="also optimise without the terrain term (the energy-only reference)",
    )
    parser.add_argument(
        "--compare-paper",
        action="store_true",
        default=default_output is not None,  # the demo shows the paper's plan beside
        help="with navigation-aware routes (the default planner.edge_model): also plan on the "
        "paper's information-map routes (trajectories_paper.csv; on by default for demo)",
    )
    parser.add_argument(
        "--compare-no-current",
        action="store_true",
        help="with a [current]: also plan as if in still water, fly that plan in the current "
        "and report both energies and the saving",
    )
    parser.add_argument(
        "--no-figures", action="store_true", help="write no figures (report.html has tables only)"
    )
    add_figure_options(parser)


def run_plan(args: argparse.Namespace) -> int:
    """Load, validate and run the mission file."""
    from auvplan.mission.config import load_mission

    return _run(load_mission(args.mission), args)


def run_demo(args: argparse.Namespace) -> int:
    """Run the packaged demo mission."""
    from auvplan.mission.config import demo_mission

    return _run(demo_mission(), args)


def _run(config: Any, args: argparse.Namespace) -> int:
    """Plan ``config`` into ``--output``, print the report, and choose the exit code."""
    from auvplan.api.planning import plan_to_folder
    from auvplan.export import DEFAULT_TOLERANCE_M

    saved = plan_to_folder(
        config,
        args.output,
        stage=args.stage,
        compare_energy_only=args.compare_energy_only,
        compare_no_current=args.compare_no_current,
        compare_paper=args.compare_paper,
        progress=not args.quiet,
        jobs=args.jobs,
        figures=not args.no_figures,
        figure_format=args.figure_format,
        dpi=args.dpi,
        exports=getattr(args, "formats", None),  # demo: no --export
        tolerance_m=getattr(args, "tolerance_m", DEFAULT_TOLERANCE_M),
        moos_frame=getattr(args, "moos_frame", "utm"),
    )
    if not args.quiet:
        print_report(saved.result, saved.written)
    return exit_code(saved.result.problem)


def exit_code(problem: str | None) -> int:
    """0 for a plan that converged with every constraint met between samples; otherwise 3.

    The outputs are still written (the best plan found), the summary records the status and
    the violations, and one line on stderr names the first problem and what to change.
    """
    if problem is None:
        return 0
    print(f"auvplan: {problem}", file=sys.stderr)
    return EXIT_NOT_CONVERGED


def print_report(result: Any, written: tuple[Path, ...]) -> None:
    """Print the stage timings, the plan and its comparisons, and the files written."""
    out = sys.stdout
    print(f"stage: {result.stage.value}", file=out)
    for name, seconds in result.timings.items():
        print(f"  {name:<22s} {seconds:8.2f} s", file=out)
    plan = result.plan
    if plan is not None:
        print(
            f"optimiser: {plan.result.status.name}, {plan.result.n_iter} iterations; "
            f"plan {plan.verdict.status.name}",
            file=out,
        )
        for i, name in enumerate(result.preplan.names):
            closest = min(plan.separations[name].values(), default=float("nan"))
            print(
                f"  {name:<10s} energy {plan.energy[i]:9.1f} J"
                f"   info {plan.terrain_information[i]:.3f}"
                f"   arrival error {plan.arrival_error[i]:.2f} m   closest {closest:.2f} m",
                file=out,
            )
    paper = result.paper_plan
    if paper is not None:
        print(
            f"paper's plan (information-map routes): energy {paper.energy.sum():.1f} J, plan "
            f"{paper.verdict.status.name}",
            file=out,
        )
    comparison = result.current_comparison
    if comparison is not None:
        using, still = comparison.using_current.energy.sum(), comparison.still_water.energy.sum()
        print(
            f"current: flown energy {using:.1f} J using it, {still:.1f} J with the still-water "
            f"plan; saving {comparison.saving:.1f} J",
            file=out,
        )
    print("wrote: " + ", ".join(str(path) for path in written), file=out)
