"""``auvplan export OUTPUT_DIR --format FORMAT,... [-o DIR] [--tolerance-m X] [--moos-frame F]``."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from auvplan.errors import InputError
from auvplan.export import DEFAULT_TOLERANCE_M, FORMATS, MOOS_FRAMES, check_tolerance


def tolerance_m(text: str) -> float:
    """A waypoint tolerance [m] within :func:`auvplan.export.check_tolerance` (argparse type)."""
    try:
        value = float(text)
        check_tolerance(value)
    except InputError as error:  # a ValueError too: first
        raise argparse.ArgumentTypeError(str(error)) from None
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a distance in m, got {text!r}") from None
    return value


def add_export_options(parser: argparse.ArgumentParser, *, required: bool) -> None:
    """``--format`` (``--export`` for ``plan``) and ``--tolerance-m``."""
    flag = "--format" if required else "--export"
    parser.add_argument(
        flag,
        dest="formats",
        required=required,
        metavar="FORMAT,...",
        help=f"export formats, comma-separated: {', '.join(FORMATS)}"
        + ("" if required else " (written into OUTPUT/export)"),
    )
    parser.add_argument(
        "--tolerance-m",
        type=tolerance_m,
        default=DEFAULT_TOLERANCE_M,
        help="largest distance between the exported waypoints, flown at their leg speeds, and "
        f"the plan at any time [m] (default {DEFAULT_TOLERANCE_M:g})",
    )
    parser.add_argument(
        "--moos-frame",
        choices=MOOS_FRAMES,
        default=MOOS_FRAMES[0],
        help="frame of the MOOS-IvP points: utm (MOOS-IvP's default build, -DUSE_UTM=ON) or "
        "local (a build with LatLong2LocalGrid) (default utm)",
    )


def register(subparsers: Any) -> None:
    """Add the ``export`` verb."""
    export = subparsers.add_parser(
        "export",
        help="export a finished plan for vehicles, ground stations and GIS",
        description="Write the optimised plan of an output folder as MOOS-IvP behaviours, "
        "QGroundControl plans (ArduSub), Neptus/IMC plans, GPX, KML or GeoJSON.",
    )
    export.add_argument("folder", type=Path, help="output folder of auvplan plan")
    export.add_argument(
        "-o", "--output", type=Path, default=None, help="export folder (default FOLDER/export)"
    )
    add_export_options(export, required=True)
    export.set_defaults(run=run_export)


def run_export(args: argparse.Namespace) -> int:
    """Read the folder's plan and write the exports all-or-nothing."""
    from auvplan.export import check_georeference, parse_formats, write_exports
    from auvplan.io.output import staged_output_dir
    from auvplan.record import export_plan, read_record
    from auvplan.record.files import EXPORT_FOLDER

    formats = parse_formats(args.formats)
    record = read_record(args.folder)
    plan = export_plan(record)
    if not plan.is_georeferenced:
        check_georeference(formats, args.moos_frame, f"the terrain {record.summary.terrain.name!r}")
    target = args.output if args.output is not None else args.folder / EXPORT_FOLDER
    with staged_output_dir(target) as staging:
        written = write_exports(
            plan, staging, formats, tolerance=args.tolerance_m, moos_frame=args.moos_frame
        )
    if not args.quiet:
        print("wrote: " + ", ".join(str(target / path.name) for path in written), file=sys.stdout)
    return 0
