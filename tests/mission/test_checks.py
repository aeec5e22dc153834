"""The plan verdict: CONVERGED only when every constraint holds between samples."""

from __future__ import annotations

import tomllib
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from auvplan.mission.checks import ARRIVAL_TOLERANCE, BatteryUse, PlanStatus, judge_plan
from auvplan.mission.config import parse_mission
from auvplan.record.labels import Pair

MISSION = """
[terrain]
synthetic = true
[fleet]
horizon_s = 100.0
safety_radius_m = 5.0
[[vehicle]]
name = "a"
start = { north = 0.0, east = 0.0 }
goal = { north = 50.0, east = 0.0 }
[[vehicle]]
name = "b"
start = { north = 0.0, east = 30.0 }
goal = { north = 50.0, east = 30.0 }
[[obstacle]]
name = "rock"
center = { north = 25.0, east = 15.0 }
radius_m = 2.0
[[comm]]
pair = ["b", "a"]
max_range_m = 40.0
"""
TIME = np.linspace(0.0, 100.0, 1001)


def _result(success: bool = True) -> Any:
    return SimpleNamespace(
        success=success, status=SimpleNamespace(name="CONVERGED" if success else "MAX_ITER"),
        n_iter=7, message="",
    )  # fmt: skip


def _distances(**overrides: np.ndarray) -> dict[Pair, np.ndarray]:
    distances = {
        Pair("a", "b"): np.full(TIME.size, 30.0),
        Pair("a", "rock"): np.full(TIME.size, 12.0),
        Pair("b", "rock"): np.full(TIME.size, 12.0),
    }
    distances.update({Pair(*key.split("_")): value for key, value in overrides.items()})
    return distances


def _judge(distances: dict[Pair, np.ndarray], arrival: float = 0.1, success: bool = True) -> Any:
    config = parse_mission(tomllib.loads(MISSION))
    return judge_plan(
        config, ("a", "b"), _result(success), TIME, distances, np.array([arrival, 0.0])
    )


def test_clean_plan_converges() -> None:
    verdict = _judge(_distances())
    assert verdict.status is PlanStatus.CONVERGED
    assert verdict.success
    assert verdict.violations == ()


def test_dip_between_samples_is_a_named_separation_violation() -> None:
    dip = np.full(TIME.size, 30.0)
    dip[400] = 9.4  # one fine sample below 2 r_c = 10 m
    verdict = _judge(_distances(a_b=dip))
    assert verdict.status is PlanStatus.CONSTRAINT_VIOLATED
    (violation,) = verdict.violations
    assert (violation.kind, violation.who, violation.value) == ("separation", "a / b", 9.4)
    assert violation.time == TIME[400]
    assert "a / b" in verdict.message
    assert "fleet.horizon_s" in verdict.message
    assert "\n" not in verdict.message


def test_obstacle_clearance_and_comm_range_and_arrival() -> None:
    close = np.full(TIME.size, 12.0)
    close[10] = 4.0  # r_c = 5 m from the edge needed
    far = np.full(TIME.size, 30.0)
    far[-1] = 41.0  # max_range_m = 40
    verdict = _judge(_distances(b_rock=close, a_b=far), arrival=ARRIVAL_TOLERANCE + 1.0)
    kinds = {(v.kind, v.who) for v in verdict.violations}
    assert kinds == {
        ("obstacle clearance", "b / rock"),
        ("communication", "a / b"),
        ("arrival", "a"),
    }


def test_not_converged_wins_over_violations_and_names_them() -> None:
    dip = np.full(TIME.size, 30.0)
    dip[3] = 1.0
    verdict = _judge(_distances(a_b=dip), success=False)
    assert verdict.status is PlanStatus.NOT_CONVERGED
    assert "MAX_ITER" in verdict.message
    assert "separation" in verdict.message


def test_only_vehicles_of_known_capacity_are_checked_against_their_reserve() -> None:
    """None is never flagged; a capacity C when E > C (1 − f), f = reserve_fraction = 0.2."""
    config = parse_mission(tomllib.loads(MISSION))
    used = np.stack([1e9 * TIME, 10.0 * TIME])  # J drawn so far: b draws 10 W

    def judge(capacity: tuple[float | None, ...]) -> Any:
        return judge_plan(
            config, ("a", "b"), _result(), TIME, _distances(), np.zeros(2),
            battery=BatteryUse(TIME, used, capacity),
        )  # fmt: skip

    assert judge((None, 1250.0)).success  # b uses exactly C (1 - f) = 1000 J
    verdict = judge((None, 750.0))  # b may use 600 J, drawn after 60 s at 10 W
    assert verdict.status is PlanStatus.CONSTRAINT_VIOLATED
    (violation,) = verdict.violations
    assert (violation.kind, violation.who, violation.unit) == ("battery reserve", "b", "J")
    assert (violation.value, violation.limit) == (1000.0, 600.0)
    assert violation.time == TIME[np.argmax(used[1] > 600.0)] == pytest.approx(60.1)
    assert "b needs 1000.0 J, 400.0 J (0.11 Wh) more than the 600.0 J" in verdict.message
    assert "mission.reserve_fraction 0.2" in verdict.message
