"""``auvplan vehicle``: headline characteristics of a vehicle type, and its validation figure."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from auvplan.vehicle.params import Propeller
    from auvplan.vehicle.trim import VehicleCharacteristics


def register(subparsers: argparse._SubParsersAction[Any]) -> None:
    """Add the ``vehicle`` verb to the command line."""
    parser = subparsers.add_parser(
        "vehicle",
        help="report a vehicle type's characteristics (bollard pull, speeds, power, turns)",
        description="Load a vehicle type (packaged name such as 'medusa' or 'remus100', or a "
        "vehicle TOML file) and report bollard thrust and torque at maximum propeller speed, "
        "top speed, energy-optimal cruise speed and its energy per metre, steady electrical "
        "power at 0.5 and 1.0 m/s, maximum steady yaw rate, the turning radius at full "
        "steering at the cruise speed, and the battery and the range it gives at that speed.",
    )
    parser.add_argument(
        "vehicle",
        metavar="TYPE|FILE",
        nargs="?",
        default="medusa",
        help="packaged vehicle type or vehicle file (default: medusa)",
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.add_argument(
        "--figure",
        metavar="PATH",
        type=Path,
        help="write the validation figure (format from the extension: .png, .pdf, .svg, ...)",
    )
    parser.add_argument(
        "--order",
        type=int,
        metavar="K",
        help="harmonics of the propeller series (default: the file's order, else all)",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Compute and print the characteristics; returns the exit code."""
    import json

    from auvplan.api.vehicle import describe_vehicle

    if args.figure is not None:
        _check_figure_path(args.figure)
    description = describe_vehicle(args.vehicle, propeller_order=args.order, figure=args.figure)
    if args.json:
        print(json.dumps(description.characteristics.to_document(), indent=2))
    elif not args.quiet:
        _print_table(description.characteristics, description.propeller)
    if args.figure is not None and not args.quiet and not args.json:
        print(f"wrote                      {args.figure}")
    return 0


def _check_figure_path(path: Path) -> None:
    """Refuse, before any work, a figure path that is a folder or has an unknown extension."""
    from matplotlib.backend_bases import FigureCanvasBase

    from auvplan.errors import InputError
    from auvplan.io.output import check_output_file

    check_output_file(path)
    supported = sorted(FigureCanvasBase.get_supported_filetypes())
    extension = path.suffix.lower().removeprefix(".")
    if extension not in supported:
        raise InputError(
            f"--figure {path}: unsupported extension {path.suffix!r} "
            f"(supported: {', '.join('.' + name for name in supported)})"
        )


def _print_table(table: VehicleCharacteristics, propeller: Propeller) -> None:
    from auvplan.io.vehicle_tables import UNITS
    from auvplan.vehicle.params import PropellerParams

    series = (
        f"propeller order {table.propeller_order}"
        if isinstance(propeller, PropellerParams)
        else f"propeller {propeller.name}, K_T and K_Q linear in J"
    )
    print(f"vehicle                    {table.name} ({series})")
    print(
        f"{f'bollard at {table.n_max:.1f} rev/s':<27}thrust {table.bollard_thrust:.2f} N, "
        f"torque {table.bollard_torque:.3f} N m per propeller; "
        f"electrical power {table.bollard_power:.0f} W"
    )
    print(f"top speed                  {table.top_speed:.3f} m/s (propellers at n_max)")
    print(
        f"energy-optimal cruise      {table.cruise_speed:.3f} m/s, "
        f"{table.cruise_energy_per_metre:.1f} J/m"
    )
    for speed, power, n in (
        (0.5, table.power_at_0_5, table.n_at_0_5),
        (1.0, table.power_at_1_0, table.n_at_1_0),
    ):
        print(
            f"{f'steady power at {speed:.1f} m/s':<27}{power:.1f} W "
            f"(hotel {table.hotel_power:.0f} W; n = {n:.1f} rev/s)"
        )
    print(f"max steady yaw rate        {table.max_yaw_rate:.3f} rad/s (full steering)")
    print(
        f"turning radius             {table.turning_radius:.2f} m "
        f"(full steering at the cruise speed {table.cruise_speed:.2f} m/s)"
    )
    print(
        f"depth profile              climb {table.climb_rate:.2f} m/s, dive "
        f"{table.dive_rate:.2f} m/s, at least {table.min_altitude:g} m above the seabed "
        "([vertical]; [mission] altitude_m)"
    )
    if table.battery_capacity is None or table.cruise_range is None:
        print("battery                    unknown (no [power] battery_capacity: no reserve check)")
    else:
        print(
            f"battery                    {table.battery_capacity / UNITS['J']['Wh']:.1f} Wh; "
            f"{table.cruise_range / 1e3:.2f} km at the energy-optimal cruise (still water)"
        )
