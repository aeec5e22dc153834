"""Bathymetry readers on hostile files: stray fixes, absurd sizes and values, off-Earth axes."""

from __future__ import annotations

import logging
import re
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from auvplan.errors import DataFormatError
from auvplan.io._xyz import drop_stray_fixes
from auvplan.io.bathymetry import MAX_ABS_ELEVATION, read_bathymetry


def _survey(rng: np.random.Generator, n: int = 400) -> np.ndarray:
    """A UTM-like survey of a plane, 300 m x 200 m, depth = 30 + 0.05 north - 0.02 east."""
    east, north = rng.uniform(0.0, 300.0, n), rng.uniform(0.0, 200.0, n)
    depth = 30.0 + 0.05 * north - 0.02 * east
    return np.column_stack([500_000.0 + east, 4_100_000.0 + north, depth])


def _netcdf(path: Path, lat: np.ndarray, lon: np.ndarray, elevation: np.ndarray) -> Path:
    dataset = xr.Dataset(
        {"elevation": (("lat", "lon"), elevation)}, coords={"lat": lat, "lon": lon}
    )
    dataset["lat"].attrs["units"] = "degrees_north"
    dataset["lon"].attrs["units"] = "degrees_east"
    dataset.to_netcdf(path)
    return path


def test_a_stray_fix_at_zero_is_dropped_with_a_warning(
    tmp_path: Path, rng: np.random.Generator, caplog: pytest.LogCaptureFixture
) -> None:
    table = _survey(rng)
    clean = tmp_path / "clean.xyz"
    np.savetxt(clean, table, fmt="%.6f")
    table[17] = (0.0, 0.0, 25.0)  # a GNSS glitch logged as position (0, 0)
    glitch = tmp_path / "glitch.xyz"
    np.savetxt(glitch, table, fmt="%.6f")
    with caplog.at_level(logging.WARNING):
        grid = read_bathymetry(glitch, vertical="depth")
    assert "dropped 1 of 400 soundings" in caplog.text
    assert str(glitch) in caplog.text
    # The grid is that of the survey without the glitch (compared with a reading of the
    # 399 good soundings alone), not one spanning 4,100 km to (0, 0).
    np.savetxt(clean, np.delete(table, 17, axis=0), fmt="%.6f")
    expected = read_bathymetry(clean, vertical="depth")
    assert grid.geometry == expected.geometry
    np.testing.assert_array_equal(grid.depth, expected.depth)
    assert grid.geometry.n_rows * grid.geometry.spacing_north < 210.0


def test_stray_rule_keeps_uniform_and_two_part_surveys(rng: np.random.Generator) -> None:
    """Uniform coverage has no point beyond 1.35 robust sigmas; a far group of 10 % is kept."""
    first, second = rng.uniform(0.0, 1.0, 1000), rng.uniform(0.0, 1.0, 1000)
    z = np.zeros(1000)
    kept = drop_stray_fixes(first, second, z, Path("x"))
    assert kept[0].size == 1000
    first[:100] += 1e6
    assert drop_stray_fixes(first, second, z, Path("x"))[0].size == 1000
    first[:100] -= 1e6
    first[:5] = -1e6  # 0.5 %: stray
    assert drop_stray_fixes(first, second, z, Path("x"))[0].size == 995


def test_two_far_parts_are_refused_before_allocating(
    tmp_path: Path, rng: np.random.Generator
) -> None:
    near, far = _survey(rng), _survey(rng)
    far[:, :2] += (2_000_000.0, 3_000_000.0)
    path = tmp_path / "two_areas.xyz"
    np.savetxt(path, np.vstack([near, far]), fmt="%.6f")
    tracemalloc.start()
    try:
        with pytest.raises(DataFormatError, match="the grid would need") as info:
            read_bathymetry(path)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    message = str(info.value)
    assert message.startswith(f"bathymetry {path}: ")
    assert "remove stray positions" in message
    assert "\n" not in message
    assert peak < 50e6  # refused from the estimate: nothing near the 1e12-byte grid allocated


def test_collinear_soundings_are_one_line(tmp_path: Path) -> None:
    t = np.linspace(0.0, 100.0, 50)
    path = tmp_path / "line.xyz"
    np.savetxt(path, np.column_stack([1000.0 + t, 2000.0 + 0.5 * t, 30.0 + 0 * t]))
    with pytest.raises(DataFormatError, match="50 soundings lie on one line") as info:
        read_bathymetry(path)
    assert "\n" not in str(info.value)
    assert str(info.value).startswith(f"bathymetry {path}: ")


@pytest.mark.parametrize(
    ("lat", "lon", "message"),
    [
        (np.linspace(89.5, 95.0, 20), np.linspace(10.0, 10.1, 20), "latitudes 89.5 … 95 deg"),
        (np.linspace(40.0, 40.1, 20), np.linspace(400.0, 400.1, 20), "longitudes 400 … 400.1"),
        (np.linspace(-91.0, -90.5, 20), np.linspace(0.0, 0.1, 20), "outside [-90, 90] deg"),
    ],
)
def test_coordinates_off_the_earth_are_refused(
    tmp_path: Path, lat: np.ndarray, lon: np.ndarray, message: str
) -> None:
    path = _netcdf(tmp_path / "grid.nc", lat, lon, np.full((20, 20), -50.0))
    with pytest.raises(DataFormatError, match=re.escape(message)):
        read_bathymetry(path)


def test_lat_lon_named_axes_without_units_are_geographic(tmp_path: Path) -> None:
    path = tmp_path / "no_units.nc"
    xr.Dataset(
        {"elevation": (("lat", "lon"), np.full((10, 10), -50.0))},
        coords={"lat": np.linspace(90.5, 91.0, 10), "lon": np.linspace(0.0, 0.1, 10)},
    ).to_netcdf(path)
    with pytest.raises(DataFormatError, match=r"latitudes 90\.5 … 91 deg are outside"):
        read_bathymetry(path)


def test_absurd_elevations_become_no_data_with_a_count(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    lat, lon = np.linspace(40.0, 40.01, 30), np.linspace(10.0, 10.01, 30)
    elevation = -50.0 - 100.0 * np.add.outer(lat - 40.0, lon - 10.0)
    reference = read_bathymetry(_netcdf(tmp_path / "clean.nc", lat, lon, elevation))
    elevation[3, 3], elevation[20, 7], elevation[25, 25] = -1e308, 1e300, -32767.0
    with caplog.at_level(logging.WARNING):
        grid = read_bathymetry(_netcdf(tmp_path / "dirty.nc", lat, lon, elevation))
    assert f"3 of 900 values beyond ±{MAX_ABS_ELEVATION:g} m treated as no data" in caplog.text
    assert np.nanmax(grid.depth) < 52.0
    # Only cells interpolated from the three bad nodes are lost; all others are unchanged.
    changed = ~np.isclose(grid.depth, reference.depth, rtol=0.0, atol=1e-9, equal_nan=True)
    assert np.all(np.isnan(grid.depth[changed]))
    assert 3 <= changed.sum() <= 12


def test_a_grid_without_any_valid_value_is_a_format_error(tmp_path: Path) -> None:
    lat, lon = np.linspace(40.0, 40.01, 5), np.linspace(10.0, 10.01, 5)
    elevation = np.full((5, 5), -1e308)
    elevation[0, 0] = np.nan
    path = _netcdf(tmp_path / "absurd.nc", lat, lon, elevation)
    with pytest.raises(DataFormatError, match="no valid value: all 25 values are no data"):
        read_bathymetry(path)
