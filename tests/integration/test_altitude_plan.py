"""A constant-altitude plan up the wall of Monterey Canyon's head (the packaged sample).

A REMUS 100 whose climb rate is 0.2 m/s climbs ~55 m out of the canyon in 400 s, faster than
it may where the wall is steep; it is asked for 3 m above the seabed, below its 4 m minimum.
The output folder is read back as the user would: ``trajectories.csv``, ``trajectories.nc``,
``maps.nc`` and the exports.
"""

from __future__ import annotations

import csv
import json
from importlib import resources
from pathlib import Path

import gpxpy
import numpy as np
import pytest
import xarray as xr

from auvplan.cli.main import main
from auvplan.io.maps_file import read_maps_netcdf
from auvplan.navigation.depth import depth_at
from auvplan.record import read_record

pytestmark = pytest.mark.slow

CLIMB_RATE = 0.2
MIN_ALTITUDE = 4.0
#: Round-off allowed on a rate [m/s] and on the clearance between samples [m] (the profile
#: samples the seabed where a step crosses grid nodes and at 4 points a step; checked at 20).
RATE_TOLERANCE = 1e-9
CLEARANCE_TOLERANCE = 1e-6

MISSION = """
[terrain]
sample = "monterey"
window = { lat = [36.79360, 36.79714], lon = [-121.81473, -121.80582] }
[fleet]
horizon_s = 400.0
safety_radius_m = 5.0
[planner]
edge_model = "paper"
[solver]
dt_s = 1.0
[mission]
altitude_m = 3.0
start_time = "2026-05-01T08:00:00Z"
[[vehicle]]
name = "blue"
type = "climber.toml"
start = { north = 360.0, east = 60.0, heading_deg = 120.0, speed = 0.5 }
goal = { north = 250.0, east = 330.0, heading_deg = 90.0 }
"""


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("altitude")
    remus = resources.files("auvplan").joinpath("data", "vehicles", "remus100.toml").read_text()
    vertical = (
        f"[vertical]\nclimb_rate = {{ value = {CLIMB_RATE}, unit = 'm/s' }}\n"
        f"dive_rate = {{ value = {CLIMB_RATE}, unit = 'm/s' }}\n"
        f"min_altitude = {{ value = {MIN_ALTITUDE}, unit = 'm' }}\n"
    )
    start, end = remus.index("[vertical]"), remus.index("[smoothing]")
    (root / "climber.toml").write_text(remus[:start] + vertical + remus[end:])
    (root / "mission.toml").write_text(MISSION)
    out = root / "out"
    argv = ["-q", "plan", str(root / "mission.toml"), "-o", str(out), "--no-figures"]
    assert main([*argv, "--export", "moos,qgc,gpx"]) == 0
    return out


def _table(folder: Path) -> dict[str, np.ndarray]:
    with (folder / "trajectories.csv").open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    return {
        key: np.array([float(row[key]) for row in rows])
        for key in ("t", "north", "east", "depth_m", "altitude_m")
    }


def test_profile_keeps_the_climb_rate_and_minimum_altitude_at_and_between_samples(
    folder: Path,
) -> None:
    table = _table(folder)
    time, depth = table["t"], table["depth_m"]
    seabed = depth_at(
        read_maps_netcdf(folder / "maps.nc").bathymetry, table["north"], table["east"]
    )
    np.testing.assert_allclose(table["altitude_m"], seabed - depth, atol=1e-9)
    rate = np.diff(depth) / np.diff(time)
    assert rate.min() >= -CLIMB_RATE - RATE_TOLERANCE
    assert rate.max() <= CLIMB_RATE + RATE_TOLERANCE
    assert np.all(depth >= 0.0)
    assert np.all(table["altitude_m"] >= MIN_ALTITUDE - 1e-9)
    # the seabed rises faster than the vehicle may climb: the limit shaped the profile
    assert np.min(np.diff(seabed) / np.diff(time)) < -2.0 * CLIMB_RATE
    assert np.isclose(rate.min(), -CLIMB_RATE)
    # between samples, flown straight at linearly interpolated depth
    fine = np.linspace(0.0, 1.0, 21)[:-1]
    north = (table["north"][:-1, None] + fine * np.diff(table["north"])[:, None]).ravel()
    east = (table["east"][:-1, None] + fine * np.diff(table["east"])[:, None]).ravel()
    between = (depth[:-1, None] + fine * np.diff(depth)[:, None]).ravel()
    bathymetry = read_maps_netcdf(folder / "maps.nc").bathymetry
    clearance = depth_at(bathymetry, north, east) - between
    assert clearance.min() >= MIN_ALTITUDE - CLEARANCE_TOLERANCE


def test_netcdf_record_and_exports_carry_the_profile(folder: Path) -> None:
    table = _table(folder)
    with xr.open_dataset(folder / "trajectories.nc") as dataset:
        np.testing.assert_array_equal(dataset["depth"].values[0], table["depth_m"])
        np.testing.assert_array_equal(dataset["altitude"].values[0], table["altitude_m"])
        assert dataset.attrs["geospatial_vertical_max"] == table["depth_m"].max()
    (vehicle,) = read_record(folder).plans["terrain_aware"]
    assert vehicle.depth is not None
    np.testing.assert_array_equal(vehicle.depth, table["depth_m"])
    exports = folder / "export"
    gpx = gpxpy.parse((exports / "trajectories.gpx").read_text())
    points = gpx.tracks[0].segments[0].points
    times = [p.time for p in points if p.time is not None]
    seconds = np.array([(moment - times[0]).total_seconds() for moment in times])
    expected = np.interp(seconds, table["t"], table["depth_m"])
    elevation = np.array([p.elevation for p in points], dtype=np.float64)
    np.testing.assert_allclose(-elevation, expected, atol=1e-3)
    items = json.loads((exports / "blue.plan").read_text())["mission"]["items"]
    altitude = np.array([item["params"][6] for item in items if item["command"] == 16])
    np.testing.assert_allclose(-altitude, expected, atol=1e-9)
    assert np.ptp(altitude) > 20.0
    assert (exports / "blue.bhv").read_text().count("BHV_ConstantDepth") == len(points) - 1
