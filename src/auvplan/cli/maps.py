"""``auvplan maps``: terrain-information maps (paper Fig. 5) from a bathymetry file.

Writes ``DIR/maps.nc`` and ``DIR/maps.png`` (or ``.svg``/``.pdf``, ``--figure-format``)
all-or-nothing (:func:`auvplan.api.maps.write_terrain_maps`): ``DIR`` is checked before any
work (by :mod:`auvplan.cli.main`) and replaced as a whole at the end (other files already in
``DIR`` are kept); on any error nothing is written.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

from auvplan.cli.figure_options import add_figure_options

if TYPE_CHECKING:
    from auvplan.terrain.maps import TerrainMaps


def register(subparsers: argparse._SubParsersAction[Any]) -> None:
    """Add the ``maps`` verb to the command line."""
    parser = subparsers.add_parser(
        "maps",
        help="compute the terrain-information maps (paper Fig. 5) of a bathymetry",
        description="Read a bathymetric grid (NetCDF, GeoTIFF, ESRI ASCII grid, XYZ) or the "
        "embedded synthetic bank, compute the information, excitation and cost maps "
        "(paper eqs. 13-15) and write DIR/maps.nc and DIR/maps.png.",
    )
    parser.add_argument(
        "bathymetry", metavar="BATHYMETRY", help="bathymetry file, or 'synthetic' for the bank"
    )
    parser.add_argument("-o", "--output", metavar="DIR", type=Path, required=True)
    parser.add_argument("--seed", type=int, default=7, help="seed of the synthetic bank")
    window = parser.add_argument_group("window (crop)")
    window.add_argument("--window-north", nargs=2, type=float, metavar=("S", "N"), help="[m]")
    window.add_argument("--window-east", nargs=2, type=float, metavar=("W", "E"), help="[m]")
    window.add_argument("--window-lat", nargs=2, type=float, metavar=("S", "N"), help="[deg]")
    window.add_argument("--window-lon", nargs=2, type=float, metavar=("W", "E"), help="[deg]")
    maps = parser.add_argument_group("map parameters (paper eqs. 13-15)")
    maps.add_argument("--s", type=float, default=1.0, dest="exponent", help="exponent s of M_I")
    maps.add_argument(
        "--block",
        nargs=2,
        type=int,
        default=(2, 2),
        metavar=("RN", "RE"),
        help="excitation block size in cells (north, east)",
    )
    maps.add_argument("--omega", type=float, default=10.0, help="cost shift omega (> 0)")
    maps.add_argument("--w", type=float, default=10.0, dest="weight", help="cost weight w (>= 0)")
    add_figure_options(parser)
    parser.set_defaults(run=run)


def _pair(values: list[float] | None) -> tuple[float, float] | None:
    return None if values is None else (float(values[0]), float(values[1]))


def run(args: argparse.Namespace) -> int:
    """Compute the maps and write them; returns the exit code."""
    from auvplan.api.maps import write_terrain_maps
    from auvplan.terrain import MapParameters

    folder = write_terrain_maps(
        None if args.bathymetry == "synthetic" else args.bathymetry,
        args.output,
        parameters=MapParameters(
            exponent=args.exponent,
            block=(int(args.block[0]), int(args.block[1])),
            omega=args.omega,
            weight=args.weight,
        ),
        seed=args.seed,
        window_north=_pair(args.window_north),
        window_east=_pair(args.window_east),
        window_lat=_pair(args.window_lat),
        window_lon=_pair(args.window_lon),
        figure_format=args.figure_format,
        dpi=args.dpi,
    )
    if not args.quiet:
        _print_summary(folder.maps, folder.written)
    return 0


def _print_summary(maps: TerrainMaps, written: tuple[Path, ...]) -> None:
    import numpy as np

    fine, coarse = maps.bathymetry.geometry, maps.cost_geometry
    depth = maps.bathymetry.depth
    cost = maps.shifted_cost
    print(f"bathymetry   {maps.bathymetry.name}")
    print(
        f"grid         {fine.n_rows} x {fine.n_cols} cells of {fine.spacing_north:.2f} m (N) x "
        f"{fine.spacing_east:.2f} m (E); {np.isnan(depth).mean():.1%} no-go"
    )
    print(f"depth        {np.nanmin(depth):.1f} … {np.nanmax(depth):.1f} m")
    print(
        f"cost grid    {coarse.n_rows} x {coarse.n_cols} blocks of {coarse.spacing_north:.2f} m x "
        f"{coarse.spacing_east:.2f} m; shifted cost {np.nanmin(cost):.2f} … {np.nanmax(cost):.2f}"
    )
    print(f"wrote        {', '.join(str(path) for path in written)}")
