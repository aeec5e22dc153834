"""Current files as each provider publishes them: HYCOM, Copernicus Marine, RTOFS, ROMS/CROCO."""

from __future__ import annotations

from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from auvplan.errors import DataFormatError, InputError
from auvplan.io.currents import read_current
from auvplan.ocean import GriddedCurrent

from ._current_files import (
    EAST,
    NORTH,
    PROJECTION,
    analytic,
    level_factor,
    roms_factor,
    write_copernicus,
    write_hycom,
    write_roms,
    write_rtofs,
)

EXTENT = ((0.0, 2000.0), (0.0, 2000.0))
START_TIME = datetime(2026, 5, 1, 7, 0, tzinfo=UTC)  # one hour after the files' first time
ZERO = {"base": 0.0, "per_lat": 0.0, "per_lon": 0.0, "per_hour": 0.0}


def _read(path: Path, *, depth: float, **options: object) -> GriddedCurrent:
    return read_current(
        path,
        projection=PROJECTION,
        extent=EXTENT,
        start_time=START_TIME,
        depth=depth,
        **options,  # type: ignore[arg-type]
    )


def _assert_analytic(
    field: GriddedCurrent, factor: float, rng: np.random.Generator, *, atol: float
) -> None:
    """The field read equals ``factor`` times the analytic one over the map and 3 hours."""
    north, east = rng.uniform(200.0, 1800.0, (2, 60))
    time = rng.uniform(0.0, 3 * 3600.0, 60)
    lat, lon = PROJECTION.to_geographic(north, east)
    hours = 1.0 + time / 3600.0
    v_n, v_e = field.velocity(north, east, time)
    np.testing.assert_allclose(v_n, factor * analytic(NORTH, lat, lon, hours), atol=atol)
    np.testing.assert_allclose(v_e, factor * analytic(EAST, lat, lon, hours), atol=atol)


@pytest.mark.parametrize(
    ("writer", "depth", "factor", "atol"),
    [
        # int16 with scale 0.001: each value is off by at most 5e-4 m/s
        pytest.param(write_hycom, 30.0, level_factor(30.0), 1e-3, id="hycom"),
        pytest.param(write_copernicus, 12.0, level_factor(12.0), 1e-5, id="copernicus"),
        pytest.param(write_copernicus, 0.0, level_factor(0.494), 1e-5, id="copernicus-surface"),
        # float32 Latitude/Longitude: nodes off by up to 1e-5 deg, the field by 5e-5 m/s
        pytest.param(lambda path: write_rtofs(path, three_d=True), 30.0, 0.3, 1e-4, id="rtofs-3d"),
        pytest.param(lambda path: write_rtofs(path, three_d=False), 30.0, 1.0, 1e-4, id="rtofs-2d"),
    ],
)
def test_each_convention_reads_the_analytic_field(
    tmp_path: Path,
    rng: np.random.Generator,
    writer: Callable[[Path], Path],
    depth: float,
    factor: float,
    atol: float,
) -> None:
    """Linear in lat, lon and time, and linear in depth between the levels (30 m is 0.3 of
    the surface value between 0.5 at 10 m and 0.1 at 50 m; the nearest level would give 0.5
    or 0.1); above Copernicus's first level (0.494 m) its value; a 2-D RTOFS file has one."""
    field = _read(writer(tmp_path / "current.nc"), depth=depth)
    _assert_analytic(field, factor, rng, atol=atol)


def test_hycom_is_packed_and_its_fill_is_land(tmp_path: Path) -> None:
    """The file holds int16 with −30000 at the land nodes; read, they are NaN (still water):
    refused under the map's water, and nowhere near −30 m/s on the spline."""
    import xarray as xr

    path = write_hycom(tmp_path / "hycom.nc", land=(slice(7, 9), slice(7, 9)))
    with xr.open_dataset(path, mask_and_scale=False, decode_times=False) as raw:
        assert raw["water_u"].dtype == np.int16
        assert int(raw["water_u"].values[0, 0, 7, 7]) == -30000
        assert raw["time"].attrs["units"] == "hours since 2000-01-01 00:00:00"
        assert float(raw["lon"].min()) > 180.0
    field = _read(path, depth=0.0)
    north, east = np.meshgrid(np.linspace(0.0, 2000.0, 41), np.linspace(0.0, 2000.0, 41))
    v_n, v_e = field.velocity(north.ravel(), east.ravel(), np.full(north.size, 1800.0))
    assert np.all(np.isfinite(v_n))
    assert np.max(np.hypot(v_n, v_e)) < 0.5
    land = PROJECTION.to_local(np.array([36.80 - 0.004]), np.array([-121.81 - 0.004]))
    with pytest.raises(DataFormatError, match=r"hycom.nc: water_v is NaN over the map's water"):
        _read(path, depth=0.0, water=land)


@pytest.mark.parametrize("angle_deg", [30.0, -110.0])
def test_roms_eastward_current_on_a_rotated_grid_is_eastward(
    tmp_path: Path, rng: np.random.Generator, angle_deg: float
) -> None:
    """0.3 m/s east written as grid components (u = 0.3 cos α, v = −0.3 sin α) is read back
    as 0.3 m/s east and nothing north (a wrong sign of the rotation gives ±0.3 sin α north)."""
    east = {**ZERO, "base": 0.3}
    path = write_roms(tmp_path / "roms.nc", angle_deg=angle_deg, east=east, north=ZERO)
    field = _read(path, depth=20.0)
    north_m, east_m = rng.uniform(100.0, 1900.0, (2, 50))
    v_n, v_e = field.velocity(north_m, east_m, rng.uniform(0.0, 7200.0, 50))
    np.testing.assert_allclose(v_n, 0.0, atol=1e-9)
    np.testing.assert_allclose(v_e, 0.3 * roms_factor(20.0), rtol=1e-9)


def test_roms_field_through_s_levels_and_noleap_time(
    tmp_path: Path, rng: np.random.Generator
) -> None:
    """A field linear in lat, lon, time and depth on a C-grid rotated by 30°, s-levels of
    ``Vtransform`` 2 with ``Cs_r = -s²`` and times in the 'noleap' calendar (decoded as the
    standard calendar, 2000-2026's seven leap days would put the mission outside the file)."""
    path = write_roms(tmp_path / "roms.nc", angle_deg=30.0)
    _assert_analytic(_read(path, depth=37.0), float(roms_factor(37.0)), rng, atol=1e-5)


def test_roms_land_mask_is_still_water(tmp_path: Path) -> None:
    """ROMS writes 0 on land; ``mask_u``/``mask_v`` make it NaN: still water on land (the
    spline's zero), refused under the map's water; the water away from the coast is intact."""
    path = write_roms(tmp_path / "roms.nc", angle_deg=30.0, land=lambda north, east: north > 1500.0)
    field = _read(path, depth=20.0)
    north, east = np.array([1900.0, 700.0]), np.array([900.0, 900.0])  # on land, in water
    v_n, v_e = field.velocity(north, east, np.zeros(2))
    assert v_n[0] == v_e[0] == 0.0
    lat, lon = PROJECTION.to_geographic(north[1:], east[1:])
    expected = roms_factor(20.0) * analytic(EAST, lat, lon, np.ones(1))
    np.testing.assert_allclose(v_e[1:], expected, atol=1e-5)
    with pytest.raises(DataFormatError, match=r"roms.nc: v is NaN over the map's water"):
        _read(path, depth=20.0, water=(np.array([1900.0]), np.array([900.0])))


def test_roms_file_without_its_grid_is_one_line(tmp_path: Path) -> None:
    import xarray as xr

    path = write_roms(tmp_path / "roms.nc", angle_deg=0.0)
    with xr.open_dataset(path) as source:
        dataset = source.drop_vars("angle").load()
    dataset.to_netcdf(tmp_path / "no_angle.nc")
    with pytest.raises(DataFormatError, match=r"no_angle.nc: u/v are on a ROMS C-grid but"):
        _read(tmp_path / "no_angle.nc", depth=0.0)


def test_noleap_start_on_29_february_is_refused(tmp_path: Path) -> None:
    path = write_roms(tmp_path / "roms.nc", angle_deg=0.0)
    with pytest.raises(InputError, match="does not exist in the file's 'noleap' calendar"):
        read_current(
            path,
            projection=PROJECTION,
            extent=EXTENT,
            start_time=datetime(2028, 2, 29, tzinfo=UTC),
            depth=0.0,
        )


def test_curvilinear_file_off_the_map_is_refused(tmp_path: Path) -> None:
    path = write_rtofs(tmp_path / "rtofs.nc", three_d=False)
    with pytest.raises(InputError, match=r"rtofs.nc: it does not cover the map"):
        read_current(
            path,
            projection=PROJECTION,
            extent=((0.0, 2000.0), (0.0, 9000.0)),
            start_time=START_TIME,
            depth=0.0,
        )


@pytest.mark.parametrize(
    ("attribute", "value", "message"),
    [
        ("calendar", "lunar", r"roms.nc: time axis ocean_time .* cannot be decoded"),
        ("units", "seconds since the flood", r"roms.nc: time axis ocean_time .* cannot be decoded"),
    ],
)
def test_undecodable_time_is_one_line(
    tmp_path: Path, attribute: str, value: str, message: str
) -> None:
    import xarray as xr

    source = write_roms(tmp_path / "source.nc", angle_deg=0.0)
    with xr.open_dataset(source, decode_times=False) as opened:
        dataset = opened.load()
    dataset["ocean_time"].attrs[attribute] = value
    dataset.to_netcdf(tmp_path / "roms.nc")
    with pytest.raises(DataFormatError, match=message) as raised:
        _read(tmp_path / "roms.nc", depth=0.0)
    assert "\n" not in str(raised.value)


@pytest.mark.parametrize(
    "shift_days",
    [-1e6, 1e30],  # dates before year 1 (CF has no year 0 in the standard calendar); no int64
)
def test_times_no_calendar_holds_are_one_line(tmp_path: Path, shift_days: float) -> None:
    """Time values far outside any ocean model's (a damaged RTOFS file, found by the fuzz
    test: the first case was a CFWarning from cftime, the second an OverflowError)."""
    source = write_rtofs(tmp_path / "source.nc", three_d=False)
    with xr.open_dataset(source, decode_times=False) as opened:
        dataset = opened.load()
    dataset["MT"] = dataset["MT"] + shift_days
    dataset.to_netcdf(tmp_path / "rtofs.nc")
    with pytest.raises(
        DataFormatError, match=r"rtofs.nc: time axis MT .* cannot be decoded"
    ) as raised:
        _read(tmp_path / "rtofs.nc", depth=0.0)
    assert "\n" not in str(raised.value)


@pytest.mark.parametrize(
    ("variable", "value", "message"),
    [
        ("water_u", 1e30, r"water_u holds 1e\+27 m/s at \d+ of its \d+ values, faster than any"),
        ("water_v", np.inf, r"water_v holds inf m/s"),
        ("depth", np.nan, "a depth level is not a finite number"),
        ("lat", np.nan, r"lat holds \d+ of 17 values that are not numbers"),
    ],
)
def test_values_no_current_has_are_one_line_errors(
    tmp_path: Path, variable: str, value: float, message: str
) -> None:
    """Absurd speeds (fill without a _FillValue, a units slip), infinite ones and non-finite
    levels or coordinates are refused naming the variable, not planned (fuzzing found them)."""
    import xarray as xr

    with xr.open_dataset(write_hycom(tmp_path / "clean.nc"), decode_cf=False) as opened:
        dataset = opened.load()
    values = np.array(dataset[variable].values, dtype=np.float64)
    values[tuple(slice(0, max(1, n // 2)) for n in values.shape)] = value
    if variable.startswith("water"):  # raw int16 of scale 0.001: write the decoded floats
        dataset[variable] = (dataset[variable].dims, 0.001 * values, {"units": "m/s"})
    else:
        dataset = dataset.assign_coords(
            {variable: (dataset[variable].dims, values, dataset[variable].attrs)}
        )
    dataset.to_netcdf(tmp_path / "damaged.nc")
    with pytest.raises(DataFormatError, match=message):
        _read(tmp_path / "damaged.nc", depth=5.0)
