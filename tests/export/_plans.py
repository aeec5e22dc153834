"""Builders of the export tests: a synthetic plan and a small georeferenced mission."""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import xarray as xr

from auvplan.export.plan import CircleZone, ExportPlan, PolygonZone, VehicleTrack
from auvplan.terrain import LocalProjection

START = datetime(2026, 5, 1, 8, 0, 0, tzinfo=UTC)
ORIGIN = (36.79, -121.815)  # lat, lon [deg] of the local origin (Monterey Bay)


def synthetic_track(name: str, east_offset: float) -> VehicleTrack:
    """A curving track that slows down, waits 10 s and speeds up again (dt = 0.5 s)."""
    time = np.arange(0.0, 120.0 + 0.25, 0.5)
    progress = np.interp(time, [0.0, 40.0, 50.0, 120.0], [0.0, 22.0, 22.0, 70.0])
    north = 10.0 + progress
    east = east_offset + 12.0 * np.sin(progress / 15.0)
    lat, lon = LocalProjection(*ORIGIN).to_geographic(north, east)
    return VehicleTrack(name, time, north, east, lat, lon)


def synthetic_plan() -> ExportPlan:
    """Two vehicles (one with characters XML must escape), a circle and a polygon obstacle."""
    projection = LocalProjection(*ORIGIN)
    square_lat, square_lon = projection.to_geographic(
        np.array([100.0, 100.0, 120.0, 120.0]), np.array([50.0, 80.0, 80.0, 50.0])
    )
    circle_lat, circle_lon = projection.to_geographic(np.array([80.0]), np.array([300.0]))
    return ExportPlan(
        tracks=(synthetic_track("blue", 150.0), synthetic_track("r&d <2>", 250.0)),
        start_time=START,
        depth=3.0,
        origin_lat=ORIGIN[0],
        origin_lon=ORIGIN[1],
        capture_radius=5.0,
        zones=(
            CircleZone("rock", float(circle_lat[0]), float(circle_lon[0]), 10.0),
            PolygonZone("wreck", square_lat, square_lon),
        ),
    )


MISSION = """
[terrain]
file = "grid.nc"
[fleet]
horizon_s = 80.0
safety_radius_m = 5.0
[[vehicle]]
name = "blue"
start = { north = 20.0, east = 150.0, speed = 0.5 }
goal = { north = 52.0, east = 170.0 }
[[vehicle]]
name = "green"
start = { north = 20.0, east = 250.0, speed = 0.5 }
goal = { north = 52.0, east = 230.0 }
[[obstacle]]
name = "rock"
center = { north = 80.0, east = 300.0 }
radius_m = 10.0
[[obstacle]]
name = "wreck"
polygon = [[100.0, 50.0], [100.0, 80.0], [120.0, 80.0], [120.0, 50.0]]
[solver]
dt_s = 1.0
[mission]
start_time = 2026-05-01T10:00:00+02:00
depth_m = 3.0
[metadata]
creator_name = "Ada Operator"
creator_email = "ada@example.org"
creator_url = "https://example.org/ada"
creator_type = "person"
institution = "Example Marine Robotics Lab"
project = "auvplan export tests"
license = "CC-BY-4.0"
naming_authority = "org.example"
"""


def write_geographic_grid(path: Path) -> None:
    """A 500 m x 500 m lat/lon grid (about 5 m cells) with smooth relief, depths 20-40 m."""
    lat = np.linspace(36.790, 36.7945, 91)
    lon = np.linspace(-121.815, -121.8094, 101)
    north = (lat[:, None] - lat[0]) * 111_000.0
    east = (lon[None, :] - lon[0]) * 89_000.0
    elevation = -(30.0 + 10.0 * np.sin(north / 40.0) * np.cos(east / 55.0))
    xr.Dataset(
        {"elevation": (("lat", "lon"), elevation, {"units": "m"})},
        coords={
            "lat": ("lat", lat, {"units": "degrees_north"}),
            "lon": ("lon", lon, {"units": "degrees_east"}),
        },
    ).to_netcdf(path)
