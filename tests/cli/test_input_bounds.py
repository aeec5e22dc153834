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
from _cli import one_error_line, run_cli, run_cli_process

DEMO = resources.files("auvplan").joinpath("data", "missions", "demo.toml").read_text()


def _tree(root: Path) -> dict[str, bytes | None]:
    """Every entry below ``root``: relative path -> file content (None for folders)."""
    return {
        str(path.relative_to(root)): path.read_bytes() if path.is_file() else None
        for path in sorted(root.rglob("*"))
    }


@pytest.fixture(scope="module")
def plan_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A real output folder of ``auvplan plan``: one MEDUSA for 300 s on the synthetic bank."""
    root = tmp_path_factory.mktemp("plan")
    head = DEMO.split("[[vehicle]]")[0].replace("horizon_s = 600.0", "horizon_s = 300.0")
    mission = root / "one.toml"
    mission.write_text(
        f'{head}[[vehicle]]\nname = "blue"\ntype = "medusa"\n'
        "start = { north = 10.0, east = 400.0, heading_deg = 0.0, speed = 0.5 }\n"
        "goal = { north = 150.0, east = 420.0, heading_deg = 0.0 }\n"
        '[planner]\nedge_model = "paper"\n[solver]\ndt_s = 2.0\n',
        encoding="utf-8",
    )
    folder = root / "out"
    command = ["-q", "plan", str(mission), "-o", str(folder), "--jobs", "1", "--no-figures"]
    assert run_cli_process(command, timeout=300)[0] == 0
    return folder


@pytest.mark.parametrize(
    ("flags", "fragment"),
    [
        (["--seed", "-1"], "--seed must be a non-negative integer, got -1"),
        (["--particles", "20000000000"], "at most 1000000 (--particles), got 20000000000"),
        (["--particles", "2e10"], "--particles: invalid int value: '2e10'"),
        (["--runs", "1e8"], "--runs: invalid int value: '1e8'"),
        (["--drift", "1e10"], "navigation.drift_percent: Input should be less than or equal to 20"),
        (["--initial-sigma", "1e300"], "navigation.initial_sigma_m: Input should be less than"),
        (["--convergence-updates", "10" * 10], "<= 1728000 (the most updates of a run)"),
    ],
)
def test_evaluate_numbers_out_of_bounds_are_one_line(
    plan_folder: Path, capsys: pytest.CaptureFixture[str], flags: list[str], fragment: str
) -> None:
    """Each flag is bounded, and the work and memory of the runs are checked before any run."""
    before = _tree(plan_folder.parent)
    started = time.perf_counter()
    code, out, err = run_cli(["evaluate", str(plan_folder), "--no-figure", *flags], capsys)
    assert time.perf_counter() - started < 30.0
    assert code == 2
    assert out == ""
    assert fragment in one_error_line(err.replace("auvplan evaluate: error:", "auvplan: error:"))
    assert _tree(plan_folder.parent) == before


@pytest.mark.parametrize(
    ("flags", "fragment"),
    [
        (["--runs", "100000000"], "--runs must be >= 1 and <= 100000, got 100000000"),
        (["--update-period", "1e-4"], "navigation.update_period_s: Input should be greater"),
        (["--runs", "100000", "--particles", "1000000"], "more than the limit 1e+11"),
        (
            ["--runs", "100000", "--particles", "2", "--update-period", "0.1"],
            "GiB of results, more than the limit 4 GiB",
        ),
    ],
)
def test_evaluate_refuses_what_used_to_hang_in_bounded_time(
    plan_folder: Path, flags: list[str], fragment: str
) -> None:
    """Runs x particles x updates per run are checked from the bounds before any run."""
    before = _tree(plan_folder.parent)
    code, err = run_cli_process(["evaluate", str(plan_folder), "--no-figure", *flags], timeout=60)
    assert code == 2
    assert fragment in one_error_line(err)
    assert _tree(plan_folder.parent) == before


def _wide_fleet_mission(n_vehicles: int, dt_s: float) -> str:
    """The demo's bank and horizon with ``n_vehicles`` side by side, northbound, paper routes."""
    head = DEMO.split("[[vehicle]]")[0].replace("safety_radius_m = 5.0", "safety_radius_m = 2.0")
    vehicles = "".join(
        f'[[vehicle]]\nname = "v{i}"\ntype = "medusa"\n'
        f"start = {{ north = 10.0, east = {300.0 + 8.0 * i}, heading_deg = 0.0, speed = 0.5 }}\n"
        f"goal = {{ north = 380.0, east = {300.0 + 8.0 * i}, heading_deg = 0.0 }}\n"
        for i in range(n_vehicles)
    )
    return (
        f'{head}{vehicles}[planner]\nedge_model = "paper"\n[solver]\ndt_s = {dt_s}\n'
        'fleet = "coupled"\n'  # the decomposed solve needs one vehicle's memory at a time
    )


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
