"""The terrain-information maps of a bathymetry (paper Fig. 5), written as a folder.

:func:`write_terrain_maps` is what ``auvplan maps`` does: read the bathymetry
(:func:`auvplan.mission.preplan.read_terrain`, the loader of mission files too), compute the
information, excitation and cost maps (paper eqs. 13-15), and write ``maps.nc`` and the
figure of :func:`auvplan.viz.maps.plot_terrain_maps` all-or-nothing
(:func:`~auvplan.io.output.staged_output_dir`: other files already in the folder are kept).
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

from auvplan._figures import DEFAULT_DPI
from auvplan.io.maps_file import write_maps_netcdf
from auvplan.io.output import staged_output_dir
from auvplan.io.writing import writing
from auvplan.mission.preplan import read_terrain
from auvplan.record.files import MAPS_FILE
from auvplan.terrain import MapParameters, TerrainMaps, compute_terrain_maps
from auvplan.viz.maps import plot_terrain_maps
from auvplan.viz.report import render_figure


@dataclass(frozen=True)
class MapsFolder:
    """The maps written by :func:`write_terrain_maps` and the files written, under the target."""

    maps: TerrainMaps
    written: tuple[Path, ...]


def write_terrain_maps(
    bathymetry: str | Path | None,
    target: Path,
    *,
    parameters: MapParameters,
    seed: int = 7,
    window_north: tuple[float, float] | None = None,
    window_east: tuple[float, float] | None = None,
    window_lat: tuple[float, float] | None = None,
    window_lon: tuple[float, float] | None = None,
    figure_format: str = "png",
    dpi: int = DEFAULT_DPI,
) -> MapsFolder:
    """Compute the maps of ``bathymetry`` and write ``target/maps.nc`` and its figure.

    Parameters
    ----------
    bathymetry : str, Path or None
        Bathymetry file (NetCDF, GeoTIFF, ESRI ASCII grid, XYZ); None for the synthetic bank.
    target : Path
        The output folder; files of the same name are replaced, other files kept.
    parameters : MapParameters
        Exponent, excitation block [cells], shift and weight of the maps (eqs. 13-15).
    seed : int
        Seed of the synthetic bank.
    window_north, window_east : (float, float), optional
        Crop to these north and east ranges [m].
    window_lat, window_lon : (float, float), optional
        Crop to these latitude and longitude ranges [deg].
    figure_format : str
        ``"png"``, ``"svg"`` or ``"pdf"``: the figure is ``maps.<figure_format>``.
    dpi : int
        Resolution of the raster figure [dots per inch].

    Returns
    -------
    MapsFolder
        The maps, and ``target/maps.nc`` and ``target/maps.<figure_format>``.

    Raises
    ------
    InputError, DataFormatError
        For a bathymetry that cannot be read or cropped, or parameters out of range; nothing
        is written.
    """
    grid = read_terrain(
        bathymetry,
        seed=seed,
        window_north=window_north,
        window_east=window_east,
        window_lat=window_lat,
        window_lon=window_lon,
    )
    maps = compute_terrain_maps(grid, parameters)
    figure = render_figure(plot_terrain_maps(maps), figure_format=figure_format, dpi=dpi)
    figure_name = f"maps.{figure_format}"
    with staged_output_dir(target) as staging:
        write_maps_netcdf(maps, staging / MAPS_FILE, created=datetime.now(UTC))
        with writing(staging / figure_name):
            (staging / figure_name).write_bytes(figure.data)
    return MapsFolder(maps, (target / MAPS_FILE, target / figure_name))
