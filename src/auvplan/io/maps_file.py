"""Writing and reading ``maps.nc``: the terrain maps with CF-style metadata (SPEC §8).

Layout (NetCDF-4, CF-1.8):

* fine grid, coordinates ``north(north)``, ``east(east)`` [m]: ``depth`` (standard name
  ``sea_floor_depth_below_sea_surface``, positive down) and ``information``;
* coarse (block) grid, coordinates ``north_block``, ``east_block`` [m]: ``excitation``,
  ``cost`` and ``shifted_cost``;
* global attributes: the map parameters (``information_exponent``, ``block_north``,
  ``block_east``, ``omega``, ``weight``), ``source``, ``Conventions``, and, when the grid has
  one, its projection (``projection_lat_0``, ``projection_lon_0``, ``projection_offset_north``,
  ``projection_offset_east``, ``projection_ellipsoid``).

The file is also a valid bathymetry input: :func:`auvplan.io.bathymetry.read_bathymetry`
reads its ``depth`` and projection back.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from auvplan import __version__
from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError
from auvplan.terrain.grid import BathymetryGrid, GridGeometry
from auvplan.terrain.maps import MapParameters, TerrainMaps
from auvplan.terrain.projection import LocalProjection


def write_maps_netcdf(maps: TerrainMaps, path: str | Path) -> Path:
    """Write the terrain maps to a CF-1.8 NetCDF-4 file.

    Parameters
    ----------
    maps : TerrainMaps
        The maps to write.
    path : str or Path
        Output file (usually ``DIR/maps.nc``); overwritten if it exists.

    Returns
    -------
    Path
        ``path``.
    """
    import xarray as xr

    path = Path(path)
    fine, coarse = maps.bathymetry.geometry, maps.cost_geometry
    parameters = maps.parameters

    def coordinate(values: FloatArray, name: str, long_name: str) -> xr.Variable:
        axis = "Y" if name.startswith("north") else "X"
        return xr.Variable(
            (name,),
            values,
            {"units": "m", "long_name": long_name, "axis": axis},
        )

    coords = {
        "north": coordinate(fine.north, "north", "distance north of the map origin"),
        "east": coordinate(fine.east, "east", "distance east of the map origin"),
        "north_block": coordinate(coarse.north, "north_block", "block centre north of origin"),
        "east_block": coordinate(coarse.east, "east_block", "block centre east of origin"),
    }
    fine_dims, coarse_dims = ("north", "east"), ("north_block", "east_block")
    data_vars = {
        "depth": xr.Variable(
            fine_dims,
            maps.bathymetry.depth,
            {
                "units": "m",
                "standard_name": "sea_floor_depth_below_sea_surface",
                "long_name": "depth of the sea floor (NaN: land or no data)",
                "positive": "down",
            },
        ),
        "information": xr.Variable(
            fine_dims,
            maps.information,
            {
                "units": "1",
                "long_name": "terrain information map M_I = (|grad depth| / max)^s (eq. 13)",
            },
        ),
        "excitation": xr.Variable(
            coarse_dims,
            maps.excitation,
            {"units": "1", "long_name": "excitation map M_E: block mean of M_I (eq. 14)"},
        ),
        "cost": xr.Variable(
            coarse_dims,
            maps.cost,
            {"units": "1", "long_name": "cost map M_C = cos(pi/2 M_E)"},
        ),
        "shifted_cost": xr.Variable(
            coarse_dims,
            maps.shifted_cost,
            {"units": "1", "long_name": "shifted cost map omega + w M_C (eq. 15)"},
        ),
    }
    attributes: dict[str, str | float | int] = {
        "Conventions": "CF-1.8",
        "title": "auvplan terrain-information maps",
        "source": maps.bathymetry.name,
        "history": f"created by auvplan {__version__}",
        "references": "Häusler et al., Cooperative AUV Motion Planning using Terrain "
        "Information, OCEANS 2013, Sec. III-A",
        "information_exponent": float(parameters.exponent),
        "block_north": int(parameters.block[0]),
        "block_east": int(parameters.block[1]),
        "omega": float(parameters.omega),
        "weight": float(parameters.weight),
        "spacing_north_m": float(fine.spacing_north),
        "spacing_east_m": float(fine.spacing_east),
    }
    projection = maps.bathymetry.projection
    if projection is not None:
        attributes.update(
            {
                "projection": "transverse Mercator centred on the map (PROJ tmerc, k=1)",
                "projection_lat_0": float(projection.lat_0),
                "projection_lon_0": float(projection.lon_0),
                "projection_offset_north": float(projection.offset_north),
                "projection_offset_east": float(projection.offset_east),
                "projection_ellipsoid": projection.ellipsoid,
            }
        )
    dataset = xr.Dataset(data_vars, coords, attributes)
    encoding = {name: {"zlib": True, "complevel": 4} for name in data_vars}
    dataset.to_netcdf(path, format="NETCDF4", engine="netcdf4", encoding=encoding)
    return path


def read_maps_netcdf(path: str | Path) -> TerrainMaps:
    """Read a file written by :func:`write_maps_netcdf` back into :class:`TerrainMaps`.

    Parameters
    ----------
    path : str or Path
        A ``maps.nc`` file.

    Returns
    -------
    TerrainMaps
        The maps, grids, projection and parameters as written.

    Raises
    ------
    DataFormatError
        If the file is missing or is not an auvplan maps file.
    """
    import xarray as xr

    path = Path(path)
    try:
        dataset = xr.open_dataset(path, engine="netcdf4")
    except (OSError, ValueError) as error:
        raise DataFormatError(f"maps file {path}: cannot open ({error})") from None
    with dataset:
        try:
            north, east = dataset["north"].values, dataset["east"].values
            north_block = dataset["north_block"].values
            east_block = dataset["east_block"].values
            attrs = dataset.attrs
            parameters = MapParameters(
                float(attrs["information_exponent"]),
                (int(attrs["block_north"]), int(attrs["block_east"])),
                float(attrs["omega"]),
                float(attrs["weight"]),
            )
            arrays = {
                name: np.asarray(dataset[name].values, dtype=np.float64)
                for name in ("depth", "information", "excitation", "cost", "shifted_cost")
            }
            projection = None
            if "projection_lat_0" in attrs:
                projection = LocalProjection(
                    float(attrs["projection_lat_0"]),
                    float(attrs["projection_lon_0"]),
                    float(attrs["projection_offset_north"]),
                    float(attrs["projection_offset_east"]),
                    str(attrs["projection_ellipsoid"]),
                )
            source = str(attrs.get("source", path.name))
            fine = GridGeometry(
                north.size,
                east.size,
                float(attrs["spacing_north_m"]),
                float(attrs["spacing_east_m"]),
                float(north[0]),
                float(east[0]),
            )
        except KeyError as error:
            raise DataFormatError(f"maps file {path}: missing {error}") from None
    coarse = GridGeometry(
        north_block.size,
        east_block.size,
        fine.spacing_north * parameters.block[0],
        fine.spacing_east * parameters.block[1],
        float(north_block[0]),
        float(east_block[0]),
    )
    bathymetry = BathymetryGrid(arrays["depth"], fine, projection, None, source)
    return TerrainMaps(
        bathymetry,
        arrays["information"],
        arrays["excitation"],
        arrays["cost"],
        arrays["shifted_cost"],
        coarse,
        parameters,
    )
