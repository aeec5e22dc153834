"""maps.nc: CF layout, attributes, and round trips through both readers."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import rasterio
import rioxarray  # noqa: F401  (the .rio accessor)
import xarray as xr
from pyproj import CRS

from auvplan.errors import DataFormatError
from auvplan.io.bathymetry import read_bathymetry
from auvplan.io.maps_file import read_maps_netcdf, write_maps_netcdf
from auvplan.terrain import (
    BathymetryGrid,
    GridGeometry,
    LocalProjection,
    MapParameters,
    TerrainMaps,
    compute_terrain_maps,
    synthetic_bank,
)


@pytest.fixture
def maps_with_projection(rng: np.random.Generator) -> TerrainMaps:
    depth = 30.0 + rng.random((9, 13)) * 5.0
    depth[0, :2] = np.nan
    grid = BathymetryGrid(
        depth,
        GridGeometry(9, 13, 10.27, 8.25),
        LocalProjection(36.8, -121.815, -50.0, -60.0),
        name="test grid",
    )
    return compute_terrain_maps(
        grid, MapParameters(exponent=2.0, block=(2, 3), omega=3.0, weight=7.0)
    )


def test_layout_and_cf_attributes(tmp_path: Path, maps_with_projection: TerrainMaps) -> None:
    maps = maps_with_projection
    path = write_maps_netcdf(maps, tmp_path / "maps.nc")
    with xr.open_dataset(path) as ds:
        assert ds["depth"].dims == ("north", "east")
        assert ds["information"].dims == ("north", "east")
        for name in ("excitation", "cost", "shifted_cost"):
            assert ds[name].dims == ("north_block", "east_block")
        assert ds["depth"].attrs["standard_name"] == "sea_floor_depth_below_sea_surface"
        assert ds["depth"].attrs["units"] == "m"
        assert ds["north"].attrs["axis"] == "Y"
        assert ds["east"].attrs["axis"] == "X"
        assert ds["north"].attrs["units"] == "m"
        np.testing.assert_allclose(ds["north"].values, maps.bathymetry.geometry.north)
        np.testing.assert_allclose(ds["east_block"].values, maps.cost_geometry.east)
        attrs = ds.attrs
        assert attrs["Conventions"] == "CF-1.8, ACDD-1.3"
        assert attrs["source"] == "test grid"
        assert (attrs["information_exponent"], attrs["omega"], attrs["weight"]) == (2.0, 3.0, 7.0)
        assert (attrs["block_north"], attrs["block_east"]) == (2, 3)
        # CF-1.8: coordinate variables without _FillValue, projected standard names, and
        # the local frame as a grid mapping variable referenced by every data variable.
        for name in ("north", "east", "north_block", "east_block", "lat", "lon"):
            assert "_FillValue" not in ds[name].encoding, name
        assert ds["north"].attrs["standard_name"] == "projection_y_coordinate"
        assert ds["east"].attrs["standard_name"] == "projection_x_coordinate"
        for name in ("depth", "information"):
            assert ds[name].attrs["grid_mapping"] == "crs"
        # the block axes are plain coordinate variables (no second projection_y_coordinate,
        # no axis: the IOOS checker would take them for latitude/longitude); the block maps'
        # grid mapping is the same frame with the block grid's GDAL GeoTransform
        for name in ("north_block", "east_block"):
            assert not {"axis", "standard_name"} & set(ds[name].attrs), name
            assert ds[name].attrs["units"] == "m"
        for name in ("excitation", "cost", "shifted_cost"):
            assert ds[name].attrs["grid_mapping"] == "crs_block"
        assert CRS.from_cf(ds["crs_block"].attrs) == CRS.from_cf(ds["crs"].attrs)
        coarse = maps.cost_geometry
        assert [float(v) for v in ds["crs_block"].attrs["GeoTransform"].split()] == [
            coarse.east_bounds[0],
            coarse.spacing_east,
            0.0,
            coarse.north_bounds[0],
            0.0,
            coarse.spacing_north,
        ]
        mapping = ds["crs"].attrs
        assert mapping["grid_mapping_name"] == "transverse_mercator"
        assert mapping["scale_factor_at_central_meridian"] == 1.0
        assert (mapping["latitude_of_projection_origin"], mapping["false_easting"]) == (36.8, 60.0)
        assert CRS.from_cf(mapping) == maps.bathymetry.projection.crs  # type: ignore[union-attr]
        # 2-D lat/lon auxiliary coordinates [deg] of every node.
        geometry = maps.bathymetry.geometry
        north, east = np.meshgrid(geometry.north, geometry.east, indexing="ij")
        lat, lon = maps.bathymetry.projection.to_geographic(north, east)  # type: ignore[union-attr]
        np.testing.assert_array_equal(ds["lat"].values, lat)
        np.testing.assert_array_equal(ds["lon"].values, lon)
        assert ds["lat_block"].shape == maps.cost.shape


def test_rioxarray_places_the_maps(tmp_path: Path, maps_with_projection: TerrainMaps) -> None:
    maps = maps_with_projection
    path = write_maps_netcdf(maps, tmp_path / "maps.nc")
    projection = maps.bathymetry.projection
    assert projection is not None
    with xr.open_dataset(path, decode_coords="all") as ds:
        for name, geometry in (("depth", maps.bathymetry.geometry), ("cost", maps.cost_geometry)):
            raster = ds[name].rio
            if name == "cost":  # the block axes are no CF axes: rioxarray is told them
                raster.set_spatial_dims(x_dim="east_block", y_dim="north_block", inplace=True)
            assert raster.crs is not None
            assert CRS(raster.crs) == projection.crs
            west, south, east, north = raster.bounds()
            assert (south, north) == pytest.approx(geometry.north_bounds, abs=1e-9)
            assert (west, east) == pytest.approx(geometry.east_bounds, abs=1e-9)
            # GDAL (QGIS) places each grid too: the fine one by its axes' `axis` attributes,
            # the block one by its grid mapping's GeoTransform; a node's value is where it is
            with rasterio.open(f"netcdf:{path}:{name}") as dataset:
                bounds = dataset.bounds
                assert CRS(dataset.crs) == projection.crs
                (sample,) = dataset.sample([(geometry.east[3], geometry.north[2])])
            assert (bounds.left, bounds.right) == pytest.approx(geometry.east_bounds, abs=1e-6)
            assert sorted((bounds.bottom, bounds.top)) == pytest.approx(
                geometry.north_bounds, abs=1e-6
            )
            assert sample[0] == ds[name].values[2, 3]


def test_cf_compliance_checker_passes(tmp_path: Path, maps_with_projection: TerrainMaps) -> None:
    """``compliance-checker --test cf:1.8`` exits 0 (no failed check of high or medium
    priority), georeferenced or not; a georeferenced file whose block axes keep ``axis``
    (the layout before issue 25) does not."""
    compliance_checker = pytest.importorskip("compliance_checker.runner")
    compliance_checker.CheckSuite.load_all_available_checkers()
    georeferenced = write_maps_netcdf(maps_with_projection, tmp_path / "geo.nc")
    local = write_maps_netcdf(compute_terrain_maps(synthetic_bank()), tmp_path / "local.nc")
    axes = tmp_path / "axes.nc"
    with xr.open_dataset(georeferenced) as ds:
        with_axes = ds.load()
    with_axes["north_block"].attrs["axis"] = "Y"
    with_axes["east_block"].attrs["axis"] = "X"
    with_axes.to_netcdf(axes)
    for path, passes in ((georeferenced, True), (local, True), (axes, False)):
        report = tmp_path / f"{path.stem}.json"
        passed, _ = compliance_checker.ComplianceChecker.run_checker(
            str(path), ["cf:1.8"], 0, "normal", output_filename=str(report), output_format="json"
        )
        results = json.loads(report.read_text())["cf:1.8"]
        assert len(results["high_priorities"]) > 10  # the checks did run
        assert passed == passes, path.name


def test_round_trip(tmp_path: Path, maps_with_projection: TerrainMaps) -> None:
    maps = maps_with_projection
    back = read_maps_netcdf(write_maps_netcdf(maps, tmp_path / "maps.nc"))
    assert back.parameters == maps.parameters
    assert back.cost_geometry == maps.cost_geometry
    assert back.bathymetry.geometry == maps.bathymetry.geometry
    assert back.bathymetry.projection == maps.bathymetry.projection
    for name in ("information", "excitation", "cost", "shifted_cost"):
        np.testing.assert_array_equal(getattr(back, name), getattr(maps, name))
    np.testing.assert_array_equal(back.bathymetry.depth, maps.bathymetry.depth)
    # maps.nc is also a bathymetry input, with its projection.
    grid = read_bathymetry(tmp_path / "maps.nc")
    np.testing.assert_array_equal(grid.depth, maps.bathymetry.depth)
    assert grid.projection == maps.bathymetry.projection
    assert grid.geometry == maps.bathymetry.geometry


def test_synthetic_bank_without_projection(tmp_path: Path) -> None:
    maps = compute_terrain_maps(synthetic_bank())
    back = read_maps_netcdf(write_maps_netcdf(maps, tmp_path / "maps.nc"))
    assert back.bathymetry.projection is None
    np.testing.assert_array_equal(back.shifted_cost, maps.shifted_cost)


def test_not_a_maps_file(tmp_path: Path) -> None:
    path = tmp_path / "x.nc"
    xr.Dataset({"a": ("t", [1.0])}).to_netcdf(path)
    with pytest.raises(DataFormatError, match="missing"):
        read_maps_netcdf(path)


def test_vertical_datum_of_the_source_is_carried(tmp_path: Path, bathymetry_dir: Path) -> None:
    """NCEI's Monterey DEM is relative to NAVD88: maps.nc's depth says so, and reads back."""
    grid = read_bathymetry(bathymetry_dir / "monterey_canyon_head_ncei_13arcsec.nc")
    assert grid.attributes["vertical_datum"] == "NAVD88"
    maps = compute_terrain_maps(grid.window((0.0, 200.0), (0.0, 200.0)))
    path = write_maps_netcdf(maps, tmp_path / "maps.nc")
    with xr.open_dataset(path) as ds:
        assert ds["depth"].attrs["vertical_datum"] == "NAVD88"
    assert read_maps_netcdf(path).bathymetry.attributes == {"vertical_datum": "NAVD88"}
    assert read_bathymetry(path).attributes["vertical_datum"] == "NAVD88"
    # a source without one: no attribute (nothing invented)
    local = write_maps_netcdf(compute_terrain_maps(synthetic_bank()), tmp_path / "local.nc")
    with xr.open_dataset(local) as ds:
        assert "vertical_datum" not in ds["depth"].attrs
