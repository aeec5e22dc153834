"""Desired headings turn from the start heading and onto the goal heading at a flyable rate."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvplan.io.vehicles import load_vehicle
from auvplan.mission.timing import TURN_RATE_FRACTION, turn_in_and_out
from auvplan.vehicle import build_vehicle_model, minimum_useful_speed, turning_radius

TIME = np.arange(0.0, 1200.5, 0.5)


@pytest.fixture(scope="module")
def remus():  # type: ignore[no-untyped-def]
    return build_vehicle_model(load_vehicle("remus100"))


@settings(max_examples=40, deadline=None)
@given(
    start=st.floats(-3.0, 3.0),
    goal=st.floats(-3.0, 3.0),
    course=st.floats(-3.0, 3.0),
    speed=st.floats(0.3, 1.5),
)
def test_turns_start_at_the_start_end_at_the_goal_within_the_turn_rate(
    remus, start: float, goal: float, course: float, speed: float
) -> None:
    path = course + 0.2 * np.sin(TIME / 150.0)  # a gently curving path
    psi = turn_in_and_out(path, TIME, (start, goal), np.full(TIME.size, speed), remus)
    assert psi[0] == pytest.approx(start, abs=1e-12)
    assert np.cos(psi[-1] - goal) == pytest.approx(1.0, abs=1e-12)
    # away from the turns the path's heading is kept (modulo whole turns)
    middle = slice(TIME.size // 3 + 1, 2 * TIME.size // 3 - 1)
    np.testing.assert_allclose(np.cos(psi[middle] - path[middle]), 1.0, atol=1e-12)
    # the turns (on top of the path's own) are no faster than TURN_RATE_FRACTION of the steady
    # rate, or, when a turn is capped at a third of the horizon, than a half-cosine turn of π
    rate = TURN_RATE_FRACTION * max(speed, minimum_useful_speed(remus)) / turning_radius(remus)
    capped = 0.5 * np.pi * np.pi / (TIME[-1] / 3.0)
    turning = np.abs(np.diff(psi - path)) / np.diff(TIME)
    assert turning.max() <= max(rate, capped) * (1 + 1e-3)


def test_aligned_ends_leave_the_headings_alone(remus) -> None:  # type: ignore[no-untyped-def]
    path = 0.4 + 0.1 * np.cos(TIME / 90.0)
    psi = turn_in_and_out(path, TIME, (path[0], path[-1] + 2 * np.pi), np.ones(TIME.size), remus)
    np.testing.assert_allclose(psi, path, atol=1e-12)
