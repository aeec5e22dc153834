"""``trajectories.nc`` without planning: true headings, terrain without georeference."""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from pyproj import Proj

from auvplan.errors import DataFormatError
from auvplan.io.trajectories_file import (
    SERIES,
    read_trajectories_netcdf,
    trajectories_dataset,
    true_heading,
)
from auvplan.record.dataset import operator_metadata
from auvplan.terrain import LocalProjection

from ._readers import checker_passes, checker_report


def test_true_heading_adds_the_meridian_convergence() -> None:
    """Oracle: PROJ's meridian convergence of the same transverse Mercator (km off its centre)."""
    projection = LocalProjection(36.8, -121.8)
    north = np.array([0.0, 0.0, 3000.0, -4000.0])
    east = np.array([5000.0, -5000.0, 5000.0, 20.0])
    lat, lon = projection.to_geographic(north, east)
    tmerc = Proj("+proj=tmerc +lat_0=36.8 +lon_0=-121.8 +k=1 +x_0=0 +y_0=0 +ellps=WGS84")
    convergence = tmerc.get_factors(lon, lat).meridian_convergence
    assert np.max(np.abs(convergence)) > 0.03  # large enough to be seen
    for psi_deg in (0.0, 45.0, 90.0, 200.0):
        psi = np.full(4, np.radians(psi_deg))
        expected = np.mod(psi_deg + convergence, 360.0)
        np.testing.assert_allclose(true_heading(projection, north, east, psi), expected, atol=1e-6)
    np.testing.assert_allclose(true_heading(None, north, east, np.full(4, -np.pi / 2)), 270.0)


def test_without_georeference_the_file_has_no_lat_lon_and_is_still_cf(tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    time = np.arange(0.0, 10.5, 0.5)
    series = {name: rng.normal(size=(2, time.size)) for name in SERIES}
    psi = rng.uniform(-np.pi, np.pi, size=(2, time.size))
    path = tmp_path / "trajectories.nc"
    start = datetime(2026, 5, 1, 8, 0, 0, 500000, tzinfo=UTC)
    built = trajectories_dataset(
        ["a", "b c"], time, series, psi=psi, start_time=start, depth=0.0, projection=None,
        attributes={"history": "test"},
    )  # fmt: skip
    built.to_netcdf(path)
    # the in-memory dataset is the file as read back (values, coordinates, attributes)
    xr.testing.assert_identical(read_trajectories_netcdf(path), built)
    assert checker_passes(path, tmp_path / "cf.json", "cf:1.8")  # exit 0: no error, no warning
    with xr.open_dataset(path) as dataset:
        assert "lat" not in dataset.variables
        assert "lon" not in dataset.variables
        assert list(dataset["trajectory"].values) == ["a", "b c"]
        assert dataset["time"].values[1, 0] == np.datetime64("2026-05-01T08:00:00.500")
        np.testing.assert_allclose(dataset["heading"].values, np.mod(np.degrees(psi), 360.0))
        for name in SERIES:
            np.testing.assert_array_equal(dataset[name].values, series[name])


def test_operator_metadata_and_dates_never_replace_computed_attributes(tmp_path: Path) -> None:
    """[metadata] keys are written as given, below the computed ones; dates only when known."""
    time = np.arange(0.0, 4.5, 0.5)
    series = {name: np.ones((1, time.size)) for name in SERIES}
    start = datetime(2026, 5, 1, 8, 0, 0, tzinfo=UTC)
    common = {"psi": np.zeros((1, time.size)), "start_time": start, "depth": 2.0}
    bare = trajectories_dataset(
        ["a"], time, series, **common, projection=None, attributes={}
    )  # fmt: skip
    assert not {"date_created", "creator_name"} & set(bare.attrs)
    created = datetime(2026, 11, 25, 23, 10, 5, 700000, tzinfo=UTC)
    dataset = trajectories_dataset(
        ["a"], time, series, **common, projection=LocalProjection(36.8, -121.8),
        attributes={"history": "test"},
        metadata={"creator_name": "Ada", "Conventions": "none", "id": "x"},
        created=created,
    )  # fmt: skip
    assert dataset.attrs["creator_name"] == "Ada"
    assert dataset.attrs["Conventions"] == bare.attrs["Conventions"]
    assert dataset.attrs["id"] == bare.attrs["id"]  # the positions' digest
    assert dataset.attrs["date_created"] == "2026-11-25T23:10:05Z"
    assert dataset.attrs["time_coverage_resolution"] == "PT0.5S"
    path = tmp_path / "trajectories.nc"
    dataset.to_netcdf(path)
    assert checker_passes(path, tmp_path / "cf.json", "cf:1.8")
    # the dates score: ACDD's date_created check finds an ISO 8601 date
    acdd = checker_report(path, tmp_path / "acdd.json", "acdd:1.3")
    (dates,) = [r for r in acdd["medium_priorities"] if r["name"] == "date_created_is_iso"]
    assert dates["value"] == [2, 2]


def test_operator_metadata_of_an_edited_mission_file_is_refused_in_one_line() -> None:
    assert operator_metadata({}) == {}
    assert operator_metadata({"metadata": {"project": "p"}}) == {"project": "p"}
    for table in ({"project": 3}, "text"):
        with pytest.raises(DataFormatError, match=r"mission.toml: \[metadata\] must hold text"):
            operator_metadata({"metadata": table})
