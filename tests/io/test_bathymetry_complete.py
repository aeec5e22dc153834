"""Bathymetry files cut short (interrupted downloads) are refused, naming what is missing."""

from __future__ import annotations

from pathlib import Path

import netCDF4
import numpy as np
import pytest
import rasterio
import xarray as xr
from affine import Affine

from auvplan.errors import DataFormatError
from auvplan.io._complete import check_netcdf_complete
from auvplan.io.bathymetry import read_bathymetry


def _dataset() -> xr.Dataset:
    dataset = xr.Dataset(
        coords={"lat": np.linspace(40.0, 40.1, 37), "lon": np.linspace(10, 10.1, 41)}
    )
    dataset["elevation"] = ("lat", "lon"), -50.0 - np.arange(37 * 41.0).reshape(37, 41) / 100.0
    return dataset


def _cut(path: Path, n_bytes: int) -> Path:
    """A copy of ``path`` without its last ``n_bytes`` bytes."""
    data = path.read_bytes()
    cut = path.with_name("cut_" + path.name)
    cut.write_bytes(data[: len(data) - n_bytes])
    return cut


@pytest.mark.parametrize(
    ("netcdf_format", "unlimited"),
    [
        ("NETCDF3_CLASSIC", None),
        ("NETCDF3_CLASSIC", "lat"),
        ("NETCDF3_64BIT", None),
        ("NETCDF4_CLASSIC", None),
        ("NETCDF4", "lat"),
    ],
)
def test_netcdf_missing_its_last_byte_is_truncated(
    tmp_path: Path, netcdf_format: str, unlimited: str | None
) -> None:
    path = tmp_path / "grid.nc"
    _dataset().to_netcdf(
        path, format=netcdf_format, unlimited_dims=[unlimited] if unlimited else None
    )
    assert read_bathymetry(path).depth.shape[0] == 37  # the whole file reads
    for n_bytes in (1, path.stat().st_size * 2 // 3):
        cut = _cut(path, n_bytes)
        with pytest.raises(DataFormatError, match=rf"^bathymetry {cut}: truncated NetCDF"):
            read_bathymetry(cut)


def test_netcdf3_names_the_variable_and_its_missing_fraction(tmp_path: Path) -> None:
    path = tmp_path / "grid.nc"
    _dataset().to_netcdf(path, format="NETCDF3_CLASSIC")
    n_bytes = 37 * 41 * 8 // 2  # the second half of elevation (stored last)
    with pytest.raises(DataFormatError, match="50 % of the values of elevation are missing"):
        read_bathymetry(_cut(path, n_bytes))


def test_cdf5_with_record_variables(tmp_path: Path) -> None:
    """The 64-bit data format (8-byte counts and offsets), two record variables (padded)."""
    path = tmp_path / "cdf5.nc"
    with netCDF4.Dataset(path, "w", format="NETCDF3_64BIT_DATA") as dataset:
        dataset.createDimension("time", None)
        dataset.createDimension("x", 5)
        dataset.createVariable("a", "i8", ("time", "x"))[:] = np.ones((7, 5))
        dataset.createVariable("b", "i2", ("time",))[:] = np.arange(7)
    check_netcdf_complete(path)
    with pytest.raises(DataFormatError, match="14 % of the values of b are missing"):
        check_netcdf_complete(_cut(path, 3))  # b's last record ends 2 bytes before its padding


def _raster(path: Path, driver: str, **options: object) -> Path:
    depth = 40.0 + 0.1 * np.add.outer(np.arange(60.0), np.arange(60.0))
    with rasterio.open(
        path,
        "w",
        driver=driver,
        height=60,
        width=60,
        count=1,
        dtype="float32",
        transform=Affine(10.0, 0.0, 0.0, 0.0, -10.0, 600.0),
        **options,
    ) as raster:
        raster.write(depth.astype(np.float32), 1)
    return path


@pytest.mark.parametrize("options", [{}, {"tiled": True, "blockxsize": 16, "blockysize": 16}])
def test_geotiff_cut_short_counts_the_missing_values(
    tmp_path: Path, options: dict[str, object]
) -> None:
    path = _raster(tmp_path / "grid.tif", "GTiff", **options)
    assert read_bathymetry(path).depth.shape == (60, 60)
    cut = _cut(path, 1)
    with rasterio.open(path) as source:
        *_, (_, last) = source.block_windows(1)
    n_missing = last.width * last.height  # the last tile (12 x 12) or strip (26 rows)
    with pytest.raises(
        DataFormatError,
        match=rf"^bathymetry {cut}: truncated GeoTIFF: .* {n_missing} of the 3600 values",
    ):
        read_bathymetry(cut)


def test_esri_ascii_names_declared_and_found_value_counts(tmp_path: Path) -> None:
    path = _raster(tmp_path / "grid.asc", "AAIGrid")
    assert read_bathymetry(path).depth.shape == (60, 60)
    cut = tmp_path / "short.asc"
    cut.write_text(path.read_text().rsplit(maxsplit=10)[0])  # without the last 10 values
    with pytest.raises(DataFormatError) as raised:
        read_bathymetry(cut)
    assert str(raised.value) == (
        f"bathymetry {cut}: ESRI ASCII grid cut short: the header declares 60 x 60 = 3600 "
        "values, the file holds 3590 (0.28 % missing; an interrupted download or copy? fetch "
        "the file again)"
    )


def test_other_gdal_errors_give_their_cause(tmp_path: Path) -> None:
    """Not rasterio's "Read failed. See previous exception for details."."""
    path = _raster(tmp_path / "grid.tif", "GTiff", compress="deflate")
    data = bytearray(path.read_bytes())
    with rasterio.open(path) as source:
        offset = int(source.get_tag_item("BLOCK_OFFSET_0_0", "TIFF", bidx=1))
    data[offset : offset + 64] = bytes(64)  # a corrupted first strip, the size intact
    path.write_bytes(bytes(data))
    with pytest.raises(DataFormatError, match=r"unreadable raster \((?!Read failed)"):
        read_bathymetry(path)


def test_xyz_lines_cut_or_garbled_are_named(tmp_path: Path) -> None:
    east, north = np.meshgrid(np.arange(10.0) * 10.0, np.arange(8.0) * 10.0)
    rows = [f"{e:.1f} {n:.1f} 30.0" for e, n in zip(east.ravel(), north.ravel(), strict=True)]
    path = tmp_path / "survey.xyz"
    path.write_text("east north depth\n" + "\n".join(rows))  # a header line is fine
    assert read_bathymetry(path).depth.shape == (8, 10)
    path.write_text("east north depth\n" + "\n".join(rows)[:-6])  # cut in the last line
    with pytest.raises(DataFormatError, match="line 81 has 2 columns, need 3"):
        read_bathymetry(path)
    rows[40] = "50.0 4O.0 30.0"  # a letter O for a zero: was skipped silently
    path.write_text("\n".join(rows))
    with pytest.raises(DataFormatError, match="line 41 is not numeric"):
        read_bathymetry(path)
