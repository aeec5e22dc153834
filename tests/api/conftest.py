"""A small georeferenced mission planned once through the notebook API (about 5 s)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import auvplan

# Vehicle names with characters that HTML must escape.
NAMES = ("blue <1>", "r&d")
MISSION = """
[terrain]
file = "ridge.nc"
[fleet]
horizon_s = 70.0
safety_radius_m = 4.0
[[vehicle]]
name = "blue <1>"
start = { north = 30.0, east = 120.0, speed = 0.5 }
goal = { north = 60.0, east = 135.0 }
[[vehicle]]
name = "r&d"
start = { north = 30.0, east = 220.0, speed = 0.5 }
goal = { north = 60.0, east = 200.0 }
[[obstacle]]
name = "rock"
center = { north = 150.0, east = 300.0 }
radius_m = 8.0
[solver]
dt_s = 1.0
[mission]
start_time = 2025-03-14T09:00:00Z
depth_m = 2.0
"""
#: Latitude and longitude ranges [deg] of the grid file (cell centres), and its shape.
LAT, LON, SHAPE = (38.650, 38.653), (-9.40, -9.3945), (67, 97)


def write_ridge(path: Path) -> None:
    """A lat/lon grid, about 490 m x 330 m of 5 m cells, with a ridge running north-east."""
    lat = np.linspace(*LAT, SHAPE[0])
    lon = np.linspace(*LON, SHAPE[1])
    north = (lat[:, None] - lat[0]) * 111_000.0
    east = (lon[None, :] - lon[0]) * 87_000.0
    depth = 25.0 + 8.0 * np.tanh((east - north - 150.0) / 60.0) + 2.0 * np.cos(north / 30.0)
    xr.Dataset(
        {"elevation": (("lat", "lon"), -depth, {"units": "m"})},
        coords={
            "lat": ("lat", lat, {"units": "degrees_north"}),
            "lon": ("lon", lon, {"units": "degrees_east"}),
        },
    ).to_netcdf(path)


@pytest.fixture(scope="session")
def mission_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("api_mission")
    write_ridge(root / "ridge.nc")
    (root / "mission.toml").write_text(MISSION)
    return root / "mission.toml"


@pytest.fixture(scope="session")
def mission_plan(mission_file: Path) -> auvplan.MissionPlan:
    return auvplan.plan(mission_file, progress=False)


@pytest.fixture(scope="session")
def saved_folder(
    mission_plan: auvplan.MissionPlan, tmp_path_factory: pytest.TempPathFactory
) -> Path:
    """The plan saved with PNG figures at 60 dpi (read only)."""
    folder = tmp_path_factory.mktemp("api_saved") / "out"
    mission_plan.save(folder, dpi=60)
    return folder
