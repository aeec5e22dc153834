"""The CLI's second process: figures identical to this process's, the first-run warm-up."""

from __future__ import annotations

import logging
import operator
from pathlib import Path

import pytest

import auvplan
from auvplan.api.companion import Companion, warm_marker
from auvplan.cli.main import main
from auvplan.viz.report import render_mission_figures


def test_figures_drawn_in_two_processes_are_those_of_one(
    mission_plan: auvplan.MissionPlan,
) -> None:
    result = mission_plan.result
    alone = render_mission_figures(result, figure_format="png", dpi=40)
    with Companion() as companion:
        shared = companion.render_figures(result, figure_format="png", dpi=40)
    assert list(shared) == list(alone)  # the report's order
    assert {stem: figure.data for stem, figure in shared.items()} == {
        stem: figure.data for stem, figure in alone.items()
    }


def test_warm_up_runs_once_per_machine_and_settings(
    mission_plan: auvplan.MissionPlan, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("AUVPLAN_CACHE_DIR", str(tmp_path))
    config = mission_plan.result.config
    marker = warm_marker(config)
    with Companion() as companion:
        assert companion.warm_up(config)
        companion.wait_for_warm_up()
    assert marker.is_file()
    with Companion() as companion:
        assert not companion.warm_up(config)  # marked: nothing to compile
    faster = config.solver.model_copy(update={"dt": config.solver.dt / 2})
    other = config.model_copy(update={"solver": faster})
    assert warm_marker(other) != marker  # other settings, other kernels


def test_a_failed_warm_up_is_logged_not_marked(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    with Companion() as companion:
        companion.start().submit(operator.truediv, 1, 0)  # a warm-up that raises there
        companion._warm_up = (tmp_path / "marker", 0.0)
        with caplog.at_level(logging.INFO, logger="auvplan.api.companion"):
            companion.wait_for_warm_up()
    assert not (tmp_path / "marker").exists()
    assert "kernel warm-up failed (division by zero)" in caplog.text


def test_plan_with_a_second_process_writes_the_whole_folder(
    mission_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    code = main(["-q", "plan", str(mission_file), "-o", str(out), "--jobs", "2", "--dpi", "40"])
    assert code == 0, capsys.readouterr().err
    alone = tmp_path / "alone"
    assert (
        main(["-q", "plan", str(mission_file), "-o", str(alone), "--jobs", "1", "--dpi", "40"]) == 0
    )
    figures = sorted(path.name for path in out.glob("*.png"))
    assert figures == sorted(path.name for path in alone.glob("*.png"))
    assert "time_series.png" in figures
    assert (out / "report.html").is_file()
    for name in figures:
        assert (out / name).read_bytes() == (alone / name).read_bytes(), name


@pytest.mark.parametrize("jobs", ["0", "3"])
def test_jobs_other_than_one_or_two_are_refused(
    mission_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], jobs: str
) -> None:
    out = tmp_path / "out"
    assert main(["plan", str(mission_file), "-o", str(out), "--jobs", jobs]) == 2
    assert f"--jobs (or $AUVPLAN_JOBS) must be 1 or 2, got {jobs}" in capsys.readouterr().err
    assert not out.exists()
