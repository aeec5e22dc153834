"""A plan read from its folder is replanned on the stage 2 of its own run (issue 27).

The golden mission's plan is saved, read back and its parent (:func:`parent_from_record`)
compared with the one of the run in memory: the coordination problem, the schedule (time
grid, progress, speeds, certificate) and the desired states must be the same floats, whether
the schedule is read from ``summary.json`` or, for a folder written before the time laws had
their speeds, planned again.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import auvplan
from auvplan.api.result import MissionPlan
from auvplan.errors import DataFormatError
from auvplan.mission.parent import ParentPlan, parent_from_record, record_mission
from auvplan.mission.timing import DeconflictStage


@pytest.fixture(scope="module")
def saved(golden_solved: tuple[Any, Any, Any], tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The golden plan's output folder, without figures (read only)."""
    folder = tmp_path_factory.mktemp("replan_folder") / "parent"
    MissionPlan.from_result(golden_solved[1]).save(folder, figures=False)
    return folder


def _copy_with_laws(saved: Path, target: Path, edit: Any) -> Path:
    """``saved`` copied to ``target`` with ``edit(time_law)`` applied to every time law."""
    target.mkdir()
    for path in saved.iterdir():
        (target / path.name).write_bytes(path.read_bytes())
    summary = json.loads((saved / "summary.json").read_text())
    for vehicle in summary["vehicles"]:
        edit(vehicle["timing"]["time_law"])
    (target / "summary.json").write_text(json.dumps(summary))
    return target


def _parent(folder: Path) -> ParentPlan:
    record = auvplan.load(folder).record
    config = record_mission(record, folder=str(folder))
    return parent_from_record(record, config, folder=str(folder))


def _assert_same(mine: Any, theirs: Any, where: str) -> None:
    """Every field of two dataclasses equal: arrays element for element (NaN equal to NaN)."""
    for field in dataclasses.fields(mine):
        a, b = getattr(mine, field.name), getattr(theirs, field.name)
        if dataclasses.is_dataclass(a):
            _assert_same(a, b, f"{where}.{field.name}")
        elif isinstance(a, tuple) and a and isinstance(a[0], np.ndarray):
            for x, y in zip(a, b, strict=True):
                np.testing.assert_array_equal(x, y, err_msg=f"{where}.{field.name}")
        elif isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
            np.testing.assert_array_equal(a, b, err_msg=f"{where}.{field.name}")
        elif isinstance(a, float) and np.isnan(a):
            assert np.isnan(b), f"{where}.{field.name}"
        else:
            assert a == b, f"{where}.{field.name}: {a!r} != {b!r}"


def _assert_same_stage(mine: DeconflictStage, theirs: DeconflictStage) -> None:
    assert mine.horizon == theirs.horizon
    assert mine.dt == theirs.dt
    np.testing.assert_array_equal(mine.cruise_speeds, theirs.cruise_speeds)
    np.testing.assert_array_equal(mine.time, theirs.time)
    _assert_same(mine.problem, theirs.problem, "problem")
    for name in ("min_speeds", "max_accelerations", "path_lengths"):
        np.testing.assert_array_equal(getattr(mine.problem, name), getattr(theirs.problem, name))
    _assert_same(mine.coordination, theirs.coordination, "coordination")
    for x, y in zip(mine.desired_states, theirs.desired_states, strict=True):
        np.testing.assert_array_equal(x, y)


def test_the_schedule_read_from_the_folder_is_the_runs(
    golden_solved: tuple[Any, Any, Any], saved: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    stage2 = golden_solved[1].deconfliction
    assert stage2.coordination.speeds is not None  # smooth laws: their speeds matter
    assert not np.all(np.isnan(stage2.coordination.speeds))

    def planned_again(*_: Any, **__: Any) -> None:
        raise AssertionError("stage 2 planned again although the folder holds it")

    monkeypatch.setattr("auvplan.mission.parent.run_deconfliction", planned_again)
    _assert_same_stage(_parent(saved).deconfliction, stage2)


def test_a_folder_without_the_laws_speeds_has_its_stage_2_planned_again(
    golden_solved: tuple[Any, Any, Any], saved: Path, tmp_path: Path
) -> None:
    older = _copy_with_laws(saved, tmp_path / "older", lambda law: law.pop("speed_m_s"))
    _assert_same_stage(_parent(older).deconfliction, golden_solved[1].deconfliction)


def test_time_laws_that_do_not_end_on_the_paths_are_refused(saved: Path, tmp_path: Path) -> None:
    def shorten(law: dict[str, Any]) -> None:
        law["progress_m"][-1] -= 1.0

    edited = _copy_with_laws(saved, tmp_path / "edited", shorten)
    with pytest.raises(DataFormatError, match="its time laws are not those of the paths"):
        _parent(edited)
