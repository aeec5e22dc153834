"""`auvplan plan`: every bad-input class exits non-zero with one line and writes nothing."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from auvplan.cli.main import main

# 60 x 80 cells of 5 m; a land block (NaN) in the north-west corner, a deep pit elsewhere.
N_ROWS, N_COLS, SPACING = 60, 80, 5.0


@pytest.fixture
def terrain_file(tmp_path: Path) -> Path:
    north = SPACING * np.arange(N_ROWS)
    east = SPACING * np.arange(N_COLS)
    depth = 30.0 + 10.0 * np.sin(north[:, None] / 40.0) * np.cos(east[None, :] / 55.0)
    depth[40:, :20] = np.nan  # land
    path = tmp_path / "grid.nc"
    xr.Dataset(
        {"depth": (("north", "east"), depth, {"units": "m", "positive": "down"})},
        coords={"north": ("north", north, {"units": "m"}), "east": ("east", east, {"units": "m"})},
    ).to_netcdf(path)
    return path


def _mission(terrain: Path, **edits: str) -> str:
    blue_start = edits.get("blue_start", "{ north = 10.0, east = 200.0, heading_deg = 0.0 }")
    green_start = edits.get("green_start", "{ north = 10.0, east = 300.0, heading_deg = 0.0 }")
    blue_goal = edits.get("blue_goal", "{ north = 250.0, east = 220.0 }")
    horizon = edits.get("horizon", "600.0")
    extra = edits.get("extra", "")
    return f"""
[terrain]
file = "{terrain.name}"
[fleet]
horizon_s = {horizon}
safety_radius_m = 5.0
[[vehicle]]
name = "blue"
start = {blue_start}
goal = {blue_goal}
[[vehicle]]
name = "green"
start = {green_start}
goal = {{ north = 250.0, east = 320.0 }}
{extra}
"""


def _run_bad(
    tmp_path: Path, text: str, capsys: pytest.CaptureFixture[str], stage: str = "preplan"
) -> str:
    mission = tmp_path / "mission.toml"
    mission.write_text(text)
    out = tmp_path / "out"
    code = main(["plan", str(mission), "-o", str(out), "--stage", stage, "--no-figures"])
    captured = capsys.readouterr()
    assert code != 0
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0].startswith("auvplan: error: ")
    assert not out.exists()
    assert not any(p.name.startswith(".out.") for p in tmp_path.iterdir())
    return lines[0]


def test_missing_mission_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["plan", str(tmp_path / "nope.toml"), "-o", str(tmp_path / "out")])
    assert code == 2
    assert "not found" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("edits", "fragment"),
    [
        ({"extra": "[planner]\nedge_model = 'quick'\n"}, "planner.edge_model"),
        ({"blue_start": "{ north = 280.0, east = 20.0 }"}, "blue"),  # on land
        ({"blue_start": "{ north = -50.0, east = 20.0 }"}, "blue"),  # outside the map
        ({"green_start": "{ north = 12.0, east = 203.0 }"}, "within 2 r_c"),
        (
            {"extra": "[[obstacle]]\ncenter = { north = 250.0, east = 220.0 }\nradius_m = 30.0\n"},
            "blue",
        ),  # goal inside an obstacle
        (
            {
                "extra": "[[obstacle]]\npolygon = [[100.0, -10.0], [110.0, -10.0], "
                "[110.0, 500.0], [100.0, 500.0]]\n"
            },
            "unreachable",
        ),  # a wall across the map
    ],
)
def test_bad_missions_at_preplan(
    tmp_path: Path,
    terrain_file: Path,
    capsys: pytest.CaptureFixture[str],
    edits: dict[str, str],
    fragment: str,
) -> None:
    message = _run_bad(tmp_path, _mission(terrain_file, **edits), capsys)
    assert fragment in message


def test_horizon_too_short(
    tmp_path: Path, terrain_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    message = _run_bad(tmp_path, _mission(terrain_file, horizon="20.0"), capsys, "deconflict")
    assert "horizon" in message
    assert "blue" in message or "green" in message


def test_bad_terrain_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    garbage = tmp_path / "grid.nc"
    garbage.write_bytes(b"definitely not netcdf")
    message = _run_bad(tmp_path, _mission(garbage), capsys)
    assert "grid.nc" in message


def test_preplan_writes_paths(
    tmp_path: Path, terrain_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import json

    mission = tmp_path / "mission.toml"
    mission.write_text(_mission(terrain_file))
    out = tmp_path / "out"
    assert main(["-q", "plan", str(mission), "-o", str(out), "--stage", "preplan"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    for vehicle in summary["vehicles"]:
        cells = np.array(vehicle["preplan"]["cells"])
        steps = np.abs(np.diff(cells, axis=0))
        assert steps.max() <= 2  # king and knight moves (navigation-aware routes)
        assert np.all(steps.sum(axis=1) <= 3)
        assert np.all(steps.sum(axis=1) >= 1)
        assert vehicle["preplan"]["graph_cost"] > 0
    for name in ("maps.nc", "maps.png", "paths.png", "paths.geojson"):
        assert (out / name).is_file(), name
    assert not (out / "trajectories.csv").exists()


def test_communication_range_violated_at_start(
    tmp_path: Path, terrain_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    extra = '[[comm]]\npair = ["blue", "green"]\nmax_range_m = 50.0\n'
    message = _run_bad(tmp_path, _mission(terrain_file, extra=extra), capsys)
    assert "blue and green start 100 m apart" in message


def test_cruise_speed_mode_deconflicts_and_arrives_together(
    tmp_path: Path, terrain_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import json

    text = _mission(terrain_file).replace("horizon_s = 600.0", "cruise_speed = 0.6")
    text += "[solver]\ndt_s = 0.5\n"
    mission = tmp_path / "mission.toml"
    mission.write_text(text)
    out = tmp_path / "out"
    assert main(["-q", "plan", str(mission), "-o", str(out), "--stage", "deconflict"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    horizon = summary["deconfliction"]["horizon_s"]
    assert horizon == pytest.approx(0.5 * round(horizon / 0.5))
    for vehicle in summary["vehicles"]:
        assert vehicle["timing"]["arrival_time_s"] == pytest.approx(horizon)
        assert vehicle["timing"]["nominal_speed_m_s"] == pytest.approx(0.6)
    assert summary["deconfliction"]["certified_min_separation_m"] >= 10.0
    rows = np.genfromtxt(out / "desired.csv", delimiter=",", skip_header=1, usecols=(1, 2, 3))
    blue, green = rows[: len(rows) // 2], rows[len(rows) // 2 :]
    np.testing.assert_allclose(blue[:, 0], green[:, 0])
    assert np.hypot(*(blue[:, 1:] - green[:, 1:]).T).min() >= 10.0
    assert not (out / "trajectories.csv").exists()
