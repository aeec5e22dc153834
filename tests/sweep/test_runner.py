"""One run in this process: its folder, its record read back, failures as records."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from auvplan.errors import DataFormatError
from auvplan.sweep import (
    RunOptions,
    add_run_columns,
    build_runs,
    mission_file_base,
    navigation_columns,
    sweep_frame,
)
from auvplan.sweep.runner import execute_run
from auvplan.sweep.table import RUN_RECORD_FILE, read_run_folder

PREPLAN = RunOptions(stage="preplan", quiet_logs=False)


def _runs(mission: Path, *options: str, stage: str = "preplan") -> tuple:
    base = mission_file_base(mission)
    return build_runs(list(options), [None], lambda _seed: base, stage=stage)[1]


def test_run_writes_its_folder_and_reads_back(tiny_mission: Path, tmp_path: Path) -> None:
    run, other = _runs(tiny_mission, "planner.edge_model=paper,crossed")
    folder = tmp_path / "runs" / run.run_id
    record = execute_run(run, folder, PREPLAN)
    assert record.status == "PREPLANNED"
    assert not record.failed
    assert record.reason == ""
    assert record.folder == folder
    assert record.wall_s is not None
    assert record.wall_s > 0
    assert {"summary.json", "mission.toml", "maps.nc", RUN_RECORD_FILE} <= {
        path.name for path in folder.iterdir()
    }
    assert "crossed" not in (folder / "mission.toml").read_text()
    assert read_run_folder(folder, run) == record
    assert read_run_folder(folder, other) is None  # another run's digest: not finished
    full = _runs(tiny_mission, "planner.edge_model=paper", stage="full")[0]
    assert full.run_id == run.run_id
    assert read_run_folder(folder, full) is None
    (folder / "summary.json").unlink()
    assert read_run_folder(folder, run) is None


def test_failed_run_is_a_record_and_writes_nothing(tiny_mission: Path, tmp_path: Path) -> None:
    (run,) = _runs(tiny_mission, "vehicle[0].start.north=280.0", "vehicle[0].start.east=20.0")
    folder = tmp_path / "runs" / run.run_id
    record = execute_run(run, folder, PREPLAN)  # the start is on land
    assert record.failed
    assert record.folder is None
    assert record.status in {"InputError", "InfeasibleError"}
    assert "blue" in record.reason
    assert "\n" not in record.reason
    assert not (tmp_path / "runs").exists() or not any((tmp_path / "runs").iterdir())


def test_unexpected_exception_is_a_bug_record(
    tiny_mission: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from auvplan.mission import pipeline

    def broken(*args: object, **kwargs: object) -> None:
        raise ZeroDivisionError("boom")

    monkeypatch.setattr(pipeline, "run_mission", broken)
    (run,) = _runs(tiny_mission, "weights.terrain=1")
    record = execute_run(run, tmp_path / "runs" / run.run_id, PREPLAN)
    assert record.status == "ZeroDivisionError"
    assert record.reason.startswith("boom (unexpected at test_runner.py:")


def test_table_columns_and_navigation_hook(tiny_mission: Path, tmp_path: Path) -> None:
    runs = _runs(tiny_mission, "weights.terrain=0,2")
    records = [execute_run(run, tmp_path / "runs" / run.run_id, PREPLAN) for run in runs]
    frame = sweep_frame(records, ["weights.terrain"])
    assert list(frame.columns) == [
        "run_id", "weights.terrain", "seed", "status", "reason", "energy_J",
        "terrain_information", "n_iter", "wall_s", "peak_rss_mb", "tan_rmse_m", "folder",
    ]  # fmt: skip
    assert frame["weights.terrain"].tolist() == [0.0, 2.0]
    assert frame["tan_rmse_m"].isna().all()
    navigation = {"plans": {"terrain_aware": {"rmse_m": 7.5}}}
    (records[1].folder / "navigation.json").write_text(json.dumps(navigation))
    filled = add_run_columns(frame, navigation_columns)
    assert filled["tan_rmse_m"].isna().tolist() == [True, False]
    assert filled.loc[1, "tan_rmse_m"] == 7.5
    (records[0].folder / "navigation.json").write_text('{"plans": {}}')
    with pytest.raises(DataFormatError, match=r"plans\.terrain_aware\.rmse_m"):
        add_run_columns(frame, navigation_columns)
