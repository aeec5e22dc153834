"""The bathymetry samples shipped with auvplan: intact, readable, named by a mission."""

from __future__ import annotations

import hashlib
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

from auvplan.errors import InputError
from auvplan.io.bathymetry import read_bathymetry
from auvplan.io.samples import SAMPLE_FILES, sample_path, samples_folder
from auvplan.mission.config import parse_mission
from auvplan.mission.preplan import load_terrain

SHARED = Path(__file__).parents[3] / "shared" / "data" / "bathymetry"


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.mark.parametrize("name", sorted(SAMPLE_FILES))
def test_each_sample_is_the_cited_file(name: str) -> None:
    """The checksum listed in the README beside the files (and the shared copy's, if present)."""
    readme = (samples_folder() / "README.md").read_text(encoding="utf-8")
    listed = dict(re.findall(r"- `([\w.]+\.nc)`: `([0-9a-f]{64})`", readme))
    path = sample_path(name)  # type: ignore[arg-type]
    assert _sha256(path) == listed[path.name]
    if (SHARED / path.name).is_file():
        assert _sha256(SHARED / path.name) == listed[path.name]
    grid = read_bathymetry(path)
    assert grid.projection is not None  # georeferenced
    assert grid.depth.size > 10_000


def _mission(terrain: str) -> str:
    return f"""
[terrain]
{terrain}
[fleet]
horizon_s = 300.0
safety_radius_m = 5.0
[[vehicle]]
name = "blue"
start = {{ lat = 36.7940, lon = -121.8140 }}
goal = {{ lat = 36.7960, lon = -121.8100 }}
"""


def test_a_mission_names_a_sample() -> None:
    config = parse_mission(tomllib.loads(_mission('sample = "monterey"')))
    assert config.terrain.path == sample_path("monterey")
    window = config.terrain.window
    expected = read_bathymetry(
        sample_path("monterey"),
        window_north=window.north,
        window_east=window.east,
        window_lat=window.lat,
        window_lon=window.lon,
    )
    np.testing.assert_array_equal(load_terrain(config.terrain).depth, expected.depth)


@pytest.mark.parametrize(
    "terrain",
    ['sample = "monterey"\nsynthetic = true', 'sample = "azores"', "synthetic = false"],
)
def test_one_terrain_source_by_name(terrain: str) -> None:
    with pytest.raises(InputError, match="terrain"):
        parse_mission(tomllib.loads(_mission(terrain)))
