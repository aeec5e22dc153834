"""Pipeline behaviour that needs no optimisation run: limits, failures, exit codes."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

from auvplan.cli.main import main
from auvplan.errors import InputError, SolverError
from auvplan.mission import pipeline
from auvplan.mission.config import parse_mission
from auvplan.mission.preplan import goal_keep_outs, turn_towards
from auvplan.scenarios import check

MISSION = """
[terrain]
synthetic = true
[fleet]
horizon_s = 100.0
safety_radius_m = 5.0
[[vehicle]]
name = "a"
start = { north = 10.0, east = 400.0, speed = 0.5 }
goal = { north = 60.0, east = 400.0 }
[solver]
dt_s = 1.0
"""


def test_start_speed_above_top_speed_names_the_key() -> None:
    config = parse_mission(tomllib.loads(MISSION.replace("speed = 0.5", "speed = 1.6")))
    with pytest.raises(InputError, match=r"vehicle\[0\]\.start\.speed = 1\.6 m/s exceeds"):
        pipeline.fleet_layout(config)


def test_optimiser_failure_writes_earlier_stages_and_exits_3(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    def fail(*_args: object, **_kwargs: object) -> None:
        raise SolverError("the projection of the initial guess diverged")

    monkeypatch.setattr(pipeline, "solve_pronto", fail)
    mission = tmp_path / "mission.toml"
    mission.write_text(MISSION)
    out = tmp_path / "out"
    assert main(["plan", str(mission), "-o", str(out), "--no-figures"]) == 3
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith("auvplan: plan FAILED: the optimiser failed")
    assert "solver.dt_s" in line
    summary = json.loads((out / "summary.json").read_text())
    assert summary["optimization"]["plan_status"] == "FAILED"
    assert (out / "desired.csv").is_file()
    assert not (out / "trajectories.csv").exists()


def test_summary_keeps_the_keys_users_read(tmp_path: Path) -> None:
    mission = tmp_path / "mission.toml"
    mission.write_text(MISSION + 'propeller_order = "full"\n')
    out = tmp_path / "out"
    assert main(["-q", "plan", str(mission), "-o", str(out), "--stage", "deconflict"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["fleet"]["deconfliction_method"] == summary["deconfliction"]["method"]
    assert summary["solver"]["dt"] == 1.0
    assert summary["solver"]["propeller_order"] is None  # "full", as before
    # what to install to rerun it elsewhere: Python and the numeric packages' versions
    from importlib import metadata

    assert summary["environment"]["packages"]["numpy"] == metadata.version("numpy")
    assert summary["environment"]["python"].count(".") == 2


def test_routes_keep_out_of_the_other_vehicles_goals() -> None:
    starts = np.array([[0.0, 0.0, 0.0], [0.0, 100.0, 0.0], [0.0, 50.0, 0.0]])
    goals = np.array([[100.0, 50.0, 0.0], [100.0, 0.0, 0.0], [100.0, 56.0, 0.0]])
    discs = goal_keep_outs(starts, goals, 1, clearance=5.0, cell=2.0)
    # the goals of vehicles 0 and 2 are kept out of, each by 2 r_c + a cell from the path
    assert [(d.north, d.east, d.radius) for d in discs] == [
        (100.0, 50.0, 7.0),
        (100.0, 56.0, 7.0),
    ]
    # vehicle 2's own goal is 6 m from vehicle 0's: that disc would cover it and is left out
    assert [(d.north, d.east) for d in goal_keep_outs(starts, goals, 2, 5.0, 2.0)] == [(100.0, 0.0)]


def _first_path(mission: str) -> np.ndarray:
    """Stage 1's smoothed path of the mission's first vehicle (north, east [m])."""
    return pipeline.run_preplan(parse_mission(tomllib.loads(mission))).paths[0]


def test_a_torpedo_path_leaves_along_its_start_heading() -> None:
    """The A* route leaves diagonally (37 deg); a REMUS 100 starting north (turning radius
    44 m) gets a path that leaves within 15 deg of north, a MEDUSA keeps the route's way."""
    mission = """
[terrain]
synthetic = true
[fleet]
horizon_s = 900.0
safety_radius_m = 5.0
[[vehicle]]
name = "t"
type = "TYPE"
start = { north = 10.0, east = 100.0, heading_deg = 0.0, speed = 0.5 }
goal = { north = 350.0, east = 500.0, heading_deg = 90.0 }
[solver]
dt_s = 1.0
"""

    def leaving_bearing(vehicle: str) -> float:
        path = _first_path(mission.replace("TYPE", vehicle))
        ahead = path[np.argmax(np.hypot(*(path - path[0]).T) > 15.0)] - path[0]
        return float(np.degrees(np.arctan2(ahead[1], ahead[0])))

    assert abs(leaving_bearing("remus100")) < 15.0
    assert leaving_bearing("medusa") > 30.0


def test_a_torpedo_turn_keeps_clear_of_another_start() -> None:
    """Torpedo ``a`` heads north with its route due east: its turn of 44 m would pass 4 m from
    ``b``'s start, where ``b`` is at t = 0 whatever the schedule; its path keeps 2 r_c away."""
    mission = """
[terrain]
synthetic = true
[fleet]
horizon_s = 1200.0
safety_radius_m = 5.0
[[vehicle]]
name = "a"
type = "remus100"
start = { north = 100.0, east = 100.0, heading_deg = 0.0, speed = 0.5 }
goal = { north = 100.0, east = 600.0, heading_deg = 90.0 }
[[vehicle]]
name = "b"
type = "remus100"
start = { north = 140.0, east = 144.0, heading_deg = 90.0, speed = 0.5 }
goal = { north = 300.0, east = 600.0, heading_deg = 90.0 }
[solver]
dt_s = 1.0
"""
    path = _first_path(mission)
    assert np.min(np.hypot(*(path - [140.0, 144.0]).T)) >= 10.0


def test_the_turn_towards_a_point_is_an_arc_that_ends_facing_it() -> None:
    """Seeded poses and targets all round, turning towards the target or the long way round
    (past 180 deg): the points lie on one circle of the radius, leave along the heading, are
    at most ``spacing`` apart, and the last one's heading (the arc's tangent) points at the
    target."""
    rng = np.random.default_rng(7)
    radius, spacing = 20.0, 1.5
    for case in range(400):
        the_long_way = case % 2 == 1
        start, heading = rng.uniform(-50.0, 50.0, 2), rng.uniform(-np.pi, np.pi)
        bearing, distance = rng.uniform(-np.pi, np.pi), rng.uniform(2.0, 6.0) * radius
        target = start + distance * np.array([np.cos(bearing), np.sin(bearing)])
        turn = turn_towards(start, heading, target, radius, spacing, the_long_way)
        assert turn is not None
        np.testing.assert_array_equal(turn[0], start)
        steps = np.diff(turn, axis=0)
        assert np.all(np.hypot(*steps.T) <= spacing + 1e-9)
        right = np.array([-np.sin(heading), np.cos(heading)])
        side = np.sign(right @ (target - start)) * (-1.0 if the_long_way else 1.0)
        centre = start + radius * side * right
        np.testing.assert_allclose(np.hypot(*(turn - centre).T), radius, rtol=1e-12)
        first = np.arctan2(steps[0, 1], steps[0, 0])  # chord bearing: half a step's turn off
        assert abs(np.angle(np.exp(1j * (first - heading)))) <= 0.5 * spacing / radius + 1e-9
        # the line on to the target is tangent at the end (perpendicular to the radius) and
        # goes on the way the arc turns
        radial, ahead = turn[-1] - centre, target - turn[-1]
        assert radial @ ahead / (radius * np.hypot(*ahead)) == pytest.approx(0.0, abs=1e-9)
        assert steps[-1] @ ahead > 0.0
    assert turn_towards(np.zeros(2), 0.0, np.array([0.0, 15.0]), 10.0, 1.0) is None  # inside


def test_a_torpedo_whose_route_leaves_behind_it_converges(tmp_path: Path) -> None:
    """A REMUS 100 (turning radius 44 m) heading north whose A* route over the Monterey
    sample leaves east-south-east: a Dubins turn into the route, not a loop the rudder
    cannot fly (before, the projection reversed the propeller and the optimiser stopped at
    MAX_ITER after 195 iterations); the plan passes the independent check."""
    mission = tmp_path / "torpedo.toml"
    mission.write_text(
        """
[terrain]
sample = "monterey"
window = { lat = [36.79360, 36.79714], lon = [-121.81473, -121.80582] }
[fleet]
horizon_s = 700.0
safety_radius_m = 5.0
[[vehicle]]
name = "torpedo1"
type = "remus100"
start = { north = 10.0, east = 350.0, heading_deg = 0.0, speed = 0.5 }
goal = { north = 370.0, east = 380.0, heading_deg = 0.0 }
[mission]
depth_m = 10.0
"""
    )
    out = tmp_path / "out"
    assert main(["-q", "plan", str(mission), "-o", str(out), "--no-figures"]) == 0
    optimization = json.loads((out / "summary.json").read_text())["optimization"]
    assert optimization["status"] == "CONVERGED"
    assert optimization["n_iter"] <= 50
    report = check(out, mission=mission)
    assert report.success, report.failures


def test_before_optimization_is_called_once_between_stages_2_and_3() -> None:
    """The explicit event a second process waits on (not a progress stage's name)."""
    from contextlib import contextmanager

    from auvplan.mission.config import load_mission
    from auvplan.mission.pipeline import Stage, run_mission

    events: list[str] = []

    @contextmanager
    def progress(name: str, *, total: int | None = None):  # type: ignore[no-untyped-def]
        del total
        events.append(f"start {name}")
        yield lambda label: None
        events.append(f"end {name}")

    golden = Path(__file__).parents[1] / "regression" / "golden_mission.toml"
    run_mission(
        load_mission(golden),
        stage=Stage.FULL,
        progress=progress,
        before_optimization=lambda: events.append("hook"),
    )
    assert events.count("hook") == 1
    hook = events.index("hook")
    assert events[hook - 1] == "end deconflict"
    assert events[hook + 1] == "start optimize"
