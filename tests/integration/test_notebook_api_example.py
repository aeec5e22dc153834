"""``examples/notebook_api.py`` runs top to bottom (fast suite: CI keeps the example working)."""

from __future__ import annotations

import runpy
from pathlib import Path

import pytest

import auvplan

EXAMPLE = Path(__file__).parents[2] / "examples" / "notebook_api.py"


def test_notebook_api_example_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    namespace = runpy.run_path(str(EXAMPLE), run_name="__main__")
    plan = namespace["plan"]
    assert isinstance(plan, auvplan.MissionPlan)
    assert plan.status == "CONVERGED"
    assert (tmp_path / "out" / "notebook_api_paths.png").is_file()
    assert (tmp_path / "out" / "notebook_api" / "report.html").is_file()
    svg = {path.stem for path in (tmp_path / "out" / "notebook_api").glob("*.svg")}
    assert svg == {
        "maps", "paths", "paths_cost", "coordination", "time_series", "separation",
        "navigation_predicted",
    }  # fmt: skip
