"""Bad grids are refused before the large arrays exist, naming the setting to change."""

from __future__ import annotations

import time

import numpy as np
import pytest

from auvplan.deconfliction import CoordinationProblem, DeconflictionMethod, deconflict
from auvplan.deconfliction._budget import MAX_HEURISTIC_CELLS
from auvplan.errors import InputError


def crossing_pair(time_step: float, length: float = 400.0) -> CoordinationProblem:
    """Two straight paths crossing at 60 degrees near their middles, r_c = 5 m, 1 m/s."""
    s = np.linspace(-length / 2, length / 2, 3)[:, None]
    paths = tuple(
        s * np.array([np.cos(a), np.sin(a)]) + 0.5 * k for k, a in enumerate((0.3, 0.3 + np.pi / 3))
    )
    return CoordinationProblem(paths, 5.0, np.ones(2), time_step)


def test_tiny_cruise_speed_does_not_overflow_the_step_count() -> None:
    # 1e-17 m/s used to overflow the int64 step count, skip the guard and return a
    # schedule with separation -404 m
    paths = crossing_pair(0.5).paths
    with pytest.raises(InputError, match=r"vehicle 1 needs 8e\+19 grid steps.*cruise speed"):
        CoordinationProblem(paths, 5.0, np.array([1.0, 1e-17]), 0.5)


def test_fine_time_step_for_a_large_fleet_is_refused_up_front() -> None:
    rng = np.random.default_rng(1)
    paths = tuple(np.cumsum(rng.uniform(-200, 200, (3, 2)), axis=0) + 900 * k for k in range(8))
    problem = CoordinationProblem(paths, 5.0, np.ones(8), 2e-4)
    started = time.perf_counter()
    with pytest.raises(InputError) as info:
        deconflict(problem, method="prioritized")
    assert time.perf_counter() - started < 5.0
    message = str(info.value)
    assert "deconfliction.time_step_s = 0.0002 s is too fine" in message
    assert "fleet.cruise_speed" in message
    assert "\n" not in message


def test_pairwise_heuristic_over_budget_is_detected_before_it_is_built() -> None:
    # dt = 1 ms: the crossing's heuristic would store 5.7e9 cells (11 GB, 217 s measured);
    # it used to end in MemoryError after 80-90 s
    problem = crossing_pair(0.001)
    started = time.perf_counter()
    with pytest.raises(
        InputError, match=r"time_step_s = 0.001 s is too fine for A\*: .*heuristic needs more than"
    ):
        deconflict(problem, method="astar")
    result = deconflict(problem, method="auto")
    assert time.perf_counter() - started < 30.0
    assert result.success
    assert result.method is DeconflictionMethod.ASTAR
    assert f"more than {MAX_HEURISTIC_CELLS:.3g} cells" in result.fallback
    assert "coarser grid" in result.fallback
    assert result.time[1] == pytest.approx(0.001)


@pytest.mark.parametrize(
    ("coarsening", "time_step", "fragment"),
    [
        (5000, 0.01, r"deconfliction.coarsening = 5000 is too large: .*use coarsening <= 1000\b"),
        (1, 20.0, r"deconfliction.time_step_s = 20 s is too coarse: .*time_step_s <= 10 s"),
    ],
)
def test_search_steps_longer_than_the_separation_name_the_setting(
    coarsening: int, time_step: float, fragment: str
) -> None:
    # the vehicles' starts are far apart: the message used to blame them
    with pytest.raises(InputError, match=fragment) as info:
        deconflict(crossing_pair(time_step), coarsening=coarsening)
    assert "start" not in str(info.value)
