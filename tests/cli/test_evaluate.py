"""`auvplan evaluate`: navigation.json and .png from a plan folder; errors are one line."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from auvplan.cli.main import main
from auvplan.record import VehicleTrajectory
from auvplan.terrain import BathymetryGrid, GridGeometry, compute_terrain_maps
from auvplan.vehicle import INPUT_NAMES, STATE_NAMES

#: The ``write_plan_folder`` fixture of ``tests/conftest.py``.
PlanFolderWriter = Callable[..., Path]

FAST = ["--runs", "3", "--particles", "200", "--seed", "1", "--update-period", "2"]


def _tables(
    time: np.ndarray, east_offsets: tuple[float, ...], wiggle: float
) -> tuple[VehicleTrajectory, ...]:
    """Two northbound MEDUSAs at 1 m/s, each with its own power [W]."""
    tables = []
    for i, (name, east) in enumerate(zip(("blue", "green"), east_offsets, strict=True)):
        states = np.zeros((time.size, 8))
        states[:, 0] = 20.0 + time
        states[:, 1] = east + wiggle * np.sin(time / 15.0)
        states[:, 3] = 1.0
        power = 40.0 + 5.0 * np.cos(time / 7.0) + 3.0 * i
        tables.append(VehicleTrajectory(name, STATE_NAMES, INPUT_NAMES, time, states,
                                        np.zeros((time.size - 1, 2)), power))  # fmt: skip
    return tuple(tables)


@pytest.fixture
def plan_folder(tmp_path: Path, write_plan_folder: PlanFolderWriter) -> Path:
    """A minimal plan output folder written by the project's own writers (150 s mission)."""
    geometry = GridGeometry(60, 50, 4.0, 4.0)
    north, east = np.meshgrid(geometry.north, geometry.east, indexing="ij")
    depth = 40.0 + 8.0 * np.sin(north / 17.0) * np.cos(east / 23.0) + 0.05 * east
    maps = compute_terrain_maps(BathymetryGrid(depth, geometry))
    time = np.arange(0.0, 150.5, 0.5)
    plans = {
        "terrain_aware": _tables(time, (60.0, 120.0), wiggle=15.0),
        "energy_only": _tables(time, (60.0, 120.0), wiggle=0.0),
    }
    energies = [sum(table.energy for table in tables) for tables in plans.values()]
    return write_plan_folder(tmp_path / "out", maps, plans, extra={"test_energy_J": energies})


def test_evaluate_writes_navigation_json_and_figure(
    plan_folder: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    before = {p.name: p.read_bytes() for p in plan_folder.iterdir()}
    assert main(["evaluate", str(plan_folder), *FAST]) == 0
    out = capsys.readouterr().out
    assert out.count("3 runs (") == 4  # plain progress lines off a terminal: one per track
    assert "terrain-aware vs energy-only" in out
    document = json.loads((plan_folder / "navigation.json").read_text())
    expected_energy = json.loads((plan_folder / "summary.json").read_text())["test_energy_J"]
    for label, energy in zip(("terrain_aware", "energy_only"), expected_energy, strict=True):
        plan = document["plans"][label]
        assert plan["energy_J"] == pytest.approx(energy, rel=1e-12)
        assert 0.0 < plan["rmse_m"] < plan["dead_reckoning_rmse_m"]
        assert set(plan["vehicles"]) == {"blue", "green"}
        assert plan["vehicles"]["blue"]["distance_m"] >= 150.0 - 1e-9  # 150 s at 1 m/s
    assert document["plans"]["terrain_aware"]["terrain_weight"] == 1.0
    comparison = document["comparison"]
    aware, only = document["plans"]["terrain_aware"], document["plans"]["energy_only"]
    assert comparison["rmse_reduction"] == pytest.approx(1.0 - aware["rmse_m"] / only["rmse_m"])
    assert document["settings"]["n_runs"] == 3
    assert (plan_folder / "navigation.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    for name, content in before.items():  # the plan's own files are kept as they were
        assert (plan_folder / name).read_bytes() == content


def test_same_seed_same_json_and_only_the_plans_present(
    plan_folder: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (plan_folder / "trajectories_energy_only.csv").unlink()
    args = ["evaluate", str(plan_folder), *FAST, "--no-figure", "-q"]
    assert main(args) == 0
    first = (plan_folder / "navigation.json").read_text()
    assert main(args) == 0
    assert (plan_folder / "navigation.json").read_text() == first
    document = json.loads(first)
    assert list(document["plans"]) == ["terrain_aware"]
    assert "comparison" not in document
    assert not (plan_folder / "navigation.png").exists()
    assert capsys.readouterr().out == ""


@pytest.mark.parametrize(
    ("damage", "extra", "fragment"),
    [
        ("no_maps", [], "maps.nc not found"),
        ("no_trajectories", [], "trajectories.csv is missing: the run of"),
        ("bad_column", [], "no column 'psi' of vehicle 'blue'"),
        ("bad_number", [], "is not a finite number"),
        (None, ["--runs", "0"], "--runs must be >= 1"),
        (None, ["--particles", "1"], "needs >= 2 particles"),
        (None, ["--update-period", "500"], "less than one update period"),
    ],
)
def test_errors_are_one_line_and_write_nothing(
    plan_folder: Path,
    capsys: pytest.CaptureFixture[str],
    damage: str | None,
    extra: list[str],
    fragment: str,
) -> None:
    trajectories = plan_folder / "trajectories.csv"
    if damage == "no_maps":
        (plan_folder / "maps.nc").unlink()
    elif damage == "no_trajectories":
        trajectories.unlink()
    elif damage == "bad_column":
        trajectories.write_text(trajectories.read_text().replace(",psi,", ",heading,", 1))
    elif damage == "bad_number":
        lines = trajectories.read_text().splitlines()
        lines[5] = lines[5].replace("blue,", "blue,oops", 1)
        trajectories.write_text("\n".join(lines) + "\n")
    before = sorted(p.name for p in plan_folder.parent.rglob("*"))
    assert main(["evaluate", str(plan_folder), *FAST, *extra]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    assert lines[0].startswith("auvplan: error: ")
    assert fragment in lines[0]
    assert sorted(p.name for p in plan_folder.parent.rglob("*")) == before


def test_missing_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["evaluate", str(tmp_path / "nowhere")]) == 2
    assert "not found" in capsys.readouterr().err
    assert not (tmp_path / "nowhere").exists()


def test_evaluate_flies_the_folders_navigation_table_and_flags_override_it(
    plan_folder: Path,
) -> None:
    """The plan's [navigation] table is the evaluator's model; a flag given overrides it."""
    (plan_folder / "mission.toml").write_text(
        "[navigation]\ndrift_percent = 0.5\ninitial_sigma_m = 3.0\n[mission]\ndepth_m = 5.0\n",
        encoding="utf-8",
    )
    assert main(["-q", "evaluate", str(plan_folder), *FAST, "--no-figure"]) == 0
    settings = json.loads((plan_folder / "navigation.json").read_text())["settings"]
    assert settings["dead_reckoning"]["drift_fraction"] == pytest.approx(0.005)
    assert settings["particle_filter"]["initial_sigma"] == 3.0
    assert settings["sensor"]["vehicle_depth"] == 5.0
    assert settings["update_period_s"] == 2.0  # the flag
    assert main(["-q", "evaluate", str(plan_folder), *FAST, "--no-figure", "--drift", "2"]) == 0
    settings = json.loads((plan_folder / "navigation.json").read_text())["settings"]
    assert settings["dead_reckoning"]["drift_fraction"] == pytest.approx(0.02)
    assert settings["particle_filter"]["initial_sigma"] == 3.0


@pytest.mark.parametrize(
    ("flag", "value"), [("--update-period", "1e-4"), ("--drift", "1e6"), ("--initial-sigma", "-1")]
)
def test_navigation_flags_out_of_range_exit_2_naming_the_key(
    plan_folder: Path, capsys: pytest.CaptureFixture[str], flag: str, value: str
) -> None:
    assert main(["-q", "evaluate", str(plan_folder), "--runs", "2", flag, value]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith("auvplan: error: navigation.")
    assert not (plan_folder / "navigation.json").exists()
