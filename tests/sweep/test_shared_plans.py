"""Runs of one mission that differ only in their seed are planned once (in-process workers)."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from auvplan.sweep import RunOptions, build_runs, mission_file_base, run_sweep
from auvplan.sweep.runner import run_folder
from auvplan.sweep.table import RUN_RECORD_FILE, read_run_folder

PREPLAN = RunOptions(stage="preplan", quiet_logs=False)
LAND_START = "{ north = 280.0, east = 20.0 }"

pytestmark = pytest.mark.usefixtures("inprocess_cluster")


@pytest.fixture
def plans_made(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The mission sources planned (each call of the pipeline, in the in-process workers)."""
    from auvplan.mission import pipeline

    made: list[str] = []
    original: Callable[..., Any] = pipeline.run_mission

    def counted(config: Any, *args: Any, **kwargs: Any) -> Any:
        made.append(str(config))
        return original(config, *args, **kwargs)

    monkeypatch.setattr(pipeline, "run_mission", counted)
    return made


def _runs(mission: Path, seeds: list[int | None], *options: str) -> tuple:
    base = mission_file_base(mission)
    return build_runs(list(options), seeds, lambda _seed: base, stage="preplan")[1]


def test_seeds_share_the_plan_of_their_mission(
    tiny_mission: Path, tmp_path: Path, plans_made: list[str]
) -> None:
    out = tmp_path / "sweep"
    runs = _runs(tiny_mission, [3, 4], "weights.terrain=0,1")
    records = run_sweep(runs, out, options=PREPLAN)
    assert len(plans_made) == 2  # 2 missions x 2 seeds: 2 plans
    assert [record.status for record in records] == ["PREPLANNED"] * 4
    assert [record.seed for record in records] == [3, 4, 3, 4]
    assert [record.plan_of for record in records] == [
        None, runs[0].run_id, None, runs[2].run_id,
    ]  # fmt: skip
    for planned, shared in [(records[0], records[1]), (records[2], records[3])]:
        assert planned.folder is not None
        assert shared.folder is not None
        assert shared.folder != planned.folder
        for name in ("summary.json", "maps.nc", "mission.toml"):
            assert (shared.folder / name).samefile(planned.folder / name)  # hard links
        document = json.loads((shared.folder / RUN_RECORD_FILE).read_text())
        assert document["seed"] == shared.seed
        assert document["plan_of"] == planned.run_id
        assert document["wall_s"] == planned.wall_s
    assert records[0].folder is not None
    assert records[2].folder is not None
    assert not (records[0].folder / "summary.json").samefile(records[2].folder / "summary.json")
    assert read_run_folder(records[1].folder, runs[1]) == records[1]  # resumes like a plan

    # a navigation.json of the planning run's seed is not carried to another seed's folder
    (records[0].folder / "navigation.json").write_text("{}")
    more = _runs(tiny_mission, [3, 4, 5], "weights.terrain=0,1")
    again = run_sweep(more, out, options=PREPLAN)
    assert len(plans_made) == 2  # seed 5 shares the finished plans
    assert [record.skipped for record in again] == [True, True, False] * 2
    assert again[2].plan_of == runs[0].run_id
    assert again[2].folder is not None
    assert not (again[2].folder / "navigation.json").exists()
    assert (again[2].folder / "summary.json").samefile(records[0].folder / "summary.json")


def test_a_plan_without_seed_serves_the_seeded_runs(
    tiny_mission: Path, tmp_path: Path, plans_made: list[str]
) -> None:
    out = tmp_path / "sweep"
    (unseeded,) = run_sweep(_runs(tiny_mission, [None], "weights.terrain=1"), out, options=PREPLAN)
    assert len(plans_made) == 1
    seeded = _runs(tiny_mission, [7], "weights.terrain=1")
    (record,) = run_sweep(seeded, out, options=PREPLAN)
    assert len(plans_made) == 1
    assert record.plan_of == unseeded.run_id == "weights.terrain=1.0"
    assert record.folder == run_folder(out.resolve(), seeded[0])
    assert (record.folder / "summary.json").samefile(
        out / "runs" / unseeded.run_id / "summary.json"
    )


def test_a_failed_plan_is_made_once_and_fails_every_seed(
    tiny_mission: Path, tmp_path: Path, plans_made: list[str]
) -> None:
    runs = _runs(tiny_mission, [1, 2, 3], f"vehicle[0].start={LAND_START}")
    records = run_sweep(runs, tmp_path / "sweep", options=PREPLAN)
    assert len(plans_made) == 1
    assert all(record.failed and record.folder is None for record in records)
    assert len({(record.status, record.reason) for record in records}) == 1
    assert "blue" in records[0].reason
    assert [record.plan_of for record in records] == [None, runs[0].run_id, runs[0].run_id]
    runs_folder = tmp_path / "sweep" / "runs"
    assert not runs_folder.exists() or not any(runs_folder.iterdir())
