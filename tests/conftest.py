"""Shared fixtures: a seeded RNG and the real bathymetry grids of ../shared/data."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import matplotlib
import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from auvplan.scenarios._terrain import write_synthetic_terrain
from auvplan.terrain import BathymetryGrid, GridGeometry

matplotlib.use("Agg")
# the CLI's second process (auvplan.api.companion) is tested on its own: the many in-process
# `auvplan plan` runs of the suite use one process each, as `--jobs 1`
os.environ.setdefault("AUVPLAN_JOBS", "1")

SHARED_DATA = Path(
    os.environ.get("AUVPLAN_SHARED_DATA", Path(__file__).parents[1] / ".." / "shared" / "data")
)


@pytest.fixture
def rng() -> np.random.Generator:
    """A seeded generator; tests never touch global random state."""
    return np.random.default_rng(20131023)


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """``../shared/data`` (skip the test when the folder is absent)."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"shared data folder not found at {SHARED_DATA}")
    return SHARED_DATA.resolve()


@pytest.fixture(scope="session")
def bathymetry_dir(shared_data: Path) -> Path:
    """``../shared/data/bathymetry`` (skip when absent)."""
    path = shared_data / "bathymetry"
    if not path.is_dir():
        pytest.skip(f"bathymetry folder not found at {path}")
    return path


#: A mission writer of :func:`transit_mission`: ``(folder, ridge=..., navigation=...)``.
TransitMission = Callable[..., Path]

SPACING = 10.0
N = 160  # 1.6 km square


def _plain(path: Path, *, ridge: bool) -> Path:
    """A featureless plain, with a rough ridge 160 m north of the transit line if asked."""
    rows = np.arange(N)[:, None] + np.zeros((1, N))
    depth = 60.0 + 0.002 * SPACING * np.arange(N)[None, :] + np.zeros((N, N))
    if ridge:
        band = np.exp(-0.5 * ((rows - 96) / 4.0) ** 2)
        rough = gaussian_filter(np.random.default_rng(5).normal(0.0, 10.0, (N, N)), 1.5)
        depth = depth - 15.0 * band + band * rough
    write_synthetic_terrain(BathymetryGrid(depth, GridGeometry(N, N, SPACING, SPACING)), path)
    return path


def _transit_mission(folder: Path, *, ridge: bool, navigation: str = "") -> Path:
    _plain(folder / "terrain.nc", ridge=ridge)
    mission = folder / "mission.toml"
    mission.write_text(
        f"""
[terrain]
file = "terrain.nc"
[fleet]
horizon_s = 2200.0
safety_radius_m = 5.0
[solver]
dt_s = 2.0
[navigation]
settle_s = 300.0
{navigation}
[[vehicle]]
name = "blue"
start = {{ north = 800.0, east = 50.0, heading_deg = 90.0 }}
goal = {{ north = 800.0, east = 1550.0, heading_deg = 90.0 }}
""",
        encoding="utf-8",
    )
    return mission


@pytest.fixture
def transit_mission() -> TransitMission:
    """Writes a 1.5 km, 37 min transit of one MEDUSA over a plain (with or without a rough
    ridge 160 m beside the line) and its ``terrain.nc`` into a folder; returns the mission file.
    ``navigation`` adds lines to its ``[navigation]`` table."""
    return _transit_mission
