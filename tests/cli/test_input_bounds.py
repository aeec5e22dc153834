"""Issue 28: every number of the command line is bounded, sizes are checked before allocation.

Each case runs the command line (in-process, or as a process with a timeout where the old
code hung) and checks the contract: exit code 2, exactly one stderr line
``auvplan: error: ...`` naming the flag or key and its limit, nothing left on disk, in
bounded time.
"""

from __future__ import annotations

import time
from importlib import resources
from pathlib import Path

import pytest

from ._cli import run_cli

DEMO = resources.files("auvplan").joinpath("data", "missions", "demo.toml").read_text()


def _wide_fleet_mission(n_vehicles: int, dt_s: float) -> str:
    """The demo's bank and horizon with ``n_vehicles`` side by side, northbound, paper routes."""
    head = DEMO.split("[[vehicle]]")[0].replace("safety_radius_m = 5.0", "safety_radius_m = 2.0")
    vehicles = "".join(
        f'[[vehicle]]\nname = "v{i}"\ntype = "medusa"\n'
        f"start = {{ north = 10.0, east = {300.0 + 8.0 * i}, heading_deg = 0.0, speed = 0.5 }}\n"
        f"goal = {{ north = 380.0, east = {300.0 + 8.0 * i}, heading_deg = 0.0 }}\n"
        for i in range(n_vehicles)
    )
    return f'{head}{vehicles}[planner]\nedge_model = "paper"\n[solver]\ndt_s = {dt_s}\n'


def test_memory_budget_applies_only_to_the_stage_that_optimises(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """8 vehicles x 30000 steps: ~25 GiB for the optimiser, nothing for stages 1 and 2."""
    mission = tmp_path / "fleet.toml"
    mission.write_text(_wide_fleet_mission(8, 0.02), encoding="utf-8")
    out = tmp_path / "deconflict"
    started = time.perf_counter()
    code, _, err = run_cli(
        ["-q", "plan", str(mission), "-o", str(out), "--stage", "deconflict", "--jobs", "1",
         "--no-figures"],
        capsys,
    )  # fmt: skip
    assert code == 0, err
    assert (out / "desired.csv").is_file()
    full = tmp_path / "full"
    code, _, err = run_cli(
        ["-q", "plan", str(mission), "-o", str(full), "--jobs", "1", "--no-figures"], capsys
    )
    assert code == 2
    assert "GiB (budget 16 GiB)" in err.strip().splitlines()[-1]
    assert not full.exists()
    assert time.perf_counter() - started < 120.0
