"""Writing and reading ``maps.nc``: the terrain maps as a CF-1.8 NetCDF-4 file (SPEC §8).

Layout:

* fine grid, coordinate variables ``north(north)``, ``east(east)`` [m] (standard names
  ``projection_y_coordinate`` / ``projection_x_coordinate``, no ``_FillValue``): ``depth``
  (standard name ``sea_floor_depth_below_sea_surface``, positive down; ``vertical_datum``,
  the source's, when it names one) and ``information``;
* coarse (block) grid, coordinate variables ``north_block``, ``east_block`` [m]:
  ``excitation``, ``cost`` and ``shifted_cost``;
* when the grid is georeferenced: the grid mapping variable ``crs`` (the local frame's
  :attr:`~auvplan.terrain.projection.LocalProjection.crs`, written by rioxarray's
  ``write_crs`` from :meth:`pyproj.CRS.to_cf`, with its WKT) of the fine maps, the same
  frame as ``crs_block`` of the block maps, and the 2-D auxiliary coordinates ``lat``/``lon``
  and ``lat_block``/``lon_block`` [deg, WGS 84], so GIS software (QGIS, GDAL, rioxarray)
  places the maps. The block axes then carry no ``axis``/``standard_name`` (see
  :func:`_axes`): GDAL places the block maps by ``crs_block``'s ``GeoTransform``
  (rioxarray's ``write_transform``), rioxarray once told their dimensions
  (``.rio.set_spatial_dims("east_block", "north_block")``);
* global attributes: the map parameters (``information_exponent``, ``block_north``,
  ``block_east``, ``omega``, ``weight``), the fine spacing, ``source``, ``Conventions``, and
  the ACDD-1.3 discovery attributes (extent, ``id``, dates; who made the maps only as the
  mission's ``[metadata]`` gives it), shared with ``trajectories.nc`` by
  :mod:`auvplan.io._discovery`; each variable has its ``coverage_content_type``.

The file is also a valid bathymetry input: :func:`auvplan.io.bathymetry.read_bathymetry`
reads its ``depth`` and local frame back.
"""

from __future__ import annotations

from collections.abc import Mapping
from datetime import datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any, Final

import numpy as np

from auvplan._version import __version__
from auvplan.errors import DataFormatError
from auvplan.io._discovery import content_id, geospatial_attributes, run_attributes
from auvplan.io._gridded import VERTICAL_DATUM, grid_mapping_crs
from auvplan.io.writing import writing
from auvplan.terrain.grid import BathymetryGrid, GridGeometry
from auvplan.terrain.maps import MapParameters, TerrainMaps
from auvplan.terrain.projection import LocalProjection

if TYPE_CHECKING:
    import xarray as xr

#: Name of the CF grid mapping variable of the local frame (fine maps).
GRID_MAPPING: Final = "crs"
#: Name of the CF grid mapping variable of the block maps: the same frame, with the block
#: grid's GDAL ``GeoTransform``.
BLOCK_GRID_MAPPING: Final = "crs_block"
#: The maps on the coarse (block) grid.
_BLOCK_MAPS: Final = ("excitation", "cost", "shifted_cost")
#: ACDD ``coverage_content_type`` of the data variables (the others are coordinates).
_CONTENT_TYPES: Final = {
    "depth": "physicalMeasurement",
    "information": "modelResult",
    **dict.fromkeys(_BLOCK_MAPS, "modelResult"),
}


def write_maps_netcdf(
    maps: TerrainMaps,
    path: str | Path,
    *,
    metadata: Mapping[str, str] | None = None,
    created: datetime | None = None,
) -> Path:
    """Write the terrain maps to a CF-1.8 NetCDF-4 file with ACDD-1.3 discovery attributes.

    Parameters
    ----------
    maps : TerrainMaps
        The maps to write.
    path : str or Path
        Output file (usually ``DIR/maps.nc``); overwritten if it exists.
    metadata : mapping of str to str, optional
        Who made the maps: ACDD attributes by name (the mission's ``[metadata]``); an
        attribute computed here takes precedence.
    created : datetime, optional
        Time the maps were made (time-zone aware): ``date_created`` and the other ACDD dates
        (none when not given).

    Returns
    -------
    Path
        ``path``.
    """
    import xarray as xr

    path = Path(path)
    fine, coarse = maps.bathymetry.geometry, maps.cost_geometry
    parameters = maps.parameters
    projection = maps.bathymetry.projection
    coords = {
        **_axes(fine, "", "of the map origin", is_cf_axis=True),
        **_axes(
            coarse, "_block", "of the map origin (block centre)", is_cf_axis=projection is None
        ),
    }
    fine_dims, coarse_dims = ("north", "east"), ("north_block", "east_block")
    datum = maps.bathymetry.attributes.get(VERTICAL_DATUM)
    data_vars = {
        "depth": xr.Variable(
            fine_dims,
            maps.bathymetry.depth,
            {
                "units": "m",
                "standard_name": "sea_floor_depth_below_sea_surface",
                "long_name": "depth of the sea floor (NaN: land or no data)",
                "positive": "down",
                **({VERTICAL_DATUM: datum} if datum is not None else {}),
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
    source = maps.bathymetry.name or "auvplan"
    attributes: dict[str, Any] = {
        **run_attributes(metadata, created),
        "Conventions": "CF-1.8, ACDD-1.3",
        "title": "auvplan terrain-information maps",
        "summary": f"Terrain-information maps of the bathymetry {source} for terrain-aided "
        f"path planning, computed by auvplan: the seabed depth and the information map on a "
        f"{fine.n_rows} x {fine.n_cols} grid of {fine.spacing_north:g} m x "
        f"{fine.spacing_east:g} m cells, the excitation and cost maps on blocks of "
        f"{parameters.block[0]} x {parameters.block[1]} cells.",
        "keywords": "bathymetry, terrain information, terrain-aided navigation, cost map, "
        "path planning, autonomous underwater vehicle, AUV",
        "id": content_id(maps.bathymetry.depth, maps.information, maps.shifted_cost),
        "source": source,
        "processing_level": "maps computed from the bathymetry (model output); the depth as "
        "read from the source",
        "history": f"created by auvplan {__version__}",
        "references": "Häusler et al., Cooperative AUV Motion Planning using Terrain "
        "Information, OCEANS 2013, Sec. III-A",
        "acknowledgment": "Method: Häusler, Saccon, Pascoal, Hauser and Aguiar, Cooperative AUV "
        f"Motion Planning using Terrain Information, OCEANS 2013; bathymetry: {source}",
        "comment": "north/east: metres from the map origin (the south-west node) in the local "
        "frame, a transverse Mercator centred on the map (grid_mapping variable crs)",
        "information_exponent": float(parameters.exponent),
        "block_north": int(parameters.block[0]),
        "block_east": int(parameters.block[1]),
        "omega": float(parameters.omega),
        "weight": float(parameters.weight),
        "spacing_north_m": float(fine.spacing_north),
        "spacing_east_m": float(fine.spacing_east),
    }
    dataset = xr.Dataset(data_vars, coords, attributes)
    if projection is not None:
        dataset = _georeference(dataset, projection, fine, coarse)
    is_georeferenced = projection is not None
    dataset.attrs |= geospatial_attributes(
        dataset["lat"].values if is_georeferenced else None,
        dataset["lon"].values if is_georeferenced else None,
        maps.bathymetry.depth,
        vertical_crs=None,  # the depth's datum is the source's, not always an EPSG datum
    )
    for name, variable in dataset.variables.items():
        if name not in (GRID_MAPPING, BLOCK_GRID_MAPPING):
            variable.attrs["coverage_content_type"] = _CONTENT_TYPES.get(str(name), "coordinate")
    # Encodings replace those set by rioxarray (the grid_mapping reference): merge them.
    compressed = {"zlib": True, "complevel": 4}
    encoding: dict[str, dict[str, object]] = {
        str(name): {**variable.encoding, **(compressed if variable.ndim == 2 else {})}
        for name, variable in dataset.variables.items()
    }
    for name in dataset.coords:  # CF: no _FillValue on coordinates
        encoding[str(name)]["_FillValue"] = None
    for name in (GRID_MAPPING, BLOCK_GRID_MAPPING):
        if name in dataset.coords:
            encoding[name]["dtype"] = "int32"  # CF 1.8 has no 64-bit integers
    with writing(Path(path)):
        dataset.to_netcdf(path, format="NETCDF4", engine="netcdf4", encoding=encoding)
    return path


def _axes(
    geometry: GridGeometry, suffix: str, where: str, *, is_cf_axis: bool
) -> dict[str, xr.Variable]:
    """The coordinate variables ``north<suffix>``, ``east<suffix>`` [m] of a grid.

    A CF axis (``is_cf_axis``) also carries ``axis`` Y/X and the standard name
    ``projection_y/x_coordinate``, by which GDAL and rioxarray find the grid's position.
    With a grid mapping only the fine grid's axes are CF axes: the IOOS compliance checker
    (6.1) accepts a single variable per standard name ``projection_x/y_coordinate``
    (ioos/compliance-checker#691, although CF 1.8 allows several) and takes an ``axis`` Y/X
    variable without one for latitude/longitude, so the block axes are then plain
    coordinate variables (``units``, ``long_name``) and the block maps are placed by their
    own grid mapping ``crs_block`` (:func:`_georeference`).
    """
    import xarray as xr

    variables = {}
    for axis, cf_axis, values in (("north", "Y", geometry.north), ("east", "X", geometry.east)):
        attributes = {"units": "m", "long_name": f"distance {axis} {where}"}
        if is_cf_axis:
            attributes |= {
                "axis": cf_axis,
                "standard_name": f"projection_{cf_axis.lower()}_coordinate",
            }
        variables[f"{axis}{suffix}"] = xr.Variable((f"{axis}{suffix}",), values, attributes)
    return variables


def _georeference(
    dataset: xr.Dataset, projection: LocalProjection, fine: GridGeometry, coarse: GridGeometry
) -> xr.Dataset:
    """Add the grid mapping variables and the 2-D ``lat``/``lon`` auxiliary coordinates.

    ``crs`` (the local frame) is the grid mapping of the fine maps; ``crs_block``, the same
    frame with the GDAL ``GeoTransform`` of the block grid (west and south cell edges,
    spacings > 0: rows run south to north as stored), that of the block maps, whose axes
    are not CF axes (:func:`_axes`).
    """
    import rioxarray  # noqa: F401  (registers the .rio accessor)
    import xarray as xr
    from affine import Affine

    for geometry, suffix, where in ((fine, "", ""), (coarse, "_block", " of the block centre")):
        north, east = np.meshgrid(geometry.north, geometry.east, indexing="ij")
        lat, lon = projection.to_geographic(north, east)
        dims = (f"north{suffix}", f"east{suffix}")
        dataset = dataset.assign_coords(
            {
                f"lat{suffix}": xr.Variable(
                    dims,
                    lat,
                    {
                        "units": "degrees_north",
                        "standard_name": "latitude",
                        "long_name": f"latitude (WGS 84){where}",
                    },
                ),
                f"lon{suffix}": xr.Variable(
                    dims,
                    lon,
                    {
                        "units": "degrees_east",
                        "standard_name": "longitude",
                        "long_name": f"longitude (WGS 84){where}",
                    },
                ),
            }
        )
    # rioxarray sets a grid_mapping on the variables whose x/y dimensions it finds: the
    # fine maps here, the block maps once their dimensions are named.
    georeferenced: xr.Dataset = dataset.rio.write_crs(
        projection.crs, grid_mapping_name=GRID_MAPPING
    )
    # x = west + spacing_east * column, y = south + spacing_north * row
    south_up = Affine(
        coarse.spacing_east,
        0.0,
        coarse.east_bounds[0],
        0.0,
        coarse.spacing_north,
        coarse.north_bounds[0],
    )
    blocks: xr.Dataset = (
        georeferenced[list(_BLOCK_MAPS)]
        .rio.set_spatial_dims(x_dim="east_block", y_dim="north_block")
        .rio.write_crs(projection.crs, grid_mapping_name=BLOCK_GRID_MAPPING)
        .rio.write_transform(south_up, grid_mapping_name=BLOCK_GRID_MAPPING)
    )
    return georeferenced.assign(blocks.data_vars)


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
        If the file is missing, damaged (the NetCDF library cannot read its data) or is not
        an auvplan maps file.
    """
    import xarray as xr

    path = Path(path)
    try:
        dataset = xr.open_dataset(path, engine="netcdf4")
    except (OSError, ValueError, RuntimeError) as error:  # RuntimeError: damaged attributes
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
            projection = _local_frame(dataset, path)
            source = str(attrs.get("source", path.name))
            datum = dataset["depth"].attrs.get(VERTICAL_DATUM)
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
        except (RuntimeError, ValueError, TypeError) as error:  # damaged data or attributes
            raise DataFormatError(f"maps file {path}: cannot read ({error})") from None
    coarse = GridGeometry(
        north_block.size,
        east_block.size,
        fine.spacing_north * parameters.block[0],
        fine.spacing_east * parameters.block[1],
        float(north_block[0]),
        float(east_block[0]),
    )
    bathymetry = BathymetryGrid(
        arrays["depth"],
        fine,
        projection,
        None,
        source,
        {VERTICAL_DATUM: str(datum)} if datum is not None else {},
    )
    return TerrainMaps(
        bathymetry,
        arrays["information"],
        arrays["excitation"],
        arrays["cost"],
        arrays["shifted_cost"],
        coarse,
        parameters,
    )


def _local_frame(dataset: xr.Dataset, path: Path) -> LocalProjection | None:
    """The local frame of the ``depth`` variable's grid mapping (None without one)."""
    crs = grid_mapping_crs(dataset, dataset["depth"])
    if crs is None:
        return None
    projection = LocalProjection.from_crs(crs)
    if projection is None:
        raise DataFormatError(
            f"maps file {path}: its grid mapping is not an auvplan local frame ({crs.name})"
        )
    return projection
