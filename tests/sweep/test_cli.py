"""``auvplan sweep`` end to end on a tiny mission (``--stage preplan``, in-process dask workers)."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

from auvplan.cli.main import main
from auvplan.io.text import file_sha256

GOOD_START = "{ north = 10.0, east = 200.0, heading_deg = 0.0 }"
LAND_START = "{ north = 280.0, east = 20.0 }"


def _sweep(mission: Path, out: Path, *options: str) -> int:
    return main(["sweep", str(mission), "-o", str(out), "--stage", "preplan", *options])


@pytest.mark.usefixtures("inprocess_cluster")
def test_second_invocation_skips_finished_runs(
    tiny_mission: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "sweep"
    assert _sweep(tiny_mission, out, "--vary", "weights.terrain=0,1") == 0
    first = pd.read_csv(out / "sweep.csv")
    assert first["run_id"].tolist() == ["weights.terrain=0.0", "weights.terrain=1.0"]
    assert first["status"].tolist() == ["PREPLANNED", "PREPLANNED"]
    summaries = {path: path.stat().st_mtime_ns for path in out.glob("runs/*/summary.json")}
    assert len(summaries) == 2
    capsys.readouterr()

    assert _sweep(tiny_mission, out, "--vary", "weights.terrain=0,1,2") == 0
    assert "3 runs (1 ran, 2 skipped as finished before, 0 failed), 1 planned" in (
        capsys.readouterr().out
    )
    assert {path: path.stat().st_mtime_ns for path in summaries} == summaries  # not rewritten
    document = json.loads((out / "sweep.json").read_text())
    assert document["counts"]["skipped"] == 2
    assert document["counts"]["planned"] == 1
    second = pd.read_csv(out / "sweep.csv")
    assert len(second) == 3
    pd.testing.assert_frame_equal(second.iloc[[0, 1]].reset_index(drop=True), first)
    # no file of the sweep names a path outside it (the tables' folders are relative)
    assert second["folder"].tolist() == [f"runs/{run_id}" for run_id in second["run_id"]]
    for path in (path for path in out.rglob("*") if path.is_file()):
        assert str(tmp_path).encode() not in path.read_bytes(), path


@pytest.mark.usefixtures("inprocess_cluster")
def test_seeds_do_not_replan_a_mission_file(
    tiny_mission: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    caplog: pytest.LogCaptureFixture,
) -> None:
    out = tmp_path / "sweep"
    vary = ("--vary", "weights.terrain=0,1", "--vary", "planner.edge_model=paper,crossed")
    assert _sweep(tiny_mission, out, *vary, "--seeds", "0..1") == 0
    assert "4 runs (4 ran, 0 skipped as finished before, 0 failed), 4 planned" in (
        capsys.readouterr().out
    )  # was 8 runs, 8 plans: one per mission and seed
    assert "--seeds 0..1 do not change a mission file's plan" in caplog.text
    assert "each of its 4 missions is planned once" in caplog.text
    table = pd.read_csv(out / "sweep.csv")
    assert len(table) == 4
    assert table["seed"].isna().all()
    assert not table["run_id"].str.contains("seed").any()
    assert len(list((out / "runs").iterdir())) == 4
    document = json.loads((out / "sweep.json").read_text())
    assert document["spec"]["seeds"] == [0, 1]
    assert document["counts"]["planned"] == 4


@pytest.mark.usefixtures("inprocess_cluster")
def test_failed_runs_are_rows_and_all_failed_exits_3(
    tiny_mission: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "sweep"
    vary = f"vehicle[0].start={GOOD_START},{LAND_START}"
    assert _sweep(tiny_mission, out, "-q", "--vary", vary) == 0
    table = pd.read_csv(out / "sweep.csv", keep_default_na=False)
    assert table.loc[0, "status"] == "PREPLANNED"
    assert table.loc[0, "reason"] == ""
    assert table.loc[1, "status"] in {"InputError", "InfeasibleError"}
    assert "blue" in table.loc[1, "reason"]
    assert table.loc[1, "folder"] == ""
    assert len(list((out / "runs").iterdir())) == 1

    out_bad = tmp_path / "all_bad"
    assert _sweep(tiny_mission, out_bad, "-q", "--vary", f"vehicle[0].start={LAND_START}") == 3
    assert "every run of the sweep failed" in capsys.readouterr().err
    assert len(pd.read_csv(out_bad / "sweep.csv")) == 1


@pytest.mark.parametrize(
    ("options", "fragment"),
    [
        (["--vary", "weights.terain=1"], "unknown key 'weights.terain'"),
        (["--vary", "weights.terrain=1,-1"], "--vary weights.terrain=-1: weights.terrain"),
        (["--vary", "weights.terrain=1", "--seeds", "2..1"], "--seeds"),
        ([], "nothing to sweep"),
        (["--vary", "weights.terrain=1", "--workers", "0"], "--workers must be at least 1"),
    ],
)
def test_user_errors_exit_2_with_one_line(
    tiny_mission: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    options: list[str],
    fragment: str,
) -> None:
    out = tmp_path / "sweep"
    assert _sweep(tiny_mission, out, *options) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1
    assert lines[0].startswith("auvplan: error: ")
    assert fragment in lines[0]
    assert not out.exists()


def test_scenarios_need_seeds(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert (
        main(["sweep", "scenarios", "-o", str(tmp_path / "s"), "--vary", "weights.terrain=1"]) == 2
    )
    assert "needs --seeds" in capsys.readouterr().err


def test_missing_dask_names_the_extra(
    tiny_mission: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import importlib.util

    find_spec = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util,
        "find_spec",
        lambda name, *a: None if name == "distributed" else find_spec(name, *a),
    )
    assert _sweep(tiny_mission, tmp_path / "s", "--vary", "weights.terrain=1") == 2
    assert "pip install 'auvplan[sweep]'" in capsys.readouterr().err


@pytest.mark.usefixtures("inprocess_cluster")
def test_scenario_family_seeds_are_missions(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "empty").mkdir()
    monkeypatch.setenv("AUVPLAN_SHARED_DATA", str(tmp_path / "empty"))  # no real grids
    out = tmp_path / "family"
    options = ["--seeds", "2,3", "--vary", "weights.terrain=0"]
    assert main(["-q", "sweep", "scenarios", "-o", str(out), "--stage", "preplan", *options]) == 0
    table = pd.read_csv(out / "sweep.csv")
    assert table["seed"].tolist() == [2, 3]
    assert (table["status"] == "PREPLANNED").all()
    assert json.loads((out / "sweep.json").read_text())["counts"]["planned"] == 2
    for seed, folder in zip(table["seed"], table["folder"], strict=True):
        mission = out / "scenarios" / f"seed_{seed:04d}" / "mission.toml"
        summary = json.loads((out / folder / "summary.json").read_text())
        assert summary["inputs"]["mission"]["path"] == "mission.toml"  # no folder
        assert summary["inputs"]["mission"]["sha256"] == file_sha256(mission)
    assert len({json.loads((out / f / "summary.json").read_text())["terrain"]["name"]
                for f in table["folder"]}) == 2  # fmt: skip
