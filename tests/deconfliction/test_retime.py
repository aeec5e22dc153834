"""Flyable retimed laws: certified, monotone, common arrival, speed and acceleration bounds."""

from __future__ import annotations

import logging

import numpy as np
import pytest
from _deconfliction_oracles import dense_min_separation, law_at
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from auvplan.deconfliction import (
    CoordinationProblem,
    CoordinationResult,
    deconflict,
    retime_for_arrival,
)
from auvplan.deconfliction.schedule import progress_at
from auvplan.errors import InfeasibleError


def stopped_time(result: CoordinationResult, vehicle: int, *, grid: bool) -> float:
    """Time [s] the vehicle stands still before its arrival."""
    s = result.progress[vehicle]
    dt = np.diff(result.time)
    if grid:
        still = np.diff(s) <= 0.0
    else:
        assert result.speeds is not None
        v = result.speeds[vehicle]
        still = (v[:-1] < 1e-6) & (v[1:] < 1e-6)
    before = s[1:] < s[-1] * (1.0 - 1e-9)
    return float(np.sum(dt[still & before]))


def check_flyable(
    problem: CoordinationProblem, base: CoordinationResult, final_time: float
) -> CoordinationResult:
    result = retime_for_arrival(base, problem, final_time)
    assert result.certificate.holds
    assert dense_min_separation(problem, result, 4) >= problem.separation - 1e-9
    assert np.all(result.arrival_times <= final_time + 1e-9)
    np.testing.assert_array_equal(result.progress[:, -1], problem.path_lengths)
    assert np.all(np.diff(result.progress, axis=1) >= 0.0)
    assert result.speeds is not None
    assert problem.max_accelerations is not None
    top = problem.cruise_speeds * base.makespan / final_time
    dt = np.diff(result.time)
    for i in range(problem.n_vehicles):
        v = result.speeds[i]
        if np.isnan(v[0]):  # kept its replayed law (may arrive early): at most its speed
            assert np.all(np.diff(result.progress[i]) / dt <= top[i] * (1 + 1e-9))
            assert not result.within_limits[i]
            assert "keep their replayed law" in result.message
            continue
        assert result.arrival_times[i] == pytest.approx(final_time)
        assert np.all(v >= 0.0)
        assert np.all(v <= top[i] * (1 + 1e-9))
        # the progress is the trapezoidal integral of the speed (continuous s')
        np.testing.assert_allclose(
            np.diff(result.progress[i]), 0.5 * dt * (v[:-1] + v[1:]), atol=1e-9
        )
        if result.within_limits[i]:
            assert np.all(np.abs(np.diff(v)) / dt <= problem.max_accelerations[i] * (1 + 1e-6))
    return result


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**32 - 1),
    stretch=st.floats(1.0, 1.6),
    acceleration=st.floats(0.02, 2.0),
    floor=st.floats(0.0, 0.8),
)
def test_retimed_laws_are_flyable_and_certified(
    seed: int, stretch: float, acceleration: float, floor: float
) -> None:
    rng = np.random.default_rng(seed)
    n_vehicles = int(rng.integers(2, 4))
    paths = tuple(
        np.cumsum(np.vstack([rng.uniform(0, 20, 2), rng.uniform(-8, 8, size=(2, 2))]), axis=0)
        for _ in range(n_vehicles)
    )
    speeds = rng.uniform(0.5, 1.5, n_vehicles)
    problem = CoordinationProblem(
        paths,
        1.0,
        speeds,
        0.5,
        min_speeds=floor * speeds,
        max_accelerations=np.full(n_vehicles, acceleration),
    )
    try:
        base = deconflict(problem)
    except InfeasibleError:
        return
    check_flyable(problem, base, base.makespan * stretch)


def test_waits_become_slow_downs_within_the_bounds() -> None:
    # two crossings where the yielding vehicle stops dead on the grid: retimed, nobody stops,
    # every law keeps 0.3 m/s and 0.1 m/s^2
    paths = (
        np.array([[-20.0, 0.0], [20.0, 0.0]]),
        np.array([[0.0, -19.0], [0.0, 21.0]]),
    )
    problem = CoordinationProblem(
        paths, 2.5, np.ones(2), 0.5, min_speeds=np.full(2, 0.3), max_accelerations=np.full(2, 0.1)
    )
    base = deconflict(problem)
    assert max(stopped_time(base, i, grid=True) for i in range(2)) > 3.0
    result = check_flyable(problem, base, 1.1 * base.makespan)
    assert result.within_limits == (True, True)
    assert result.speeds is not None
    assert np.all(result.speeds >= 0.3 - 1e-9)
    assert max(stopped_time(result, i, grid=False) for i in range(2)) == 0.0


def test_retimed_law_between_samples_is_the_integrated_speed() -> None:
    paths = (np.array([[-20.0, 0.0], [20.0, 0.0]]), np.array([[0.0, -19.0], [0.0, 21.0]]))
    problem = CoordinationProblem(paths, 2.5, np.ones(2), 0.5, max_accelerations=np.full(2, 0.1))
    result = retime_for_arrival(deconflict(problem), problem, 60.0)
    middle = 0.5 * (result.time[:-1] + result.time[1:])
    for i in range(2):
        expected = [law_at(result, i, float(t)) for t in middle]
        np.testing.assert_allclose(progress_at(result, i, middle), expected, atol=1e-12)


def test_coarse_resampling_falls_back_to_the_certified_replay(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    from auvplan.deconfliction import retime

    problem = CoordinationProblem(
        (np.array([[-30.0, 0.0], [30.0, 0.0]]), np.array([[0.0, -30.0], [0.0, 30.0]])),
        safety_radius=2.0,
        cruise_speeds=np.ones(2),
        time_step=0.5,
    )
    schedule = deconflict(problem)
    monkeypatch.setattr(retime, "MAX_SAMPLES", 5)  # a grid too coarse to certify the crossing
    with caplog.at_level(logging.DEBUG, logger="auvplan"):
        result = retime_for_arrival(schedule, problem, 80.0)
    # a degradation the run reports in its result (summary.json), not on the console
    assert "the schedule is replayed at a common pace" in result.message
    assert "not certified on the resampled grid" in result.message
    assert max(record.levelno for record in caplog.records) == logging.DEBUG
    assert result.certificate.holds
    assert result.min_separation >= 2 * problem.safety_radius
    np.testing.assert_allclose(result.time, schedule.time * 80.0 / schedule.time[-1])
    assert max(result.arrival_times) == pytest.approx(80.0)
