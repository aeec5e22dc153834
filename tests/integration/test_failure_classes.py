"""Regression tests for the stage-3 failure classes of issue 11 (slow).

Each mission failed before: the projection of the initial guess diverged at ``dt_s`` = 1 s
(rendezvous layouts where vehicles wait for each other), or PRONTO spent its iteration budget
repairing a guess projected by a regulator designed at rest (four vehicles crossing). Each
must now give a CONVERGED plan that passes the independent checks.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from auvplan.cli.main import main
from auvplan.scenarios import check, generate

MISSIONS = Path(__file__).parent / "missions"


def _plan_and_check(mission: Path, out: Path) -> None:
    assert main(["-q", "plan", str(mission), "-o", str(out), "--no-figures"]) == 0
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert summary["optimization"]["plan_status"] == "CONVERGED"
    report = check(out, mission=mission)
    assert report.success, report.failures


@pytest.mark.slow
def test_four_vehicles_crossing_on_a_ring(tmp_path: Path) -> None:
    _plan_and_check(MISSIONS / "ring_crossing.toml", tmp_path / "out")


@pytest.mark.slow
def test_rendezvous_with_waits_at_one_second_interval(tmp_path: Path) -> None:
    # seed 36: four vehicles meeting on a synthetic bank, 1010 s at dt_s = 1 s (no real data)
    scenario = generate(36, data_dir=tmp_path / "no_grids")
    assert scenario.mission["solver"]["dt_s"] == 1.0
    mission = scenario.write(tmp_path / "scenario")
    _plan_and_check(mission, tmp_path / "out")
