"""``auvplan scenarios SEED... -o DIR [--kind reliability|transit]``: write seeded missions.

The public seeded scenario family (:func:`auvplan.scenarios.generate`): ``reliability`` (the
default) or ``transit`` (long transits beside rough features, or over a real grid).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any


def _seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError(f"seed must be a non-negative integer, got {text!r}")
    return value


def register(subparsers: argparse._SubParsersAction[Any]) -> None:
    """Add the ``scenarios`` verb to the command line."""
    parser = subparsers.add_parser(
        "scenarios",
        help="write missions of the seeded scenario family (to reproduce a benchmark run)",
        description="Write one folder DIR/seed_NNNN per seed with mission.toml (and terrain.nc "
        "for a generated terrain). Real grids are read from --data-dir when present; the "
        "family depends on whether they are. A --data-dir given must be a folder holding at "
        "least one of them.",
    )
    parser.add_argument("seeds", metavar="SEED", type=_seed, nargs="+", help="scenario seeds")
    parser.add_argument("-o", "--output", type=Path, required=True, help="output directory")
    parser.add_argument(
        "--data-dir",
        type=Path,
        default=None,
        help="folder of the real bathymetry grids, holding at least one of them (default: "
        "$AUVPLAN_SHARED_DATA/bathymetry, else ../shared/data/bathymetry, which may be absent)",
    )
    parser.add_argument(
        "--kind",
        choices=("reliability", "transit"),
        default="reliability",
        help="family kind: reliability (varied missions, the default) or transit (1-3 h, "
        "2-8 km transits of 1-4 MEDUSAs beside rough features, over a flat plain or a real grid)",
    )
    parser.set_defaults(run=run)


def scenario_folder(output: Path, seed: int) -> Path:
    """The folder of ``seed``'s scenario under ``output``."""
    return output / f"seed_{seed:04d}"


def run(args: argparse.Namespace) -> int:
    """Generate every scenario first, then write them; returns the exit code."""
    from auvplan.scenarios import check_data_dir, generate

    if args.data_dir is not None:
        check_data_dir(args.data_dir)
    scenarios = [generate(seed, data_dir=args.data_dir, kind=args.kind) for seed in args.seeds]
    for scenario in scenarios:
        path = scenario.write(scenario_folder(args.output, scenario.seed))
        if not args.quiet:
            print(f"{path}: {scenario.description}")
    return 0
