"""Geographic resampling and scattered-point gridding against independent oracles."""

from __future__ import annotations

import numpy as np
import pytest
from pyproj import Geod

from auvplan.errors import InputError
from auvplan.terrain.resample import grid_scattered_points, project_geographic_grid

LAT = 38.6 + 0.001 * np.arange(30)
LON = -9.3 + 0.00125 * np.arange(40)


def test_spacing_is_the_geodesic_node_distance_at_the_centre() -> None:
    grid = project_geographic_grid(np.full((30, 40), 50.0), LAT, LON)
    geod = Geod(ellps="WGS84")
    lat_c, lon_c = 0.5 * (LAT[0] + LAT[-1]), 0.5 * (LON[0] + LON[-1])
    _, _, north = geod.inv(lon_c, lat_c - 0.0005, lon_c, lat_c + 0.0005)
    _, _, east = geod.inv(lon_c - 0.000625, lat_c, lon_c + 0.000625, lat_c)
    assert grid.geometry.spacing_north == pytest.approx(north, rel=1e-6)
    assert grid.geometry.spacing_east == pytest.approx(east, rel=1e-6)
    # Over 3.3 km x 3.4 km the grid keeps (almost) every node.
    assert grid.geometry.shape[0] >= 29
    assert grid.geometry.shape[1] >= 39
    assert np.isfinite(grid.depth).all()


def test_every_node_lies_inside_the_source_and_origin_is_south_west() -> None:
    grid = project_geographic_grid(np.zeros((30, 40)), LAT, LON)
    assert grid.projection is not None
    north, east = np.meshgrid(grid.geometry.north, grid.geometry.east, indexing="ij")
    lat, lon = grid.projection.to_geographic(north, east)
    tolerance_lat, tolerance_lon = 0.01 * 0.001, 0.01 * 0.00125
    assert lat.min() >= LAT[0] - tolerance_lat
    assert lat.max() <= LAT[-1] + tolerance_lat
    assert lon.min() >= LON[0] - tolerance_lon
    assert lon.max() <= LON[-1] + tolerance_lon
    # The origin is the south-west corner of the source box (within one cell).
    assert lat[0, 0] - LAT[0] < 0.001
    assert lon[0, 0] - LON[0] < 0.00125


def test_nan_spreads_to_the_nodes_whose_stencil_touches_it() -> None:
    """GDAL's approximate transformer moves a sample by at most 1/8 cell: the test allows it."""
    depth = 40.0 + np.add.outer(np.arange(30.0), 0.5 * np.arange(40.0))
    depth[12, 17] = np.nan
    grid = project_geographic_grid(depth, LAT, LON)
    assert grid.projection is not None
    north, east = np.meshgrid(grid.geometry.north, grid.geometry.east, indexing="ij")
    lat, lon = grid.projection.to_geographic(north, east)
    row = np.interp(lat, LAT, np.arange(30.0))
    col = np.interp(lon, LON, np.arange(40.0))
    distance = np.maximum(np.abs(row - 12), np.abs(col - 17))
    assert np.all(np.isnan(grid.depth[distance < 0.99]))
    assert np.all(np.isfinite(grid.depth[distance > 1.01]))
    assert 1 <= np.isnan(grid.depth).sum() <= 4
    # Elsewhere the bilinear value of a linear field is the field at the sample position.
    expected = 40.0 + row + 0.5 * col
    error = np.abs(grid.depth - expected)[np.isfinite(grid.depth)]
    assert error.max() <= 0.125 * (1.0 + 0.5)
    assert np.median(error) < 0.01  # in practice about 1/500 cell here


def test_decreasing_or_mismatched_coordinates_are_rejected() -> None:
    with pytest.raises(InputError, match="increasing"):
        project_geographic_grid(np.zeros((30, 40)), LAT[::-1], LON)
    with pytest.raises(InputError, match="shape"):
        project_geographic_grid(np.zeros((30, 39)), LAT, LON)


def test_scattered_lattice_is_reproduced_at_its_nodes(rng: np.random.Generator) -> None:
    north, east = np.meshgrid(np.arange(0.0, 60.0, 3.0), np.arange(10.0, 100.0, 3.0), indexing="ij")
    depth = 30.0 + rng.random(north.shape)
    order = rng.permutation(north.size)
    grid = grid_scattered_points(north.ravel()[order], east.ravel()[order], depth.ravel()[order])
    assert grid.geometry.spacing_north == pytest.approx(3.0)
    np.testing.assert_allclose(grid.depth, depth, rtol=1e-12)


def test_too_few_points() -> None:
    with pytest.raises(InputError, match="at least 3"):
        grid_scattered_points(np.array([0.0, 1.0]), np.array([0.0, 1.0]), np.array([5.0, 6.0]))


def test_absurd_grid_sizes_are_refused_before_allocating() -> None:
    """A 6000 x 6000 lon/lat source (a zero-stride view: no memory) would need 36 M nodes."""
    lat = 10.0 + 0.001 * np.arange(6000)
    lon = 20.0 + 0.001 * np.arange(6000)
    depth = np.broadcast_to(np.float64(50.0), (6000, 6000))
    with pytest.raises(InputError, match=r"the grid would need 59\d\d x 59\d\d nodes"):
        project_geographic_grid(depth, lat, lon)
    north, east = np.array([0.0, 1.0, 0.0, 1e5]), np.array([0.0, 0.0, 1.0, 1e5])
    with pytest.raises(InputError, match=r"at most 2\.5e\+07\): remove stray positions"):
        grid_scattered_points(north, east, np.full(4, 30.0))


def test_collinear_soundings_are_an_input_error() -> None:
    t = np.linspace(0.0, 50.0, 20)
    with pytest.raises(InputError, match="the 20 soundings lie on one line"):
        grid_scattered_points(2.0 * t, t, np.full(20, 30.0))
