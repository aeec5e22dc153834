"""Fixtures of the sweep tests: a tiny mission on a small synthetic grid, an in-process cluster."""

from __future__ import annotations

import functools
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import xarray as xr

#: 60 x 80 cells of 5 m; land (NaN) in the north-west corner.
N_ROWS, N_COLS, SPACING = 60, 80, 5.0

TINY_MISSION = """
[terrain]
file = "grid.nc"
[fleet]
horizon_s = 600.0
safety_radius_m = 5.0
[[vehicle]]
name = "blue"
start = { north = 10.0, east = 200.0, heading_deg = 0.0 }
goal = { north = 250.0, east = 220.0 }
[[vehicle]]
name = "green"
start = { north = 10.0, east = 300.0, heading_deg = 0.0 }
goal = { north = 250.0, east = 320.0 }
"""


#: One vehicle for 300 s at a 2 s control interval: a full plan in a few seconds.
TINY_FULL_MISSION = """
[terrain]
file = "grid.nc"
[fleet]
horizon_s = 300.0
safety_radius_m = 5.0
[[vehicle]]
name = "blue"
start = { north = 10.0, east = 200.0, heading_deg = 0.0 }
goal = { north = 150.0, east = 220.0 }
[solver]
dt_s = 2.0
"""


def _write_tiny_mission(folder: Path, text: str) -> Path:
    """``text`` as ``folder/mission.toml`` next to its 300 m x 400 m grid ``grid.nc``."""
    north = SPACING * np.arange(N_ROWS)
    east = SPACING * np.arange(N_COLS)
    depth = 30.0 + 10.0 * np.sin(north[:, None] / 40.0) * np.cos(east[None, :] / 55.0)
    depth[40:, :20] = np.nan
    xr.Dataset(
        {"depth": (("north", "east"), depth, {"units": "m", "positive": "down"})},
        coords={"north": ("north", north, {"units": "m"}), "east": ("east", east, {"units": "m"})},
    ).to_netcdf(folder / "grid.nc")
    path = folder / "mission.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture
def tiny_mission(tmp_path: Path) -> Path:
    """A two-vehicle mission on a 300 m x 400 m grid (``--stage preplan`` takes < 1 s)."""
    return _write_tiny_mission(tmp_path, TINY_MISSION)


@pytest.fixture
def tiny_full_mission(tmp_path: Path) -> Path:
    """One vehicle on the same grid, cheap enough to plan in full in the fast suite."""
    return _write_tiny_mission(tmp_path, TINY_FULL_MISSION)


@pytest.fixture
def fast_demo_mission(tmp_path: Path) -> Path:
    """The demo mission at a 2 s control interval: the cheapest mission that still optimises."""
    text = (resources.files("auvplan") / "data/missions/demo.toml").read_text(encoding="utf-8")
    path = tmp_path / "demo_fast.toml"
    path.write_text(text.replace("dt_s = 0.5", "dt_s = 2.0"), encoding="utf-8")
    return path


@pytest.fixture
def inprocess_cluster(monkeypatch: pytest.MonkeyPatch) -> None:
    """The sweep's LocalCluster runs its workers as threads of the test process (fast start)."""
    distributed = pytest.importorskip("distributed")
    original = distributed.LocalCluster

    @functools.wraps(original)
    def threads(*args: Any, **kwargs: Any) -> Any:
        return original(*args, **{**kwargs, "processes": False})

    monkeypatch.setattr(distributed, "LocalCluster", threads)
