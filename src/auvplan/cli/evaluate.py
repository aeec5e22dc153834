"""``auvplan evaluate OUTPUT_DIR``: terrain-aided navigation along the plans of an output folder.

Reads the folder of ``auvplan plan``/``demo`` (:func:`auvplan.record.read_record`: ``maps.nc``
and ``trajectories.csv``, and ``trajectories_energy_only.csv`` when the plan was run with
``--compare-energy-only``; stale or malformed files are refused), runs
Monte-Carlo particle-filter navigation along every vehicle's track and writes
``navigation.json`` and ``navigation.png`` (or ``.svg``/``.pdf``: ``--figure-format``) into the
same folder, all-or-nothing (:func:`auvplan.io.output.staged_output_dir`: the folder's other
files are kept): :func:`auvplan.api.navigation.evaluate_output_folder`.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

from auvplan.cli.figure_options import add_figure_options

if TYPE_CHECKING:  # the sweep package (pandas) is imported only when a command runs
    from auvplan.sweep.navigation import NavigationRequest


def register(subparsers: argparse._SubParsersAction[Any]) -> None:
    """Add the ``evaluate`` verb."""
    parser = subparsers.add_parser(
        "evaluate",
        help="simulate terrain-aided navigation along the plans of an output folder",
        description="Monte-Carlo terrain-aided navigation (particle filter, dead reckoning, "
        "altimeter or multibeam) along each vehicle's planned track; writes "
        "OUTPUT_DIR/navigation.json and OUTPUT_DIR/navigation.png.",
    )
    parser.add_argument(
        "output", metavar="OUTPUT_DIR", type=Path, help="output folder of 'plan' or 'demo'"
    )
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    add_navigation_options(parser)
    parser.add_argument("--no-figure", action="store_true", help="write navigation.json only")
    add_figure_options(parser)
    parser.set_defaults(run=run)


def add_navigation_options(parser: argparse.ArgumentParser) -> None:
    """The navigation system's options, shared by ``evaluate`` and ``sweep --evaluate``.

    The navigation model's flags default to the plan's ``[navigation]`` table (its defaults
    when the mission has none) and override it when given.
    """
    parser.add_argument(
        "--runs", type=int, default=100, help="Monte-Carlo runs per vehicle and plan (default 100)"
    )
    parser.add_argument(
        "--sensor",
        choices=("altimeter", "multibeam"),
        default=None,
        help="depth sensor (default: the mission's navigation.sensor, altimeter; multibeam: "
        "11 beams over 90 degrees)",
    )
    parser.add_argument(
        "--particles", type=int, default=5000, help="particles per filter (default 5000)"
    )
    parser.add_argument(
        "--update-period",
        type=float,
        default=None,
        help="seconds between updates (default: the mission's navigation.update_period_s, 3)",
    )
    parser.add_argument(
        "--initial-sigma",
        type=float,
        default=None,
        help="initial position error, standard deviation per axis [m] (default: the "
        "mission's navigation.initial_sigma_m, 7)",
    )
    parser.add_argument(
        "--drift",
        type=float,
        default=None,
        help="dead-reckoning drift, CEP in %% of distance travelled (default: the mission's "
        "navigation.drift_percent, 1)",
    )
    parser.add_argument(
        "--convergence-updates",
        type=int,
        default=200,
        help="updates with sigma <= 5 m in a row that count as converged (default 200, "
        "MB-System's rule)",
    )


def navigation_request(args: argparse.Namespace) -> NavigationRequest:
    """The :class:`~auvplan.sweep.NavigationRequest` of :func:`add_navigation_options`'s args.

    Raises
    ------
    InputError
        If ``--runs`` is below 1.
    """
    from auvplan.errors import InputError
    from auvplan.sweep.navigation import NavigationRequest

    if args.runs < 1:
        raise InputError(f"--runs must be >= 1, got {args.runs}")
    flags = {
        "sensor": args.sensor,
        "update_period_s": args.update_period,
        "initial_sigma_m": args.initial_sigma,
        "drift_percent": args.drift,
    }
    return NavigationRequest(
        {key: value for key, value in flags.items() if value is not None},
        n_runs=args.runs,
        particles=args.particles,
        convergence_updates=args.convergence_updates,
    )


def run(args: argparse.Namespace) -> int:
    """Evaluate the folder's plans and write the results; returns the exit code."""
    from auvplan.api.navigation import evaluate_output_folder

    evaluated = evaluate_output_folder(
        args.output,
        navigation_request(args),
        seed=args.seed,
        figure_format=None if args.no_figure else args.figure_format,
        dpi=args.dpi,
        progress=lambda total: _progress(total, args.runs, quiet=args.quiet),
    )
    if not args.quiet:
        _print_report(evaluated.document, evaluated.written)
    return 0


@contextmanager
def _progress(total: int, n_runs: int, *, quiet: bool) -> Iterator[Callable[[str, str, int], None]]:
    """A progress callback: a rich bar on a terminal, one line per finished track otherwise."""
    started = time.perf_counter()
    finished_tracks = 0

    def line(label: str, name: str, done: int) -> None:
        if done == n_runs and not quiet:
            print(f"{label} / {name}: {n_runs} runs ({time.perf_counter() - started:.1f} s)")

    if quiet or not sys.stderr.isatty():
        yield line
        return
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

    columns = (*Progress.get_default_columns()[:1], BarColumn(), MofNCompleteColumn())
    with Progress(*columns, TimeElapsedColumn(), console=Console(stderr=True)) as bar:
        task = bar.add_task("navigation", total=total)

        def update(label: str, name: str, done: int) -> None:
            nonlocal finished_tracks
            bar.update(
                task, completed=finished_tracks * n_runs + done, description=f"{label} / {name}"
            )
            if done == n_runs:
                finished_tracks += 1

        yield update


def _print_report(document: dict[str, Any], written: tuple[Path, ...]) -> None:
    def number(value: float | None, unit: str = "") -> str:
        return "n/a" if value is None else f"{value:.2f}{unit}"

    print(
        f"{'plan':<14s} {'energy':>10s} {'TAN RMSE':>16s} {'dead reck.':>11s} {'PCRB':>7s} "
        f"{'converged':>10s} {'diverged':>9s}"
    )
    for label, plan in document["plans"].items():
        print(
            f"{label:<14s} {plan['energy_J'] / 1e3:8.1f} kJ "
            f"{plan['rmse_m']:7.2f} ± {plan['rmse_std_m']:4.2f} m "
            f"{plan['dead_reckoning_rmse_m']:9.2f} m {plan['pcrb_rms_m']:5.2f} m "
            f"{plan['converged_fraction']:10.0%} {plan['divergence_rate']:9.1%}"
        )
    for key, label in (("comparison", "terrain-aware"), ("paper_comparison", "paper's plan")):
        comparison = document.get(key)
        if comparison is not None:
            print(
                f"{label} vs energy-only: TAN RMSE {-comparison['rmse_reduction']:+.1%}, "
                f"energy {comparison['energy_increase']:+.1%}"
            )
    convergence = {
        label: number(plan["convergence_time_s"], " s") for label, plan in document["plans"].items()
    }
    print("median convergence time: " + ", ".join(f"{k} {v}" for k, v in convergence.items()))
    print("wrote: " + ", ".join(str(path) for path in written))
