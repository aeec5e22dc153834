"""End to end: a navigation-aware plan beside a ridge navigates better for little energy.

The ``transit_mission`` of ``tests/conftest.py`` (a 1.5 km transit over a plain with a rough
ridge 160 m to one side) is planned with ``--compare-energy-only`` and both plans are
flown through the particle filter by ``auvplan evaluate``: the mission's plan must cut the TAN
RMSE by at least 30 % for at most 10 % more energy (issue 23), and the planner's predicted
error must be within 30 % of the simulated one.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import pytest

from auvplan.cli.main import main

TransitMission = Callable[..., Path]

pytestmark = pytest.mark.slow


def test_the_budget_plan_navigates_better_for_little_energy(
    tmp_path: Path, transit_mission: TransitMission
) -> None:
    mission = transit_mission(tmp_path, ridge=True)
    out = tmp_path / "out"
    assert main(["-q", "plan", str(mission), "-o", str(out), "--compare-energy-only",
                 "--no-figures"]) == 0  # fmt: skip
    assert main(["-q", "evaluate", str(out), "--runs", "20", "--particles", "2000",
                 "--no-figure"]) == 0  # fmt: skip
    document = json.loads((out / "navigation.json").read_text(encoding="utf-8"))
    comparison = document["comparison"]
    assert comparison["rmse_reduction"] >= 0.30
    assert comparison["energy_increase"] <= 0.10
    for plan in document["plans"].values():
        assert plan["predicted_rmse_m"] == pytest.approx(plan["rmse_m"], rel=0.3)
