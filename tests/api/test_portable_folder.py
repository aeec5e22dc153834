"""Folders that travel (issue 25): an output folder copied elsewhere, the inputs gone, reruns.

A small mission on a real file-based grid (the packaged Monterey sample with one absurd value
in a corner, cropped by a lat/lon window), a gridded current file and two vehicle files naming
their own propeller tables (one beside the file, one in another folder) is planned; the folder
is copied to another place and every original input deleted; ``auvplan plan COPY/mission.toml
-o NEW`` must give the same trajectories and maps. No output file may hold an absolute path.
"""

from __future__ import annotations

import json
import shutil
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from auvplan.cli.main import main
from auvplan.io.samples import sample_path
from auvplan.io.text import read_toml
from auvplan.record import read_record
from ocean._current_files import write_current_file

PACKAGED = resources.files("auvplan").joinpath("data")
MEDUSA = PACKAGED.joinpath("vehicles", "medusa.toml").read_text(encoding="utf-8")
TABLE = PACKAGED.joinpath("propellers", "wageningen_b4-70_pd1.4.csv").read_bytes()
MISSION = """
[terrain]
file = "../data/grid.nc"
window = { lat = [36.79360, 36.79714], lon = [-121.81473, -121.80582] }
[fleet]
horizon_s = 90.0
safety_radius_m = 5.0
[[vehicle]]
name = "blue"
type = "../boats/boat.toml"
start = { north = 10.0, east = 330.0, heading_deg = 0.0, speed = 0.5 }
goal = { north = 50.0, east = 340.0, heading_deg = 0.0 }
[[vehicle]]
name = "green"
type = "../far/boat.toml"
start = { north = 10.0, east = 470.0, heading_deg = 0.0, speed = 0.5 }
goal = { north = 50.0, east = 460.0, heading_deg = 0.0 }
[current]
file = "../data/currents.nc"
[solver]
dt_s = 1.0
[mission]
start_time = 2026-05-01T07:00:00Z
"""
#: The distributions whose versions summary.json must record (besides auvplan and python).
NUMERIC = ("numpy", "scipy", "casadi", "numba", "xarray", "pyproj")


def _inputs(root: Path) -> Path:
    """The mission's inputs under ``root/source``; returns the mission file."""
    source = root / "source"
    for folder in ("data", "boats/props", "far", "missions"):
        (source / folder).mkdir(parents=True)
    with xr.open_dataset(sample_path("monterey")) as sample:
        grid = sample.load()
    # one absurd value in the window's north-west corner, far from the paths: a warning that
    # names the grid file (summary.json keeps it without the file's folders)
    row = int(np.searchsorted(grid["lat"].values, 36.7970)) - 1
    col = int(np.searchsorted(grid["lon"].values, -121.8146)) + 1
    grid["elevation"][row, col] = -30_000.0
    grid.to_netcdf(source / "data" / "grid.nc")
    write_current_file(source / "data" / "currents.nc")
    (source / "data" / "b4.csv").write_bytes(TABLE)
    (source / "boats" / "props" / "mine.csv").write_bytes(TABLE)
    for folder, table in (("boats", "props/mine.csv"), ("far", "../data/b4.csv")):
        text = MEDUSA.replace('"wageningen_b4-70_pd1.4"', f'"{table}"', 1)
        assert text != MEDUSA
        (source / folder / "boat.toml").write_text(text, encoding="utf-8")
    (source / "missions" / "mission.toml").write_text(MISSION, encoding="utf-8")
    return source / "missions" / "mission.toml"


@pytest.fixture(scope="module")
def travelled(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, Path]:
    """``(root, original, rerun)``: the folder planned, copied, inputs deleted, planned again."""
    root = tmp_path_factory.mktemp("travel")
    mission = _inputs(root)
    original = root / "out"
    assert main(["-q", "plan", str(mission), "-o", str(original), "--no-figures"]) == 0
    copy = root / "elsewhere" / "copy"
    shutil.copytree(original, copy)
    shutil.rmtree(root / "source")  # the mission, grid, current, vehicle files and tables
    rerun = root / "elsewhere" / "new"
    assert main(["-q", "plan", str(copy / "mission.toml"), "-o", str(rerun), "--no-figures"]) == 0
    return root, original, rerun


def test_a_copied_folder_reruns_to_the_same_trajectories(
    travelled: tuple[Path, Path, Path],
) -> None:
    _, original, rerun = travelled
    first, second = (pd.read_csv(folder / "trajectories.csv") for folder in (original, rerun))
    assert list(first.columns) == list(second.columns)
    assert list(first["vehicle"]) == list(second["vehicle"])
    numbers = first.columns[1:]
    np.testing.assert_allclose(second[numbers], first[numbers], rtol=0.0, atol=1e-9)
    # the run saw the same grid: maps.nc's arrays are bit for bit the original's
    digests = [json.loads((f / "summary.json").read_text())["digest"] for f in (original, rerun)]
    assert digests[0]["maps.nc"] == digests[1]["maps.nc"]
    assert read_record(rerun).has_plan  # the rerun's folder reads back (digest checked)


def test_the_folder_names_its_own_inputs(travelled: tuple[Path, Path, Path]) -> None:
    _, original, _ = travelled
    mission = read_toml(original / "mission.toml", what="mission file")
    assert mission["terrain"]["file"] == "maps.nc"
    assert "lat" not in mission["terrain"]["window"]  # maps.nc is already cropped
    assert mission["current"]["file"] == "inputs/currents.nc"
    assert [v["type"] for v in mission["vehicle"]] == ["inputs/boat.toml", "inputs/2/boat.toml"]
    carried = original / "inputs"
    assert (carried / "props" / "mine.csv").read_bytes() == TABLE
    assert (carried / "2" / "b4.csv").read_bytes() == TABLE
    assert read_toml(carried / "2" / "boat.toml", what="vehicle")["propeller"]["table"] == "b4.csv"
    # the vehicle file kept in place is a byte copy: the rerun read a file of the same SHA-256
    summaries = [json.loads((f / "summary.json").read_text()) for f in travelled[1:]]
    vehicles = [summary["inputs"]["vehicles"] for summary in summaries]
    assert vehicles[0]["inputs/boat.toml"] == vehicles[1]["inputs/boat.toml"]
    assert read_record(original).has_plan  # the digest check still holds


def test_no_output_file_holds_an_absolute_path(travelled: tuple[Path, Path, Path]) -> None:
    root, original, rerun = travelled
    warnings = json.loads((original / "summary.json").read_text())["warnings"]
    assert [line for line in warnings if line.startswith("bathymetry grid.nc: 1 of ")], warnings
    needles = {str(root).encode(), str(root.resolve()).encode(), str(Path.cwd()).encode()}
    for folder in (original, rerun):
        files = sorted(path for path in folder.rglob("*") if path.is_file())
        assert {"mission.toml", "summary.json", "report.html"} <= {p.name for p in files}
        for path in files:
            content = path.read_bytes()
            found = [needle.decode() for needle in needles if needle in content]
            assert not found, f"{path.relative_to(folder)} holds {found}"


def test_summary_records_the_software_versions(travelled: tuple[Path, Path, Path]) -> None:
    summary = json.loads((travelled[1] / "summary.json").read_text())
    assert summary["auvplan_version"]
    environment = summary["environment"]
    assert environment["python"].count(".") == 2
    for name in NUMERIC:
        assert environment["packages"][name], name
