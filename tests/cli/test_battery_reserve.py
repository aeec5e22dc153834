"""The energy reserve: a plan may use ``battery_capacity × (1 − reserve_fraction)`` per vehicle."""

from __future__ import annotations

import csv
import json
import re
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from _cli import one_error_line, run_cli
from scipy.integrate import cumulative_trapezoid

from auvplan.cli.main import main
from auvplan.io.vehicles import load_vehicle
from auvplan.mission.checks import PlanStatus

#: The smallest full mission of the suite (tests/mission/test_pipeline.py): 50 m in 100 s.
MISSION = """
[terrain]
synthetic = true
[fleet]
horizon_s = 100.0
safety_radius_m = 5.0
[[vehicle]]
name = "a"
type = "boat.toml"
start = {{ north = 10.0, east = 400.0, speed = 0.5 }}
goal = {{ north = 60.0, east = 400.0 }}
[solver]
dt_s = 1.0
[mission]
{mission}
"""


def _write_mission(folder: Path, battery: str, mission: str = "") -> Path:
    """A MEDUSA whose ``[power]`` table gives ``battery_capacity = battery``, and its mission."""
    folder.mkdir(parents=True, exist_ok=True)
    medusa = resources.files("auvplan").joinpath("data/vehicles/medusa.toml").read_text("utf-8")
    hotel = next(line for line in medusa.splitlines() if line.startswith("hotel "))
    boat = medusa.replace(hotel, f"{hotel}\nbattery_capacity = {battery}")
    (folder / "boat.toml").write_text(boat, encoding="utf-8")
    path = folder / "mission.toml"
    path.write_text(MISSION.format(mission=mission), encoding="utf-8")
    return path


def _summary(out: Path) -> dict[str, Any]:
    document: dict[str, Any] = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    return document


@pytest.fixture(scope="module")
def ample(tmp_path_factory: pytest.TempPathFactory) -> tuple[int, Path]:
    """The mission planned with a 1 kWh battery and the default reserve: (exit code, folder)."""
    folder = tmp_path_factory.mktemp("ample")
    mission = _write_mission(folder, '{ value = 1.0, unit = "kWh" }')
    out = folder / "out"
    return main(["-q", "plan", str(mission), "-o", str(out), "--no-figures"]), out


def test_a_sufficient_battery_passes_and_reports_what_is_left(ample: tuple[int, Path]) -> None:
    code, out = ample
    assert code == 0
    summary = _summary(out)
    capacity = summary["vehicles"][0]["battery_capacity_J"]
    assert capacity == pytest.approx(3.6e6, rel=1e-12)  # 1 kWh in J
    plan = summary["optimization"]
    assert plan["plan_status"] == "CONVERGED"
    assert plan["violations"] == []
    vehicle = plan["vehicles"]["a"]
    energy = vehicle["energy_J"]
    assert 0.0 < energy < 0.8 * capacity
    assert vehicle["energy_remaining_J"] == pytest.approx(capacity - energy, rel=1e-12)
    assert vehicle["energy_remaining_fraction"] == pytest.approx(1.0 - energy / capacity)
    report = (out / "report.html").read_text(encoding="utf-8")
    assert "battery [kJ]" in report
    assert f"{capacity / 1e3:.2f}" in report
    assert f"{(capacity - energy) / 1e3:.2f}" in report


def test_a_breached_reserve_exits_3_naming_the_vehicle_and_its_deficit(
    ample: tuple[int, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A battery of 1.5 × the plan's energy holds it, but not with half of it kept in reserve."""
    energy = _summary(ample[1])["optimization"]["vehicles"]["a"]["energy_J"]
    capacity = 1.5 * energy
    mission = _write_mission(
        tmp_path, f'{{ value = {capacity!r}, unit = "J" }}', "reserve_fraction = 0.5"
    )
    out = tmp_path / "out"
    code, _, err = run_cli(["-q", "plan", str(mission), "-o", str(out), "--no-figures"], capsys)
    assert code == 3
    (line,) = err.strip().splitlines()
    assert line.startswith("auvplan: plan CONSTRAINT_VIOLATED: battery reserve: a needs ")
    for change in ("fleet.horizon_s", "mission.reserve_fraction", "battery_capacity"):
        assert change in line
    found = re.search(r", ([\d.]+) J \(([\d.]+) Wh\) more than", line)
    assert found is not None, line
    deficit_j, deficit_wh = float(found[1]), float(found[2])

    summary = _summary(out)  # the plan is written, with its verdict
    plan = summary["optimization"]
    assert plan["plan_status"] == PlanStatus.CONSTRAINT_VIOLATED.name
    used = plan["vehicles"]["a"]["energy_J"]
    assert deficit_j == pytest.approx(used - capacity * (1.0 - 0.5), abs=0.05)
    assert deficit_wh == pytest.approx(deficit_j / 3600.0, abs=0.005)
    assert plan["vehicles"]["a"]["energy_remaining_J"] == pytest.approx(capacity - used)
    (violation,) = plan["violations"]
    assert (violation["kind"], violation["who"], violation["unit"]) == ("battery reserve", "a", "J")
    assert violation["value"] == used
    assert violation["limit"] == pytest.approx(0.5 * capacity, rel=1e-12)
    # the reserve is reached at the first sample whose energy drawn so far exceeds the limit
    with (out / "trajectories.csv").open(encoding="utf-8") as rows:
        table = [(float(row["t"]), float(row["power"])) for row in csv.DictReader(rows)]
    t, power = np.array(table).T
    drawn = cumulative_trapezoid(power, t, initial=0.0)
    assert drawn[-1] == pytest.approx(used, rel=1e-6)
    assert violation["time"] == pytest.approx(t[np.argmax(drawn > violation["limit"])], abs=1.0)


@pytest.mark.parametrize(
    ("battery", "mission", "key"),
    [
        ('{ value = -1.0, unit = "kWh" }', "", "power.battery_capacity"),
        ('{ value = 0.0, unit = "J" }', "", "power.battery_capacity"),
        ('{ value = 1.0, unit = "Ah" }', "", "power.battery_capacity"),
        ('{ value = 1.0, unit = "kWh" }', "reserve_fraction = 1.0", "mission.reserve_fraction"),
        ('{ value = 1.0, unit = "kWh" }', "reserve_fraction = -0.1", "mission.reserve_fraction"),
    ],
)
def test_bad_capacity_or_reserve_exits_2_naming_the_key(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], battery: str, mission: str, key: str
) -> None:
    path = _write_mission(tmp_path, battery, mission)
    out = tmp_path / "out"
    code, _, err = run_cli(["-q", "plan", str(path), "-o", str(out)], capsys)
    assert code == 2
    assert key in one_error_line(err)
    assert not out.exists()


def test_packaged_types_give_no_capacity_without_a_published_figure() -> None:
    """No shared reference gives MEDUSA's or the REMUS 100's battery energy: none is made up."""
    assert load_vehicle("medusa").battery_capacity is None
    assert load_vehicle("remus100").battery_capacity is None
