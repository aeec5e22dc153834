"""Current fields, the CF file reader and speeds along a path in a current."""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest

from auvplan.errors import DataFormatError, InputError
from auvplan.io.currents import read_current
from auvplan.ocean import GriddedCurrent, UniformCurrent, ground_speed, through_water
from auvplan.terrain import LocalProjection

from ._current_files import EAST, LAT_0, LON_0, NORTH, analytic, write_current_file

PROJECTION = LocalProjection(LAT_0, LON_0).shifted(-1000.0, -1000.0)
EXTENT = ((0.0, 2000.0), (0.0, 2000.0))
START_TIME = datetime(2026, 5, 1, 7, 0, tzinfo=UTC)  # one hour after the file's first time


@pytest.fixture(scope="module")
def current_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_current_file(tmp_path_factory.mktemp("current") / "currents.nc")


def _read(path: Path, *, depth: float = 0.0, start: datetime | None = START_TIME) -> GriddedCurrent:
    return read_current(path, projection=PROJECTION, extent=EXTENT, start_time=start, depth=depth)


def test_cf_file_reproduces_the_analytic_field(
    current_file: Path, rng: np.random.Generator
) -> None:
    """A field linear in lat, lon and time is reproduced by the cubic B-splines.

    Exactly, but for the affine map of the file's axes to the local frame: over ±1 km the
    curvature of the meridians and parallels changes the field by a few 1e-6 m/s.
    """
    field = _read(current_file, depth=12.0)  # 0.48: 1/20 of the way from 0.5 (10 m) to 0.1 (50 m)
    north, east = rng.uniform(200.0, 1800.0, (2, 50))
    time = rng.uniform(0.0, 3 * 3600.0, 50)
    lat, lon = PROJECTION.to_geographic(north, east)
    hours = 1.0 + time / 3600.0
    v_n, v_e = field.velocity(north, east, time)
    np.testing.assert_allclose(v_n, 0.48 * analytic(NORTH, lat, lon, hours), atol=1e-5)
    np.testing.assert_allclose(v_e, 0.48 * analytic(EAST, lat, lon, hours), atol=1e-5)


def test_time_origin_is_the_files_first_time_without_start_time(current_file: Path) -> None:
    field = _read(current_file, start=None)
    lat, lon = PROJECTION.to_geographic(np.array([1000.0]), np.array([1000.0]))
    v_n, _ = field.velocity(np.array([1000.0]), np.array([1000.0]), np.array([7200.0]))
    np.testing.assert_allclose(v_n, analytic(NORTH, lat, lon, np.array([2.0])), atol=1e-5)


def test_gradient_matches_finite_differences(current_file: Path, rng: np.random.Generator) -> None:
    field = _read(current_file)
    north, east = rng.uniform(300.0, 1700.0, (2, 20))
    time = rng.uniform(0.0, 7200.0, 20)
    step = 1.0
    numeric = np.empty((20, 2, 2))
    for axis, (dn, de) in enumerate(((step, 0.0), (0.0, step))):
        plus = np.column_stack(field.velocity(north + dn, east + de, time))
        minus = np.column_stack(field.velocity(north - dn, east - de, time))
        numeric[:, :, axis] = (plus - minus) / (2 * step)
    np.testing.assert_allclose(field.gradient(north, east, time), numeric, rtol=1e-5, atol=1e-12)
    # and the analytic gradient: ∂v/∂n = per_lat ∂lat/∂n (1 deg of latitude is ~111 km)
    assert field.gradient(north[:1], east[:1], time[:1])[0, 1, 0] == pytest.approx(
        EAST["per_lat"] / 110_990.0, rel=2e-3
    )


def test_variable_names_without_standard_names(tmp_path: Path) -> None:
    path = write_current_file(tmp_path / "cmems.nc", names=("uo", "vo"))
    field = _read(path)
    point = np.array([1000.0])
    lat, lon = PROJECTION.to_geographic(point, point)
    _, v_e = field.velocity(point, point, np.zeros(1))
    np.testing.assert_allclose(v_e, analytic(EAST, lat, lon, np.ones(1)), atol=1e-5)


def test_file_is_cf_compliant(current_file: Path) -> None:
    """The generated fixture passes the CF checker (so the reader is tested on real CF)."""
    pytest.importorskip("compliance_checker")
    from compliance_checker.runner import CheckSuite, ComplianceChecker

    CheckSuite.load_all_available_checkers()
    passed, _ = ComplianceChecker.run_checker(
        str(current_file), ["cf:1.8"], 0, "normal", output_filename="-", output_format="json"
    )
    assert passed


@pytest.mark.parametrize(
    ("change", "error", "message"),
    [
        ("missing", DataFormatError, "not found"),
        ("not netcdf", DataFormatError, "unreadable"),
        ("no variables", DataFormatError, "no current variables"),
        ("units", DataFormatError, "not a velocity"),
        ("elsewhere", InputError, "does not cover the map"),
        ("late start", InputError, "outside the file's times"),
    ],
)
def test_bad_files_are_one_line_errors(
    tmp_path: Path, current_file: Path, change: str, error: type[Exception], message: str
) -> None:
    import xarray as xr

    path = tmp_path / "bad.nc"
    start = START_TIME
    if change == "not netcdf":
        path.write_text("not a NetCDF file\n")
    elif change != "missing":
        with xr.open_dataset(current_file) as source:
            dataset = source.load()
        if change == "no variables":
            dataset = dataset.rename({"east_velocity": "a", "north_velocity": "b"})
            for name in ("a", "b"):
                dataset[name].attrs.pop("standard_name")
        elif change == "units":
            dataset["north_velocity"].attrs["units"] = "knots furlong"
        elif change == "elsewhere":
            dataset = dataset.assign_coords(lat=dataset.lat + 1.0)
        else:
            start = datetime(2027, 1, 1, tzinfo=UTC)
        dataset.to_netcdf(path)
    with pytest.raises(error, match=message) as raised:
        _read(path, start=start)
    assert "\n" not in str(raised.value)


def test_uniform_current() -> None:
    field = UniformCurrent(-0.1, 0.3)
    v_n, v_e = field.velocity(np.zeros(3), np.ones(3), np.arange(3.0))
    assert v_n.tolist() == [-0.1] * 3
    assert v_e.tolist() == [0.3] * 3
    assert not np.any(field.gradient(np.zeros(3), np.zeros(3), np.zeros(3)))


def test_ground_speed_inverts_through_water(rng: np.random.Generator) -> None:
    """The ground velocity s t̂ needs exactly U_w through the water (an independent check)."""
    angle = rng.uniform(-np.pi, np.pi, 200)
    tangent = np.column_stack([np.cos(angle), np.sin(angle)])
    current = rng.uniform(-0.4, 0.4, (200, 2))
    speed = ground_speed(0.5, current, tangent)
    across = np.abs(current[:, 0] * tangent[:, 1] - current[:, 1] * tangent[:, 0])
    assert np.array_equal(np.isnan(speed), across > 0.5)
    ok = ~np.isnan(speed)
    water, _ = through_water(speed[ok, None] * tangent[ok], current[ok])
    np.testing.assert_allclose(water, 0.5, rtol=1e-12)
    # downstream is faster than upstream
    east = np.array([[0.0, 1.0]])
    assert ground_speed(0.5, [[0.0, 0.2]], east)[0] == pytest.approx(0.7)
    assert ground_speed(0.5, [[0.0, -0.2]], east)[0] == pytest.approx(0.3)
