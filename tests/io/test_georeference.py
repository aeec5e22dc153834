"""Projected (UTM) grids, as GeoTIFF and as CF NetCDF, keep their georeference end to end.

The inputs are made as a user's GIS would: a geographic grid (synthetic, or a window of the
real Monterey grid) reprojected into UTM with rioxarray, written with ``rio.to_raster`` and
as a CF NetCDF whose ``grid_mapping`` rioxarray writes. Read back, a lat/lon point must find
the seabed depth it has in the geographic source.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import rasterio
import rioxarray  # noqa: F401  (the .rio accessor)
import xarray as xr
from pyproj import CRS, Proj, Transformer
from rasterio.enums import Resampling
from scipy.interpolate import RegularGridInterpolator

from auvplan.cli.main import main
from auvplan.errors import InputError
from auvplan.io.bathymetry import read_bathymetry
from auvplan.io.maps_file import read_maps_netcdf
from auvplan.terrain import BathymetryGrid, LocalProjection

# rioxarray computes transforms with the `*` operator that affine >= 2.4 deprecates.
pytestmark = pytest.mark.filterwarnings("ignore:Use `@` matmul:PendingDeprecationWarning")

UTM_29N, UTM_10N = "EPSG:32629", "EPSG:32610"

#: Synthetic source: WGS 84 lon/lat nodes off Lisbon, about 22 m apart.
LAT = 38.70 + 0.0002 * np.arange(101)
LON = -9.20 + 0.00025 * np.arange(121)


def synthetic_depth(lat: np.ndarray, lon: np.ndarray) -> np.ndarray:
    """A sloping shelf [m] with a 300 m wide mound: depth 15 … 100 m over the area."""
    north, east = (lat - 38.71) * 111_000.0, (lon + 9.185) * 86_800.0
    return 60.0 + 0.03 * north - 0.02 * east + 8.0 * np.exp(-(north**2 + east**2) / 300.0**2)


def geographic_elevation() -> xr.DataArray:
    lat2, lon2 = np.meshgrid(LAT, LON, indexing="ij")
    return xr.DataArray(
        -synthetic_depth(lat2, lon2),
        dims=("y", "x"),
        coords={"y": LAT, "x": LON},
        name="elevation",
    ).rio.write_crs("EPSG:4326")


def write_utm(elevation: xr.DataArray, utm: str, folder: Path) -> tuple[Path, Path]:
    """``elevation`` reprojected to ``utm`` (bilinear), as a GeoTIFF and as a CF NetCDF."""
    projected = elevation.rio.reproject(utm, resampling=Resampling.bilinear, nodata=np.nan)
    tif, nc = folder / "utm.tif", folder / "utm.nc"
    projected.rio.to_raster(tif)
    projected.to_dataset(name="elevation").to_netcdf(nc)
    return tif, nc


def depth_at(grid: BathymetryGrid, lat: np.ndarray, lon: np.ndarray) -> np.ndarray:
    """Bilinear depth [m] of ``grid`` at geographic points, through its own projection."""
    assert grid.projection is not None
    north, east = grid.projection.to_local(lat, lon)
    interpolator = RegularGridInterpolator((grid.geometry.north, grid.geometry.east), grid.depth)
    return np.asarray(interpolator(np.column_stack([north, east])))


def test_utm_geotiff_and_cf_netcdf_keep_their_crs_and_depths(
    tmp_path: Path, rng: np.random.Generator
) -> None:
    tif, nc = write_utm(geographic_elevation(), UTM_29N, tmp_path)
    with xr.open_dataset(nc) as ds:  # the NetCDF holds a CF grid mapping, not a GeoTIFF tag
        assert ds["elevation"].attrs["grid_mapping"] == "spatial_ref"
        assert ds["spatial_ref"].attrs["grid_mapping_name"] == "transverse_mercator"
    lat, lon = rng.uniform(38.703, 38.717, 500), rng.uniform(-9.195, -9.175, 500)
    truth = synthetic_depth(lat, lon)
    for path in (tif, nc):
        grid = read_bathymetry(path)
        assert CRS(grid.attributes["crs"]) == CRS(UTM_29N)  # the source CRS, kept
        assert grid.projection is not None
        assert LocalProjection.from_crs(grid.projection.crs) == grid.projection
        # 22 m nodes resampled twice (to UTM, then to the local frame): centimetres of
        # interpolation error over a 0.036 m/m slope, where one cell of misplacement is 0.8 m.
        error = np.abs(depth_at(grid, lat, lon) - truth)
        assert error.max() < 0.1, path.name
        assert np.median(error) < 0.01, path.name
        # The local frame is metric: its spacing is the UTM spacing over the UTM point scale.
        with rasterio.open(tif) as source:
            utm_spacing = source.res[1]
        scale = Proj(UTM_29N).get_factors(-9.185, 38.71).meridional_scale
        assert grid.geometry.spacing_north == pytest.approx(utm_spacing / scale, rel=1e-5)


def test_utm_grid_is_read_like_its_geographic_source(tmp_path: Path) -> None:
    geographic = tmp_path / "geographic.nc"
    geographic_elevation().to_dataset().to_netcdf(geographic)
    tif, _ = write_utm(geographic_elevation(), UTM_29N, tmp_path)
    source, utm = read_bathymetry(geographic), read_bathymetry(tif)
    assert source.projection is not None
    north, east = np.meshgrid(source.geometry.north[2:-2], source.geometry.east[2:-2])
    lat, lon = source.projection.to_geographic(north.ravel(), east.ravel())
    error = np.abs(depth_at(utm, lat, lon) - depth_at(source, lat, lon))
    assert error.max() < 0.1
    # A lat/lon window selects the same area in both.
    a, b = (
        read_bathymetry(path, window_lat=(38.705, 38.715), window_lon=(-9.19, -9.18))
        for path in (geographic, tif)
    )
    assert a.projection is not None
    assert b.projection is not None
    for grid in (a, b):
        corners = grid.projection.to_geographic(  # type: ignore[union-attr]
            np.array([0.0, grid.geometry.north[-1]]), np.array([0.0, grid.geometry.east[-1]])
        )
        np.testing.assert_allclose(corners[0], [38.705, 38.715], atol=0.0003)
        np.testing.assert_allclose(corners[1], [-9.19, -9.18], atol=0.0004)


def test_real_grid_window_reprojected_to_utm(
    tmp_path: Path, bathymetry_dir: Path, rng: np.random.Generator
) -> None:
    """Monterey canyon head (10 m nodes, 170 m of relief) through UTM zone 10N and back."""
    with xr.open_dataset(bathymetry_dir / "monterey_canyon_head_ncei_13arcsec.nc") as ds:
        window = ds.isel(lat=slice(40, 140), lon=slice(60, 180)).load()
    geographic = tmp_path / "window.nc"
    window.to_netcdf(geographic)
    elevation = window["elevation"].astype(np.float64).rename(lat="y", lon="x")
    tif, nc = write_utm(elevation.rio.write_crs("EPSG:4326"), UTM_10N, tmp_path)
    source = read_bathymetry(geographic)
    assert source.projection is not None
    north = rng.uniform(100.0, source.geometry.north[-1] - 100.0, 1000)
    east = rng.uniform(100.0, source.geometry.east[-1] - 100.0, 1000)
    lat, lon = source.projection.to_geographic(north, east)
    expected = depth_at(source, lat, lon)
    for path in (tif, nc):
        grid = read_bathymetry(path)
        assert CRS(grid.attributes["crs"]) == CRS(UTM_10N)
        error = np.abs(depth_at(grid, lat, lon) - expected)
        # Interpolation on canyon walls of up to 10 m per cell: a median of 0.13 m and at
        # most 2.4 m; the same grid misplaced by one cell (10 m) differs by 1.9 m in median.
        assert np.median(error) < 0.3, path.name
        assert error.max() < 4.0, path.name


def test_metric_grid_without_crs_has_no_georeference(tmp_path: Path) -> None:
    path = tmp_path / "local.nc"
    xr.Dataset(
        {"depth": (("y", "x"), np.full((4, 5), 30.0))},
        {"y": ("y", 100.0 * np.arange(4), {"units": "m"}), "x": ("x", 50.0 * np.arange(5))},
    ).to_netcdf(path)
    grid = read_bathymetry(path)
    assert grid.projection is None
    assert "crs" not in grid.attributes
    with pytest.raises(InputError, match="needs a grid with a geographic or projected CRS"):
        read_bathymetry(path, window_lat=(1.0, 2.0))


def test_plan_on_a_utm_geotiff_with_lat_lon_poses(tmp_path: Path) -> None:
    """``auvplan plan`` end to end: lat/lon start and goal on a UTM survey grid.

    A 60 m x 45 m leg over a 300 m x 330 m grid of 5.5 m nodes (a small, fast mission).
    """
    lat = 38.705 + 0.00005 * np.arange(61)
    lon = -9.19 + 0.0000625 * np.arange(81)
    lat2, lon2 = np.meshgrid(lat, lon, indexing="ij")
    elevation = xr.DataArray(
        -synthetic_depth(lat2, lon2), dims=("y", "x"), coords={"y": lat, "x": lon}
    ).rio.write_crs("EPSG:4326")
    tif, _ = write_utm(elevation, UTM_29N, tmp_path)
    start, goal = (38.7060, -9.1880), (38.7064, -9.1879)
    mission = tmp_path / "mission.toml"
    mission.write_text(
        f'[terrain]\nfile = "{tif.name}"\n[fleet]\nhorizon_s = 120.0\nsafety_radius_m = 5.0\n'
        f'[[vehicle]]\nname = "blue"\n'
        f"start = {{ lat = {start[0]}, lon = {start[1]}, heading_deg = 0.0, speed = 0.5 }}\n"
        f"goal = {{ lat = {goal[0]}, lon = {goal[1]}, heading_deg = 0.0 }}\n"
        "[solver]\ndt_s = 0.5\n"
    )
    out = tmp_path / "out"
    assert main(["-q", "plan", str(mission), "-o", str(out), "--no-figures"]) == 0
    maps = read_maps_netcdf(out / "maps.nc")
    projection = maps.bathymetry.projection
    assert projection is not None
    with xr.open_dataset(out / "maps.nc", decode_coords="all") as ds:
        assert CRS(ds["depth"].rio.crs) == projection.crs
    # The seabed under the planned start and goal is the source's seabed at those lat/lon.
    rows = np.genfromtxt(out / "trajectories.csv", delimiter=",", names=True, dtype=None)
    first, last = rows[0], rows[-1]
    for (north, east), (point_lat, point_lon) in (
        ((first["north"], first["east"]), start),
        ((last["north"], last["east"]), goal),
    ):
        lat_back, lon_back = projection.to_geographic(np.array([north]), np.array([east]))
        assert float(lat_back[0]) == pytest.approx(point_lat, abs=2e-6)  # 0.2 m
        assert float(lon_back[0]) == pytest.approx(point_lon, abs=2e-6)
        assert depth_at(maps.bathymetry, lat_back, lon_back)[0] == pytest.approx(
            synthetic_depth(np.array(point_lat), np.array(point_lon)), abs=0.05
        )


def test_cf_grid_mapping_parameters_without_wkt(tmp_path: Path) -> None:
    """A Lambert conformal conic grid described only by CF grid-mapping parameters."""
    mapping = {
        "grid_mapping_name": "lambert_conformal_conic",
        "standard_parallel": [38.0, 40.0],
        "longitude_of_central_meridian": -9.0,
        "latitude_of_projection_origin": 39.0,
        "false_easting": 0.0,
        "false_northing": 0.0,
        "semi_major_axis": 6378137.0,
        "inverse_flattening": 298.257223563,
    }
    y = -30_000.0 + 20.0 * np.arange(40)
    x = -12_000.0 + 25.0 * np.arange(50)
    plane = 50.0 + 0.02 * (y[:, None] - y[0]) - 0.01 * (x - x[0])
    path = tmp_path / "lcc.nc"
    xr.Dataset(
        {"depth": (("y", "x"), plane, {"units": "m", "grid_mapping": "lambert"})},
        {
            "y": ("y", y, {"standard_name": "projection_y_coordinate", "units": "m"}),
            "x": ("x", x, {"standard_name": "projection_x_coordinate", "units": "m"}),
            "lambert": ((), 0, mapping),
        },
    ).to_netcdf(path)
    grid = read_bathymetry(path)
    assert grid.projection is not None
    assert CRS(grid.attributes["crs"]).to_cf()["grid_mapping_name"] == "lambert_conformal_conic"
    north, east = np.meshgrid(grid.geometry.north, grid.geometry.east, indexing="ij")
    lcc = CRS.from_cf(mapping)
    to_lcc = Transformer.from_crs(grid.projection.crs, lcc, always_xy=True)
    node_x, node_y = to_lcc.transform(east, north)
    expected = 50.0 + 0.02 * (node_y - y[0]) - 0.01 * (node_x - x[0])
    assert grid.geometry.shape == (39, 49)  # the inscribed rectangle of the rotated source
    np.testing.assert_allclose(grid.depth, expected, atol=0.01)
