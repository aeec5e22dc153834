"""A small mission plans and converges in a current file of each provider's convention."""

from __future__ import annotations

import tomllib
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from auvplan.mission.config import parse_mission
from auvplan.mission.pipeline import run_mission

from ._current_files import (
    EAST,
    NORTH,
    analytic,
    level_factor,
    roms_factor,
    write_copernicus,
    write_hycom,
    write_roms,
    write_rtofs,
)

#: One MEDUSA on a 300 m leg in Monterey Bay at the surface, one hour into the files' times.
MISSION = """
[terrain]
sample = "monterey"
window = { lat = [36.788, 36.802], lon = [-121.822, -121.802] }
[fleet]
horizon_s = 600.0
safety_radius_m = 5.0
[mission]
start_time = 2026-05-01T07:00:00Z
[current]
file = "current.nc"
[[vehicle]]
name = "blue"
start = { lat = 36.7945, lon = -121.8150, heading_deg = 60.0 }
goal = { lat = 36.7960, lon = -121.8125, heading_deg = 60.0 }
"""

WRITERS: dict[str, Callable[[Path], Path]] = {
    "hycom": write_hycom,
    "copernicus": write_copernicus,
    "rtofs": lambda path: write_rtofs(path, three_d=True),
    "roms": lambda path: write_roms(path, angle_deg=30.0),
}


@pytest.mark.slow
@pytest.mark.parametrize("convention", sorted(WRITERS))
def test_a_mission_in_each_convention_plans_and_converges(tmp_path: Path, convention: str) -> None:
    """The plan converges, and the current it planned in is the file's field at the start."""
    WRITERS[convention](tmp_path / "current.nc")
    config = parse_mission(tomllib.loads(MISSION), base_dir=tmp_path)
    result = run_mission(config)
    assert result.plan is not None, result.failure
    assert result.plan.verdict.success, result.plan.verdict
    current, projection = result.preplan.current, result.preplan.bathymetry.projection
    assert current is not None
    assert projection is not None
    start = result.preplan.starts[0]
    lat, lon = projection.to_geographic(start[:1], start[1:2])
    v_n, v_e = current.velocity(start[:1], start[1:2], np.zeros(1))
    # one hour after the files' first time, at the first level (Copernicus's 0.494 m, ROMS's
    # top s-level 0.68 m deep)
    first_level = {"copernicus": level_factor(0.494), "roms": float(roms_factor(75.0 / 110.0))}
    factor = first_level.get(convention, 1.0)
    np.testing.assert_allclose(v_n, factor * analytic(NORTH, lat, lon, np.ones(1)), atol=1e-3)
    np.testing.assert_allclose(v_e, factor * analytic(EAST, lat, lon, np.ones(1)), atol=1e-3)
