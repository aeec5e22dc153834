"""The record of an output folder: one writer, one reader, vehicles of different state sizes.

Folders are written by :func:`auvplan.record.write_record` (the ``write_plan_folder``
fixture) from hand-made trajectories; the reader's refusals are checked through
``auvplan evaluate`` and ``auvplan export`` (exit 2, one line naming the file, the line or
vehicle and the column, nothing written).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from auvplan.cli.main import main
from auvplan.errors import DataFormatError
from auvplan.record import VehicleTrajectory, export_plan, read_record, trajectories_dataset_of
from auvplan.record.files import NAVIGATION_FILE
from auvplan.sweep.navigation import NavigationOptions, evaluate_folder
from auvplan.terrain import BathymetryGrid, GridGeometry, LocalProjection, compute_terrain_maps
from auvplan.terrain.maps import TerrainMaps
from auvplan.vehicle import INPUT_NAMES, STATE_NAMES

#: The ``write_plan_folder`` fixture of ``tests/conftest.py``.
PlanFolderWriter = Callable[..., Path]

#: A 6-state vehicle type (no actuator states: surge force and yaw moment commanded directly).
SIX_STATES = ("north", "east", "psi", "u", "v", "r")
SIX_INPUTS = ("c_surge", "c_yaw")
FAST = ["--runs", "2", "--particles", "100", "--seed", "1", "--update-period", "2"]
ORIGIN = {"north": 0.0, "east": 0.0, "lat": 36.8, "lon": -121.81}


def _maps(*, relief: float = 8.0) -> TerrainMaps:
    geometry = GridGeometry(60, 50, 4.0, 4.0)
    north, east = np.meshgrid(geometry.north, geometry.east, indexing="ij")
    depth = 40.0 + relief * np.sin(north / 17.0) * np.cos(east / 23.0) + 0.05 * east
    return compute_terrain_maps(BathymetryGrid(depth, geometry, LocalProjection(36.8, -121.81)))


def _table(
    name: str, east: float, states: tuple[str, ...], inputs: tuple[str, ...]
) -> VehicleTrajectory:
    """A vehicle northbound at 1 m/s for 120 s, its actuator states (if any) at 30 rev/s."""
    time = np.arange(0.0, 120.5, 0.5)
    values = np.zeros((time.size, len(states)))
    values[:, 0] = 20.0 + time
    values[:, 1] = east + 10.0 * np.sin(time / 15.0)
    values[:, 3] = 1.0
    values[:, 6:] = 30.0
    return VehicleTrajectory(
        name, states, inputs, time, values, np.full((time.size - 1, len(inputs)), 0.1),
        45.0 + np.cos(time / 9.0),
    )  # fmt: skip


@pytest.fixture
def mixed_folder(tmp_path: Path, write_plan_folder: PlanFolderWriter) -> Path:
    """A 6-state and an 8-state vehicle in one plan, on georeferenced maps."""
    tables = (
        _table("six", 60.0, SIX_STATES, SIX_INPUTS),
        _table("eight", 120.0, STATE_NAMES, INPUT_NAMES),
    )
    terrain = {"name": "test", "origin": ORIGIN}
    return write_plan_folder(
        tmp_path / "out", _maps(), {"terrain_aware": tables}, extra={"terrain": terrain},
        mission={"mission": {"depth_m": 2.0}},
    )  # fmt: skip


def test_a_written_folder_reads_back_as_the_same_record(mixed_folder: Path) -> None:
    record = read_record(mixed_folder)
    assert record.summary.document() == json.loads((mixed_folder / "summary.json").read_text())
    six, eight = record.plans["terrain_aware"]
    assert (six.state_names, six.input_names) == (SIX_STATES, SIX_INPUTS)
    assert eight.state_names == STATE_NAMES
    assert six.states.shape == (241, 6)
    assert eight.states.shape == (241, 8)
    expected = _table("six", 60.0, SIX_STATES, SIX_INPUTS)
    np.testing.assert_array_equal(six.states, expected.states)
    np.testing.assert_array_equal(six.inputs, expected.inputs)
    np.testing.assert_array_equal(six.power, expected.power)
    with xr.open_dataset(mixed_folder / "trajectories.nc") as written:
        xr.testing.assert_identical(
            trajectories_dataset_of(record, "terrain_aware"), written.load()
        )


def test_mixed_state_sizes_write_load_export_and_evaluate(mixed_folder: Path) -> None:
    header = (mixed_folder / "trajectories.csv").read_text().splitlines()[0].split(",")
    assert header[-3:] == ["c_surge", "c_yaw", "power"]
    record = read_record(mixed_folder)
    plan = export_plan(record)
    assert [track.name for track in plan.tracks] == ["six", "eight"]
    assert plan.depth == 2.0
    np.testing.assert_allclose(plan.tracks[0].lat[0], 36.8 + 20.0 / 111_000.0, atol=1e-5)
    dataset = trajectories_dataset_of(record, "terrain_aware")
    assert np.isnan(dataset["n_ps"].values[0]).all()
    assert list(dataset["vehicle_type"].values) == ["medusa", "medusa"]
    navigation = evaluate_folder(record, NavigationOptions(n_runs=2, seed=1))
    assert set(navigation.document["plans"]["terrain_aware"]["vehicles"]) == {"six", "eight"}
    assert main(["-q", "evaluate", str(mixed_folder), *FAST, "--no-figure"]) == 0
    assert main(["-q", "export", str(mixed_folder), "--format", "gpx"]) == 0
    assert (mixed_folder / "export" / "trajectories.gpx").is_file()


def _replace_cell(folder: Path, row: int, column: str, text: str) -> None:
    """Set ``column`` of the row on file line ``row + 1`` to ``text``."""
    path = folder / "trajectories.csv"
    lines = path.read_text().splitlines()
    header = lines[0].split(",")
    cells = lines[row].split(",")
    cells[header.index(column)] = text
    lines[row] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")


def _damage(folder: Path, damage: str) -> None:
    """Make ``folder`` hold what no run of auvplan writes."""
    summary_path, csv_path = folder / "summary.json", folder / "trajectories.csv"
    summary = json.loads(summary_path.read_text())
    if damage == "nan":
        _replace_cell(folder, 5, "power", "nan")
    elif damage == "inf":
        _replace_cell(folder, 7, "u", "inf")
    elif damage == "empty_own_cell":
        _replace_cell(folder, 3, "r", "")
    elif damage == "speed":
        _replace_cell(folder, 9, "u", "4.0")  # top speed 2 m/s
    elif damage == "step":
        _replace_cell(folder, 12, "north", "80.0")  # a 50 m jump in 0.5 s
    elif damage == "header_only":
        csv_path.write_text(csv_path.read_text().splitlines()[0] + "\n")
    elif damage == "stranger":
        _replace_cell(folder, 4, "vehicle", "ghost")
    elif damage == "list":
        summary_path.write_text("[]")
    elif damage == "string":
        summary_path.write_text('"summary"')
    elif damage == "no_vehicles":
        del summary["vehicles"]
        summary_path.write_text(json.dumps(summary))
    elif damage == "no_name":
        del summary["vehicles"][1]["name"]
        summary_path.write_text(json.dumps(summary))
    elif damage == "edited":
        _replace_cell(folder, 5, "power", "41.0")  # a finite, plausible, but foreign value
    elif damage == "stale":
        del summary["digest"]["trajectories.csv"]  # as a --stage preplan rerun records it
        summary_path.write_text(json.dumps(summary))
    elif damage == "field":
        csv_path.write_text("vehicle,t\nsix," + "9" * 200_000 + "\n")
    elif damage == "missing":
        csv_path.unlink()
        csv_path.mkdir()
    elif damage == "no_v":
        summary["vehicles"][0]["state_names"].remove("v")
        summary_path.write_text(json.dumps(summary))
    elif damage == "twins":
        summary["vehicles"][1]["name"] = "six"
        summary_path.write_text(json.dumps(summary))
    elif damage == "depth":
        (folder / "mission.toml").write_text('[mission]\ndepth_m = "deep"\n')
    elif damage == "other_maps":
        from auvplan.io.maps_file import write_maps_netcdf

        write_maps_netcdf(_maps(relief=9.0), folder / "maps.nc")


@pytest.mark.parametrize(
    ("damage", "fragments"),
    [
        ("nan", ["trajectories.csv line 6", "'six'", "power = 'nan' is not a finite number"]),
        ("inf", ["trajectories.csv line 8", "u = 'inf' is not a finite number"]),
        ("empty_own_cell", ["trajectories.csv line 4", "r = '' is not a finite number"]),
        ("speed", ["trajectories.csv line 10", "'six'", "speed hypot(u, v) = 4 m/s"]),
        ("step", ["trajectories.csv line 13", "'six'", "north/east step of"]),
        ("header_only", ["trajectories.csv", "header only"]),
        ("stranger", ["trajectories.csv line 5", "vehicle 'ghost' is not in the summary"]),
        ("list", ["summary.json", "not a JSON object (a list)"]),
        ("string", ["summary.json", "not a JSON object (a str)"]),
        ("no_vehicles", ["summary.json", "entry vehicles: missing"]),
        ("no_name", ["summary.json", "entry vehicles.1.name: missing"]),
        ("edited", ["trajectories.csv is not the file the run of", "SHA-256 differs"]),
        ("stale", ["trajectories.csv is stale", "did not write it"]),
        ("other_maps", ["maps.nc was not written by the run of"]),
        ("field", ["trajectories.csv: not a CSV table (field larger than field limit"]),
        ("missing", ["trajectories.csv is missing: the run of"]),
        ("no_v", ["trajectories.csv vehicle 'six'", "lack 'v' (every vehicle has"]),
        ("twins", ["summary.json: entry (document): value error, vehicle name 'six' appears"]),
        ("depth", ["mission.toml: mission.depth_m = 'deep' is not a number"]),
    ],
)
@pytest.mark.parametrize("verb", ["evaluate", "export"])
def test_bad_or_stale_files_are_refused_in_one_line(
    mixed_folder: Path,
    capsys: pytest.CaptureFixture[str],
    damage: str,
    fragments: list[str],
    verb: str,
) -> None:
    _damage(mixed_folder, damage)
    before = sorted(p.name for p in mixed_folder.parent.rglob("*"))
    extra = FAST if verb == "evaluate" else ["--format", "gpx"]
    assert main([verb, str(mixed_folder), *extra]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    assert lines[0].startswith("auvplan: error: ")
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    assert sorted(p.name for p in mixed_folder.parent.rglob("*")) == before
    assert not (mixed_folder / NAVIGATION_FILE).exists()


def test_load_refuses_a_stale_folder(mixed_folder: Path) -> None:
    import auvplan

    _damage(mixed_folder, "stale")
    with pytest.raises(DataFormatError, match=r"trajectories\.csv is stale"):
        auvplan.load(mixed_folder)


def test_a_folder_of_an_earlier_auvplan_is_read_from_its_cells(mixed_folder: Path) -> None:
    """A summary without the vehicles' columns, top speeds and digest (written before them)."""
    summary_path = mixed_folder / "summary.json"
    summary = json.loads(summary_path.read_text())
    del summary["digest"]
    for vehicle in summary["vehicles"]:
        for key in ("type_name", "state_names", "input_names", "top_speed_m_s"):
            del vehicle[key]
    summary_path.write_text(json.dumps(summary))
    _replace_cell(mixed_folder, 9, "u", "4.0")  # unbounded without a top speed
    six, eight = read_record(mixed_folder).plans["terrain_aware"]
    assert (six.state_names, six.input_names) == (SIX_STATES, SIX_INPUTS)
    assert (eight.state_names, eight.input_names) == (STATE_NAMES, INPUT_NAMES)
    assert six.state("u")[8] == 4.0
