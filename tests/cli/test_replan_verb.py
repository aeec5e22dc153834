"""``auvplan replan``: the golden mission's plan replanned from t = 60 s (of 150 s)."""

from __future__ import annotations

import csv
import json
from datetime import datetime, timedelta
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from _cli import one_error_line, run_cli

import auvplan
from auvplan.api.companion import Companion
from auvplan.api.result import MissionPlan

HEADER = "vehicle,north,east,heading_deg,speed\n"


@pytest.fixture(scope="module")
def parent_folder(
    golden_solved: tuple[Any, Any, Any], tmp_path_factory: pytest.TempPathFactory
) -> Path:
    """The golden plan's output folder, without figures (read only)."""
    folder = tmp_path_factory.mktemp("replan") / "parent"
    MissionPlan.from_result(golden_solved[1]).save(folder, figures=False)
    return folder


def _state_at(folder: Path, vehicle: str, t: float) -> dict[str, float]:
    with (folder / "trajectories.csv").open(newline="") as handle:
        row = next(
            r for r in csv.DictReader(handle) if r["vehicle"] == vehicle and float(r["t"]) == t
        )
    return {key: float(row[key]) for key in ("north", "east", "psi", "u")}


def test_replan_writes_a_plan_that_starts_from_the_states_and_names_its_parent(
    parent_folder: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    x = _state_at(parent_folder, "blue", 60.0)
    states = tmp_path / "states.csv"
    states.write_text(
        HEADER + f"blue,{x['north'] + 30.0},{x['east']},{np.degrees(x['psi'])},{x['u']}\n"
    )
    child = tmp_path / "child"
    argv = [str(parent_folder), "--at", "60", "--states", str(states), "-o", str(child)]
    code, _, err = run_cli(["-q", "replan", *argv, "--no-figures"], capsys)
    assert code == 0, err
    summary = json.loads((child / "summary.json").read_text())
    parent = json.loads((parent_folder / "summary.json").read_text())
    assert summary["replan"] == {
        "parent": parent_folder.name,
        "parent_digest": parent["digest"]["trajectories.csv"],
        "at_s": 60.0,
        "schedule": "kept",
    }
    assert summary["optimization"]["plan_status"] == "CONVERGED"
    assert summary["deconfliction"]["horizon_s"] == pytest.approx(90.0)
    start = datetime.fromisoformat(parent["start_time"]) + timedelta(seconds=60)
    assert datetime.fromisoformat(summary["start_time"]) == start
    assert summary["vehicles"][0]["start"]["north"] == pytest.approx(x["north"] + 30.0)
    replanned = auvplan.load(child).to_dataframe()  # a normal output folder, read back
    blue = replanned[replanned["vehicle"] == "blue"]
    assert blue["t"].iloc[0] == 0.0
    assert blue["t"].iloc[-1] == pytest.approx(90.0)
    assert blue["north"].iloc[0] == pytest.approx(x["north"] + 30.0)
    green = _state_at(child, "green", 0.0)
    assert green == _state_at(parent_folder, "green", 60.0)  # not listed: where the plan has it


@pytest.mark.parametrize(
    ("at", "states", "cause"),
    [
        ("0", None, "--at = 0 s must lie strictly between 0 and the horizon 150 s"),
        ("150", None, "--at = 150 s must lie strictly between 0 and the horizon 150 s"),
        ("-3", None, "--at = -3 s must lie strictly between 0"),
        ("60.25", None, "is not a multiple of the plan's solver.dt_s = 0.5 s"),
        ("nan", None, "argument --at: expected a number of seconds, got 'nan'"),
        ("60", HEADER + "red,50,400,0,0.5\n", "no vehicle named 'red' in the plan"),
        ("60", "vehicle,north,east,speed\nblue,50,400,0.5\n", "missing column(s) heading_deg"),
        ("60", "vehicle,heading_deg,speed\nblue,0,0.5\n", "missing column(s) north,east (or"),
        ("60", HEADER + "blue,nan,400,0,0.5\n", "line 2: north = 'nan' is not a finite number"),
        ("60", HEADER + "blue,50,400,0,0.5\nblue,50,400,0,0.5\n", "'blue' is given twice"),
        ("60", HEADER + "blue,50,400,0\n", "line 2: 4 cells, the header has 5"),
        ("60", HEADER + "blue,50,400,0,-1\n", "vehicle 'blue': "),
        ("60", HEADER + "blue,50,4000,0,0.5\n", "vehicle blue state (50, 4000) m is outside"),
        ("60", "vehicle,lat,lon,heading_deg,speed\nblue,38,-9,0,0.5\n", "no geographic ref"),
    ],
)
def test_bad_replan_inputs_exit_2_with_one_line_and_write_nothing(
    parent_folder: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    at: str,
    states: str | None,
    cause: str,
) -> None:
    argv = ["replan", str(parent_folder), "--at", at, "-o", str(tmp_path / "child")]
    if states is not None:
        (tmp_path / "states.csv").write_text(states)
        argv += ["--states", str(tmp_path / "states.csv")]
    code, out, err = run_cli(argv, capsys)
    assert code == 2
    line = err.strip() if at == "nan" else one_error_line(err)  # argparse: "auvplan replan: ..."
    assert cause in line
    assert "\n" not in line
    assert out == ""
    assert not (tmp_path / "child").exists()


def test_jobs_other_than_one_or_two_exit_2_and_write_nothing(
    parent_folder: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["replan", str(parent_folder), "--at", "60", "-o", str(tmp_path / "child")]
    code, out, err = run_cli([*argv, "--jobs", "3"], capsys)
    assert code == 2
    assert "--jobs (or $AUVPLAN_JOBS) must be 1 or 2, got 3" in one_error_line(err)
    assert out == ""
    assert not (tmp_path / "child").exists()


def test_a_vehicle_that_can_no_longer_make_it_exits_3_naming_it(
    parent_folder: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "states.csv").write_text(HEADER + "green,390,10,0,0.5\n")
    child = tmp_path / "child"
    argv = ["-q", "replan", str(parent_folder), "--at", "140", "-o", str(child), "--no-figures"]
    code, _, err = run_cli([*argv, "--states", str(tmp_path / "states.csv")], capsys)
    assert code == 3
    line = err.strip()
    assert line.startswith("auvplan: plan FAILED: vehicle green can no longer reach its goal")
    assert "\n" not in line
    summary = json.loads((child / "summary.json").read_text())
    assert summary["optimization"]["plan_status"] == "FAILED"
    assert summary["replan"]["at_s"] == 140.0


def test_figures_of_a_replan_on_two_cores_are_those_drawn_on_one(
    parent_folder: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """With ``--jobs 2`` the second process draws half the figures (as ``plan`` does): the
    same files, byte for byte, as one process draws."""
    shared: list[int] = []
    render = Companion.render_figures

    def spied(self: Companion, *args: Any, **kwargs: Any) -> Any:
        shared.append(1)
        return render(self, *args, **kwargs)

    monkeypatch.setattr(Companion, "render_figures", spied)
    folders = {}
    for jobs in ("1", "2"):
        folders[jobs] = tmp_path / f"jobs{jobs}"
        argv = [str(parent_folder), "--at", "60", "-o", str(folders[jobs]), "--dpi", "30"]
        code, _, err = run_cli(["-q", "replan", *argv, "--jobs", jobs], capsys)
        assert code == 0, err
        assert len(shared) == int(jobs) - 1  # the second process drew with --jobs 2 only
    figures = sorted(path.name for path in folders["1"].glob("*.png"))
    assert len(figures) >= 5
    assert sorted(path.name for path in folders["2"].glob("*.png")) == figures
    for name in figures:
        assert (folders["2"] / name).read_bytes() == (folders["1"] / name).read_bytes(), name
