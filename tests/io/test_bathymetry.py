"""Bathymetry readers: the three real grids, projection, windows, and every supported format."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import rasterio
import xarray as xr
from affine import Affine
from pyproj import Transformer
from scipy.interpolate import RegularGridInterpolator

from auvplan.errors import DataFormatError, InputError
from auvplan.io.bathymetry import detect_format, read_bathymetry
from auvplan.terrain.resample import grid_scattered_points, project_geographic_grid

MONTEREY = "monterey_canyon_head_ncei_13arcsec.nc"
BALANUS = "balanus_seamount_gebco2024_15arcsec.nc"
LISBON = "south_lisbon_shelf_emodnet_dtm.nc"


# --- the three real grids ------------------------------------------------------------------


def test_monterey_loads_with_true_spacing(bathymetry_dir: Path) -> None:
    grid = read_bathymetry(bathymetry_dir / MONTEREY)
    g = grid.geometry
    assert g.spacing_north == pytest.approx(10.27, abs=0.05)
    assert g.spacing_east == pytest.approx(8.25, abs=0.05)
    assert abs(g.n_rows - 227) <= 1
    assert abs(g.n_cols - 227) <= 1
    assert (g.origin_north, g.origin_east) == (0.0, 0.0)
    assert np.isfinite(grid.depth).all()
    assert np.nanmin(grid.depth) == pytest.approx(13.3, abs=0.5)
    assert np.nanmax(grid.depth) == pytest.approx(223.6, abs=0.5)
    assert grid.projection is not None


def test_balanus_and_lisbon_load(bathymetry_dir: Path) -> None:
    balanus = read_bathymetry(bathymetry_dir / BALANUS)
    assert balanus.geometry.spacing_north == pytest.approx(463.0, rel=0.01)
    assert balanus.geometry.spacing_east == pytest.approx(358.0, rel=0.01)
    assert np.nanmin(balanus.depth) == pytest.approx(1438.0, abs=5.0)
    lisbon = read_bathymetry(bathymetry_dir / LISBON)
    assert lisbon.geometry.spacing_north == pytest.approx(115.6, rel=0.01)
    assert lisbon.geometry.spacing_east == pytest.approx(90.6, rel=0.01)
    # 49 % NaN land in the source, plus the 1.6 % of valid cells above 0 m, plus edge growth.
    assert np.isnan(lisbon.depth).mean() == pytest.approx(0.50, abs=0.02)
    assert np.nanmin(lisbon.depth) > 0.0
    assert np.nanmax(lisbon.depth) == pytest.approx(495.8, abs=5.0)


def test_resampling_matches_independent_bilinear_interpolation(
    bathymetry_dir: Path, rng: np.random.Generator
) -> None:
    grid = read_bathymetry(bathymetry_dir / MONTEREY)
    assert grid.projection is not None
    with xr.open_dataset(bathymetry_dir / MONTEREY) as ds:
        lat, lon = ds["lat"].values, ds["lon"].values
        depth = -ds["elevation"].values.astype(np.float64)
    oracle = RegularGridInterpolator((lat, lon), depth, method="linear")
    rows = rng.integers(1, grid.geometry.n_rows - 1, 300)
    cols = rng.integers(1, grid.geometry.n_cols - 1, 300)
    north, east = grid.geometry.to_world(rows, cols)
    node_lat, node_lon = grid.projection.to_geographic(north, east)
    error = np.abs(grid.depth[rows, cols] - oracle(np.column_stack([node_lat, node_lon])))
    # GDAL's approximate transformer moves a sample by at most 1/8 cell, which changes a
    # bilinear value by at most 1/4 of the relief of the 4 x 4 source nodes around it.
    row0 = np.clip(np.floor(np.interp(node_lat, lat, np.arange(lat.size))).astype(int) - 1, 0, None)
    col0 = np.clip(np.floor(np.interp(node_lon, lon, np.arange(lon.size))).astype(int) - 1, 0, None)
    relief = np.array(
        [np.ptp(depth[r : r + 4, c : c + 4]) for r, c in zip(row0, col0, strict=True)]
    )
    assert np.all(error <= 0.25 * relief)
    assert np.median(error / relief) < 0.005  # in practice about 1/1000 of the relief


def test_projection_round_trip_and_known_node(bathymetry_dir: Path) -> None:
    grid = read_bathymetry(bathymetry_dir / MONTEREY)
    projection = grid.projection
    assert projection is not None
    lat = np.linspace(36.79, 36.81, 7)
    lon = np.linspace(-121.825, -121.805, 7)
    north, east = projection.to_local(lat, lon)
    lat_back, lon_back = projection.to_geographic(north, east)
    assert np.max(np.abs(lat_back - lat)) < 1e-9
    assert np.max(np.abs(lon_back - lon)) < 1e-9
    # A native node maps into the metric cell that holds (nearly) its value.
    with xr.open_dataset(bathymetry_dir / MONTEREY) as ds:
        node_lat, node_lon = float(ds["lat"][120]), float(ds["lon"][80])
        patch = -ds["elevation"].values[119:122, 79:82].astype(np.float64)
    n, e = projection.to_local(np.array([node_lat]), np.array([node_lon]))
    row, col = grid.geometry.to_index(n, e)
    frac_row, frac_col = grid.geometry.to_fractional_index(n, e)
    assert abs(frac_row[0] - row[0]) <= 0.5
    assert abs(frac_col[0] - col[0]) <= 0.5
    assert patch.min() <= grid.depth[row[0], col[0]] <= patch.max()


def test_lat_lon_window_is_the_paper_scale_window(bathymetry_dir: Path) -> None:
    grid = read_bathymetry(
        bathymetry_dir / MONTEREY,
        window_lat=(36.79361, 36.79713),
        window_lon=(-121.81472, -121.80583),
    )
    assert abs(grid.geometry.n_rows - 39) <= 1
    assert abs(grid.geometry.n_cols - 97) <= 1
    assert np.nanmin(grid.depth) == pytest.approx(17.5, abs=0.5)
    assert np.nanmax(grid.depth) == pytest.approx(108.6, abs=1.0)
    # The origin is the window's south-west node.
    assert grid.projection is not None
    lat, lon = grid.projection.to_geographic(np.array([0.0]), np.array([0.0]))
    assert lat[0] == pytest.approx(36.79361, abs=1e-4)
    assert lon[0] == pytest.approx(-121.81472, abs=1e-4)


def test_north_east_window_crops_and_reorigins(bathymetry_dir: Path) -> None:
    full = read_bathymetry(bathymetry_dir / MONTEREY)
    cropped = read_bathymetry(
        bathymetry_dir / MONTEREY, window_north=(100.0, 500.0), window_east=(200.0, 1000.0)
    )
    g, f = cropped.geometry, full.geometry
    r0 = int(np.ceil(100.0 / f.spacing_north))
    c0 = int(np.ceil(200.0 / f.spacing_east))
    np.testing.assert_array_equal(cropped.depth, full.depth[r0 : r0 + g.n_rows, c0 : c0 + g.n_cols])
    assert (g.origin_north, g.origin_east) == (0.0, 0.0)
    assert cropped.projection is not None
    # The same lat/lon lands on the same terrain in both frames.
    lat, lon = cropped.projection.to_geographic(np.array([123.0]), np.array([234.0]))
    rf, cf = f.to_index(*full.projection.to_local(lat, lon))  # type: ignore[union-attr]
    rc, cc = g.to_index(*cropped.projection.to_local(lat, lon))
    assert full.depth[rf[0], cf[0]] == cropped.depth[rc[0], cc[0]]


@pytest.mark.parametrize(
    "window",
    [
        {"window_north": (5000.0, 6000.0)},
        {"window_east": (-50.0, -10.0)},
        {"window_lat": (10.0, 11.0)},
        {"window_lon": (-121.0, -120.0)},
    ],
)
def test_window_outside_the_map_is_an_input_error(bathymetry_dir: Path, window: dict) -> None:
    with pytest.raises(InputError, match=MONTEREY):
        read_bathymetry(bathymetry_dir / MONTEREY, **window)


# --- synthetic files of every format -------------------------------------------------------


def _lonlat_grid() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    lat = 38.5 + 0.001 * np.arange(12)
    lon = -9.3 + 0.00125 * np.arange(15)
    lat2, lon2 = np.meshgrid(lat, lon, indexing="ij")
    elevation = -50.0 - 3000.0 * (lat2 - 38.5) + 800.0 * (lon2 + 9.3) ** 1.0
    elevation[0, :3] = 5.0  # land in the south-west corner
    return lat, lon, elevation


def test_netcdf4_with_decreasing_lat_and_yx_dims(tmp_path: Path) -> None:
    lat, lon, elevation = _lonlat_grid()
    path = tmp_path / "grid.nc"
    ds = xr.Dataset(
        {"elevation": (("y", "x"), elevation[::-1])},
        {"lat": ("y", lat[::-1]), "lon": ("x", lon)},
    )
    ds.to_netcdf(path, format="NETCDF4", engine="netcdf4")
    assert detect_format(path) == "netcdf"
    grid = read_bathymetry(path)
    expected = project_geographic_grid(np.where(-elevation > 0, -elevation, np.nan), lat, lon)
    np.testing.assert_array_equal(grid.depth, expected.depth)
    assert grid.geometry == expected.geometry
    assert np.isnan(grid.depth[0, 0])
    assert grid.depth[-1, -1] > 0.0


def test_netcdf_metric_depth_variable(tmp_path: Path) -> None:
    depth = np.arange(20.0, 32.0).reshape(3, 4)
    path = tmp_path / "metric.nc"
    xr.Dataset(
        {"depth": (("north", "east"), depth)},
        {"north": [100.0, 105.0, 110.0], "east": [0.0, 2.0, 4.0, 6.0]},
    ).to_netcdf(path)
    grid = read_bathymetry(path)
    np.testing.assert_array_equal(grid.depth, depth)
    assert (grid.geometry.spacing_north, grid.geometry.spacing_east) == (5.0, 2.0)
    assert grid.projection is None


def test_geographic_geotiff_with_nodata(tmp_path: Path) -> None:
    lat, lon, elevation = _lonlat_grid()
    elevation = elevation.astype(np.float32)
    elevation[5, 7] = -9999.0
    path = tmp_path / "grid.tif"
    transform = Affine(0.00125, 0.0, lon[0] - 0.000625, 0.0, -0.001, lat[-1] + 0.0005)
    with rasterio.open(
        path, "w", driver="GTiff", height=12, width=15, count=1, dtype="float32",
        crs="EPSG:4326", transform=transform, nodata=-9999.0,
    ) as dst:  # fmt: skip
        dst.write(elevation[::-1], 1)  # GeoTIFF row 0 is north
    grid = read_bathymetry(path)
    source = np.where(-elevation.astype(np.float64) > 0, -elevation.astype(np.float64), np.nan)
    source[5, 7] = np.nan
    expected = project_geographic_grid(source, lat, lon)
    np.testing.assert_allclose(grid.depth, expected.depth, rtol=1e-9)
    assert np.isnan(grid.depth).sum() == np.isnan(expected.depth).sum() > 4
    assert grid.attributes["crs"] == "EPSG:4326"


def test_projected_geotiff_is_resampled_to_the_local_frame(tmp_path: Path) -> None:
    """A plane on a UTM lattice, read at the UTM position of every local node (pyproj)."""
    northing = 4_300_000.0 + 10.0 * np.arange(60)
    easting = 500_000.0 + 5.0 * np.arange(90)
    plane = 20.0 + 0.1 * (northing[:, None] - northing[0]) + 0.05 * (easting - easting[0])
    path = tmp_path / "utm.tif"
    with rasterio.open(
        path, "w", driver="GTiff", height=60, width=90, count=1, dtype="float64",
        crs="EPSG:32629", transform=Affine(5.0, 0.0, 499_997.5, 0.0, -10.0, 4_300_595.0),
    ) as dst:  # fmt: skip
        dst.write(-plane[::-1], 1)
    grid = read_bathymetry(path)
    assert grid.projection is not None
    assert grid.attributes["crs"] == "EPSG:32629"
    north, east = np.meshgrid(grid.geometry.north, grid.geometry.east, indexing="ij")
    to_utm = Transformer.from_crs(grid.projection.crs, "EPSG:32629", always_xy=True)
    node_easting, node_northing = to_utm.transform(east, north)
    expected = 20.0 + 0.1 * (node_northing - northing[0]) + 0.05 * (node_easting - easting[0])
    np.testing.assert_allclose(grid.depth, expected, atol=0.01)  # 1/8 cell would be 0.13 m
    # On the central meridian of zone 29 (9 W) the UTM scale factor is 0.9996.
    assert grid.geometry.spacing_north == pytest.approx(10.0 / 0.9996, rel=1e-6)
    assert grid.geometry.spacing_east == pytest.approx(5.0 / 0.9996, rel=1e-6)
    # A lat/lon window goes through the CRS.
    cropped = read_bathymetry(path, window_lat=(38.8, 39.0), window_lon=(-9.0, -8.99990))
    assert cropped.depth.shape[1] < grid.depth.shape[1]


def test_esri_ascii_grid(tmp_path: Path) -> None:
    depth = np.array([[10.0, 11.0, 12.0], [13.0, 14.0, 15.0]])  # row 0 = south
    path = tmp_path / "grid.asc"
    # Elevation = -depth; the ASCII grid lists the northern row first; -9999 is no data.
    body = "\n".join(" ".join(f"{-v:g}" for v in row) for row in depth[::-1])
    path.write_text(
        "ncols 3\nnrows 2\nxllcorner 1000\nyllcorner 2000\ncellsize 25\nNODATA_value -9999\n"
        + body.replace("-15", "-9999")
        + "\n"
    )
    assert detect_format(path) == "ascii"
    grid = read_bathymetry(path)
    expected = depth.copy()
    expected[1, 2] = np.nan
    np.testing.assert_array_equal(grid.depth, expected)
    assert grid.geometry.spacing_north == grid.geometry.spacing_east == 25.0


def test_xyz_metric_lattice_with_hole(tmp_path: Path) -> None:
    north, east = np.meshgrid(np.arange(0.0, 50.0, 10.0), np.arange(0.0, 70.0, 10.0), indexing="ij")
    depth = 30.0 + 0.1 * north + 0.05 * east
    keep = np.ones(depth.shape, dtype=bool)
    keep[2, 3] = False
    path = tmp_path / "points.xyz"
    lines = [
        f"{e:.3f},{n:.3f},{-d:.4f}"
        for e, n, d in zip(east[keep], north[keep], depth[keep], strict=True)
    ]
    path.write_text("# east,north,elevation\nx,y,z\n" + "\n".join(lines[::-1]) + "\n")
    assert detect_format(path) == "xyz"
    grid = read_bathymetry(path)
    expected = depth.copy()
    expected[2, 3] = np.nan
    np.testing.assert_allclose(grid.depth, expected, rtol=1e-12)
    assert grid.geometry.spacing_north == grid.geometry.spacing_east == 10.0


def test_xyz_geographic_lattice_equals_the_netcdf_reading(tmp_path: Path) -> None:
    lat, lon, elevation = _lonlat_grid()
    lat2, lon2 = np.meshgrid(lat, lon, indexing="ij")
    xyz = tmp_path / "points.txt"
    rows = np.column_stack([lon2.ravel(), lat2.ravel(), elevation.ravel()])
    np.savetxt(xyz, rows, fmt="%.8f")
    nc = tmp_path / "grid.nc"
    xr.Dataset({"elevation": (("lat", "lon"), elevation)}, {"lat": lat, "lon": lon}).to_netcdf(nc)
    from_xyz, from_nc = read_bathymetry(xyz), read_bathymetry(nc)
    assert from_xyz.geometry.shape == from_nc.geometry.shape
    assert from_xyz.geometry.spacing_north == pytest.approx(from_nc.geometry.spacing_north)
    assert from_xyz.geometry.spacing_east == pytest.approx(from_nc.geometry.spacing_east)
    np.testing.assert_allclose(from_xyz.depth, from_nc.depth, rtol=1e-6)
    assert from_xyz.projection is not None


def test_xyz_scattered_points_reproduce_a_plane(tmp_path: Path, rng: np.random.Generator) -> None:
    east, north = rng.uniform(0.0, 200.0, 400), rng.uniform(0.0, 100.0, 400)
    depth = 40.0 + 0.2 * north - 0.1 * east
    path = tmp_path / "soundings.xyz"
    np.savetxt(path, np.column_stack([east, north, depth]), fmt="%.6f")
    grid = read_bathymetry(path, vertical="depth")
    node_north, node_east = np.meshgrid(grid.geometry.north, grid.geometry.east, indexing="ij")
    plane = 40.0 + 0.2 * (node_north + north.min()) - 0.1 * (node_east + east.min())
    finite = np.isfinite(grid.depth)
    assert finite.mean() > 0.75
    np.testing.assert_allclose(grid.depth[finite], plane[finite], atol=1e-5)  # %.6f text


def test_scattered_gridding_leaves_gaps_nan() -> None:
    north, east = np.meshgrid(np.arange(0.0, 100.0, 5.0), np.arange(0.0, 100.0, 5.0), indexing="ij")
    inside_gap = (np.abs(north - 50.0) < 30.0) & (np.abs(east - 50.0) < 30.0)
    grid = grid_scattered_points(
        north[~inside_gap], east[~inside_gap], 30.0 + 0 * north[~inside_gap]
    )
    assert grid.geometry.spacing_north == 5.0
    assert np.isnan(grid.depth[10, 10])
    assert grid.depth[0, 0] == 30.0


def test_min_depth_and_sign_conventions(tmp_path: Path) -> None:
    elevation = np.array([[-30.0, -2.0], [-10.0, 4.0]])
    path = tmp_path / "small.nc"
    xr.Dataset(
        {"elevation": (("lat", "lon"), elevation)}, {"lat": [10.0, 10.001], "lon": [20.0, 20.001]}
    ).to_netcdf(path)
    depth = read_bathymetry(path, min_depth=5.0).depth
    assert np.isfinite(depth).sum() >= 1
    assert np.nanmax(depth) <= 30.0 + 1e-9
    assert np.nanmin(depth) > 5.0


# --- failures: one line, naming the file ---------------------------------------------------


def _assert_one_line(error: pytest.ExceptionInfo[Exception], path: Path) -> None:
    message = str(error.value)
    assert "\n" not in message
    assert str(path) in message


def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "nope.nc"
    with pytest.raises(DataFormatError) as error:
        read_bathymetry(path)
    _assert_one_line(error, path)


@pytest.mark.parametrize(
    "content",
    [
        b"\x00\x01\x02binary junk\xff\xfe" * 50,
        b"hello world\nthis is not bathymetry\n",
        b"CDF\x01 truncated netcdf",
        b"II*\x00 truncated tiff",
        b"1 2\n3 4\n",
        b"",
    ],
)
def test_garbage_files(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / "garbage.dat"
    path.write_bytes(content)
    with pytest.raises(DataFormatError) as error:
        read_bathymetry(path)
    _assert_one_line(error, path)


def test_netcdf_without_bathymetry_variables(tmp_path: Path) -> None:
    path = tmp_path / "other.nc"
    xr.Dataset({"temperature": (("time",), [1.0, 2.0])}).to_netcdf(path)
    with pytest.raises(DataFormatError, match="coordinate variables") as error:
        read_bathymetry(path)
    _assert_one_line(error, path)


def test_all_land_is_an_error(tmp_path: Path) -> None:
    path = tmp_path / "land.nc"
    xr.Dataset(
        {"elevation": (("lat", "lon"), np.full((3, 3), 12.0))},
        {"lat": [1.0, 1.001, 1.002], "lon": [2.0, 2.001, 2.002]},
    ).to_netcdf(path)
    with pytest.raises(DataFormatError, match="no water cell") as error:
        read_bathymetry(path, vertical="elevation")
    _assert_one_line(error, path)


def test_netcdf_elevation_on_other_dimensions(tmp_path: Path) -> None:
    path = tmp_path / "odd.nc"
    xr.Dataset(
        {"elevation": (("time",), [-1.0, -2.0])},
        {"lat": ("lat", [1.0, 1.001]), "lon": ("lon", [2.0, 2.001])},
    ).to_netcdf(path)
    with pytest.raises(DataFormatError) as error:
        read_bathymetry(path)
    _assert_one_line(error, path)


def test_netcdf_with_a_singleton_time_dimension(tmp_path: Path) -> None:
    path = tmp_path / "timed.nc"
    elevation = -np.arange(20.0, 26.0).reshape(1, 2, 3)
    xr.Dataset(
        {"z": (("time", "lat", "lon"), elevation)},
        {"lat": [10.0, 10.001], "lon": [20.0, 20.001, 20.002], "time": [0.0]},
    ).to_netcdf(path)
    grid = read_bathymetry(path)
    assert np.nanmin(grid.depth) >= 20.0
    assert np.nanmax(grid.depth) <= 25.0
