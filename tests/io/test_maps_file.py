"""maps.nc: CF layout, attributes, and round trips through both readers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

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
        assert attrs["Conventions"] == "CF-1.8"
        assert attrs["source"] == "test grid"
        assert (attrs["information_exponent"], attrs["omega"], attrs["weight"]) == (2.0, 3.0, 7.0)
        assert (attrs["block_north"], attrs["block_east"]) == (2, 3)
        assert attrs["projection_lat_0"] == 36.8
        assert attrs["projection_offset_east"] == -60.0


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
