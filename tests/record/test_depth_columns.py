"""A plan with a depth profile: its depth_m/altitude_m columns round-trip through the folder."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from auvplan.errors import DataFormatError
from auvplan.record import VehicleTrajectory, export_plan, read_record
from auvplan.terrain import BathymetryGrid, GridGeometry, LocalProjection, compute_terrain_maps
from auvplan.vehicle import INPUT_NAMES, STATE_NAMES

#: The ``write_plan_folder`` fixture of ``tests/conftest.py``.
PlanFolderWriter = Callable[..., Path]

ORIGIN = {"north": 0.0, "east": 0.0, "lat": 36.8, "lon": -121.81}


def _vehicle(name: str, east: float, *, profile: bool = True) -> VehicleTrajectory:
    """Northbound at 1 m/s for 60 s, diving from 10 m at 0.1 m/s, 30 m above the seabed."""
    time = np.arange(0.0, 60.5, 0.5)
    states = np.zeros((time.size, len(STATE_NAMES)))
    states[:, 0], states[:, 1], states[:, 3], states[:, 6:] = 20.0 + time, east, 1.0, 30.0
    depth = 10.0 + 0.1 * time
    return VehicleTrajectory(
        name, STATE_NAMES, INPUT_NAMES, time, states,
        np.full((time.size - 1, len(INPUT_NAMES)), 0.1), np.full(time.size, 40.0),
        depth=depth if profile else None, altitude=30.0 + 0 * depth if profile else None,
    )  # fmt: skip


@pytest.fixture
def folder(tmp_path: Path, write_plan_folder: PlanFolderWriter) -> Path:
    geometry = GridGeometry(40, 40, 5.0, 5.0)
    grid = BathymetryGrid(np.full((40, 40), 40.0), geometry, LocalProjection(36.8, -121.81))
    tables = (_vehicle("blue", 60.0), _vehicle("green", 120.0))
    return write_plan_folder(
        tmp_path / "out", compute_terrain_maps(grid), {"terrain_aware": tables},
        extra={"terrain": {"name": "test", "origin": ORIGIN}},
        mission={"mission": {"altitude_m": 30.0}},
    )  # fmt: skip


def test_profile_columns_read_back_into_the_record_netcdf_and_exports(folder: Path) -> None:
    header = (folder / "trajectories.csv").read_text().splitlines()[0].split(",")
    assert header[-3:] == ["power", "depth_m", "altitude_m"]
    record = read_record(folder)
    blue, green = record.plans["terrain_aware"]
    assert blue.depth is not None
    assert green.altitude is not None
    np.testing.assert_array_equal(blue.depth, 10.0 + 0.1 * blue.time)
    np.testing.assert_array_equal(green.altitude, 30.0)
    with xr.open_dataset(folder / "trajectories.nc") as dataset:
        np.testing.assert_array_equal(dataset["depth"].values[1], green.depth)
        assert dataset["altitude"].attrs["standard_name"] == "height_above_sea_floor"
        assert dataset.attrs["geospatial_vertical_min"] == 10.0
        assert dataset.attrs["geospatial_vertical_max"] == 16.0
    (track, _) = export_plan(record).tracks
    assert track.depth is not None
    np.testing.assert_array_equal(track.depth, blue.depth)


def test_a_half_written_profile_is_refused_in_one_line(folder: Path) -> None:
    path = folder / "trajectories.csv"
    lines = [line.rsplit(",", 1)[0] for line in path.read_text().splitlines()]  # no altitude_m
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(DataFormatError, match="'depth_m' without"):
        read_record(folder)


def test_a_profile_for_some_vehicles_only_cannot_be_written(
    tmp_path: Path, write_plan_folder: PlanFolderWriter
) -> None:
    geometry = GridGeometry(40, 40, 5.0, 5.0)
    grid = BathymetryGrid(np.full((40, 40), 40.0), geometry)
    tables = (_vehicle("blue", 60.0), _vehicle("green", 120.0, profile=False))
    with pytest.raises(DataFormatError, match="for some vehicles only"):
        write_plan_folder(tmp_path / "out", compute_terrain_maps(grid), {"terrain_aware": tables})
