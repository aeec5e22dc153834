from __future__ import annotations

import math

import numpy as np
import pytest
from _deconfliction_oracles import (
    brute_force_optimum,
    dense_min_separation,
    distance_to_polyline,
    grid_collides,
)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from auvplan.deconfliction import (
    CoordinationProblem,
    CoordinationResult,
    CoordinationStatus,
    DeconflictionMethod,
    deconflict,
    timed_headings,
    timed_positions,
)
from auvplan.errors import InfeasibleError, InputError, SolverError

METHODS = [("astar", 1.0), ("astar", None), ("prioritized", None)]


def check_schedule(problem: CoordinationProblem, result: CoordinationResult) -> None:
    """Safe, on the paths, monotone, from start to goal, within cruise speed."""
    assert result.success
    assert result.certificate.holds
    assert result.min_separation >= problem.separation - 1e-9
    assert dense_min_separation(problem, result) >= result.min_separation - 1e-9
    assert np.all(result.progress[:, 0] == 0.0)
    np.testing.assert_array_equal(result.progress[:, -1], problem.path_lengths)
    assert np.all(np.diff(result.progress, axis=1) >= 0.0)
    speed = np.diff(result.progress, axis=1) / np.diff(result.time)
    assert np.all(speed <= problem.cruise_speeds[:, None] * (1 + 1e-9))
    times = np.linspace(0.0, result.time[-1], 37)
    positions = timed_positions(result, problem, times)
    assert positions.shape == (problem.n_vehicles, times.size, 2)
    for i, path in enumerate(problem.paths):
        assert max(distance_to_polyline(path, p) for p in positions[i]) < 1e-9
    assert np.all(result.delays >= -1e-9)
    np.testing.assert_allclose(result.arrival_times - problem.nominal_arrival_times, result.delays)


def crossing(
    angles_deg: list[float], half_length: float, time_step: float, safety_radius: float = 1.0
) -> CoordinationProblem:
    paths = []
    for angle in np.radians(angles_deg):
        direction = np.array([np.cos(angle), np.sin(angle)])  # north, east
        paths.append(np.array([-half_length * direction, half_length * direction]))
    return CoordinationProblem(tuple(paths), safety_radius, np.ones(len(paths)), time_step)


@pytest.mark.parametrize(("method", "weight"), METHODS)
def test_right_angle_crossing(method: str, weight: float | None) -> None:
    problem = crossing([0.0, 90.0], half_length=12.0, time_step=0.5)
    result = deconflict(problem, method=method, weight=weight)
    check_schedule(problem, result)
    # exactly one vehicle yields; the nominal schedule would collide at the centre
    assert sorted(result.delays > 0.25) == [False, True]
    if weight == 1.0:
        assert result.status is CoordinationStatus.OPTIMAL
        steps, waits = brute_force_optimum(problem)  # type: ignore[misc]
        assert result.objective[0] == pytest.approx(steps * problem.time_step)
        assert result.delays.sum() == pytest.approx(waits * problem.time_step)


def test_head_on_solved_by_waiting() -> None:
    # vehicle 1 runs west along vehicle 0's line, then leaves it northwards at east = 5 m;
    # vehicle 1 starts on vehicle 0's path, so vehicle 0 must wait until 1 has turned off
    east_bound = np.array([[0.0, -10.0], [0.0, 30.0]])
    west_then_north = np.array([[0.0, 25.0], [0.0, 5.0], [20.0, 5.0]])
    problem = CoordinationProblem((east_bound, west_then_north), 1.0, np.ones(2), 0.5)
    nominal_gap = np.hypot(*(east_bound[0] + [0, 17.5] - west_then_north[0] - [0, -17.5]))
    assert nominal_gap < problem.separation  # the nominal schedule collides head-on
    for method, weight in METHODS:
        result = deconflict(problem, method=method, weight=weight)
        check_schedule(problem, result)
        assert result.delays[0] > 5.0  # vehicle 0 waits for the other to leave the line
        assert result.delays[1] < problem.time_step


def test_overtaking_on_a_shared_segment_slows_the_faster_vehicle() -> None:
    slow = np.array([[0.0, 0.0], [0.0, 40.0]])
    fast = np.array([[0.0, -10.0], [0.0, 20.0], [20.0, 20.0]])
    problem = CoordinationProblem((slow, fast), 1.0, np.array([0.5, 1.0]), 0.5)
    for method, weight in METHODS:
        result = deconflict(problem, method=method, weight=weight)
        check_schedule(problem, result)
        assert result.delays[0] < problem.time_step
        # the fast vehicle cannot reach the turn at east = 20 m before the slow one is 2 r_c past it
        assert result.delays[1] >= (20.0 + problem.separation) / 0.5 - 30.0 - 1e-9


@pytest.fixture(scope="module")
def four_way() -> CoordinationProblem:
    return crossing([0.0, 45.0, 90.0, 135.0], half_length=6.0, time_step=1.5)


def test_four_vehicles_at_one_point_optimal_on_the_grid(four_way: CoordinationProblem) -> None:
    steps, waits = brute_force_optimum(four_way)  # type: ignore[misc]
    assert waits > 0  # there are real conflicts
    for heuristic in ("pairwise", "max"):
        result = deconflict(four_way, weight=1.0, heuristic=heuristic)
        check_schedule(four_way, result)
        assert result.status is CoordinationStatus.OPTIMAL
        assert result.objective[0] == pytest.approx(steps * four_way.time_step)
        assert result.delays.sum() == pytest.approx(waits * four_way.time_step)
    weighted = deconflict(four_way)  # weight sqrt(4) = 2: makespan within 2x the optimum
    check_schedule(four_way, weighted)
    assert weighted.status is CoordinationStatus.BOUNDED_SUBOPTIMAL
    assert weighted.objective[0] <= 2.0 * steps * four_way.time_step + 1e-9
    prioritized = deconflict(four_way, method="prioritized")
    check_schedule(four_way, prioritized)
    assert prioritized.status is CoordinationStatus.FEASIBLE
    assert prioritized.objective[0] >= steps * four_way.time_step - 1e-9


def test_headings_follow_the_path_tangent(four_way: CoordinationProblem) -> None:
    result = deconflict(four_way, method="prioritized")
    psi = timed_headings(result, four_way, np.array([0.0, 3.0, result.time[-1]]))
    expected = np.radians([0.0, 45.0, 90.0, 135.0])
    np.testing.assert_allclose(psi, np.repeat(expected[:, None], 3, axis=1), atol=1e-12)


def test_infeasible_starts_and_goals_name_the_pair() -> None:
    paths = (np.array([[0.0, 0.0], [10.0, 0.0]]), np.array([[0.0, 1.5], [-10.0, 20.0]]))
    with pytest.raises(InfeasibleError, match=r"vehicles 0 and 1 both begin .*\(north, east\)"):
        deconflict(CoordinationProblem(paths, 1.0, np.ones(2), 0.5))
    paths = (np.array([[0.0, 0.0], [10.0, 0.0]]), np.array([[0.0, 20.0], [10.0, 1.0]]))
    with pytest.raises(InfeasibleError, match=r"vehicles 0 and 1 both end"):
        deconflict(CoordinationProblem(paths, 1.0, np.ones(2), 0.5), method="prioritized")


@pytest.mark.parametrize("method", ["astar", "prioritized"])
def test_head_on_swap_on_one_line_is_infeasible(method: str) -> None:
    # each vehicle's goal lies on the other's path: no timing lets them pass
    line = np.array([[0.0, 0.0], [0.0, 30.0]])
    problem = CoordinationProblem((line, line[::-1].copy()), 1.0, np.ones(2), 0.5)
    with pytest.raises(InfeasibleError) as info:
        deconflict(problem, method=method)
    message = str(info.value)
    assert "vehicles 0 and 1 cannot be separated by timing" in message
    assert "(north, east)" in message
    assert "\n" not in message


def test_goal_on_the_path_of_a_vehicle_that_must_wait_forever() -> None:
    # vehicle 1 starts on vehicle 0's line and ends on it further ahead: vehicle 0 can
    # neither pass it (head-on is impossible, same direction means 1 ends in 0's way)
    blocker = np.array([[0.0, 10.0], [0.0, 20.0]])
    runner = np.array([[0.0, 0.0], [0.0, 30.0]])
    problem = CoordinationProblem((runner, blocker), 1.0, np.ones(2), 0.5)
    with pytest.raises(InfeasibleError, match=r"vehicle 1's goal"):
        deconflict(problem)


def test_bad_options() -> None:
    problem = crossing([0.0, 90.0], half_length=5.0, time_step=0.5)
    with pytest.raises(InputError, match="method"):
        deconflict(problem, method="rrt")
    with pytest.raises(InputError, match="weight"):
        deconflict(problem, weight=0.5)
    with pytest.raises(InputError, match="weight"):
        deconflict(problem, method="prioritized", weight=2.0)
    with pytest.raises(InputError, match="heuristic"):
        deconflict(problem, heuristic="euclid")
    by_enum = deconflict(problem, method=DeconflictionMethod.PRIORITIZED)
    assert by_enum.method == "prioritized"


def test_single_vehicle_is_its_nominal_schedule() -> None:
    problem = CoordinationProblem((np.array([[0.0, 0.0], [3.0, 4.0]]),), 1.0, np.array([2.0]), 0.5)
    for method in ("astar", "prioritized"):
        result = deconflict(problem, method=method)
        assert result.time[-1] == 2.5
        assert math.isinf(result.min_separation)
        assert result.delays[0] == pytest.approx(0.0)


@pytest.mark.parametrize(
    ("method", "status"),
    [("auto", "OPTIMAL"), ("astar", "OPTIMAL"), ("prioritized", "FEASIBLE")],
)
def test_single_vehicle_needs_no_search(method: str, status: str) -> None:
    path = np.array([[0.0, 0.0], [30.0, 10.0], [60.0, 0.0]])
    problem = CoordinationProblem((path,), 2.0, np.array([0.7]), 0.5)
    result = deconflict(problem, method=method)
    assert result.n_expanded == 0
    assert result.status.name == status
    assert str(result.method) == ("prioritized" if method == "prioritized" else "astar")
    # one grid step per time step: at the nominal speed, arriving on the first step after it
    assert np.all(np.diff(result.progress[0]) <= 0.7 * 0.5 + 1e-9)
    nominal = float(problem.nominal_arrival_times[0])
    assert nominal <= result.arrival_times[0] < nominal + problem.time_step


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1), method=st.sampled_from(["astar", "prioritized"]))
def test_random_path_sets_are_safe_or_infeasible(seed: int, method: str) -> None:
    rng = np.random.default_rng(seed)
    n_vehicles = int(rng.integers(2, 4))
    paths = tuple(
        np.cumsum(np.vstack([rng.uniform(0, 20, 2), rng.uniform(-8, 8, size=(2, 2))]), axis=0)
        for _ in range(n_vehicles)
    )
    problem = CoordinationProblem(paths, 1.0, rng.uniform(0.5, 1.5, n_vehicles), 1.0)
    try:
        result = deconflict(problem, method=method)
    except InfeasibleError as error:
        message = str(error)
    else:
        check_schedule(problem, result)
        return
    assert "vehicle" in message
    assert "\n" not in message


def earliest_arrival_brute_force(
    problem: CoordinationProblem, first_schedule: np.ndarray, vehicle: int, other: int
) -> int | None:
    """Breadth-first search over (k, t) for ``vehicle`` given ``other``'s grid schedule."""
    n_k = int(problem.n_steps[vehicle])
    horizon = first_schedule.size + n_k + 200

    def other_at(t: int) -> int:
        return int(first_schedule[min(t, first_schedule.size - 1)])

    def free(k: int, t: int) -> bool:
        nodes = [0, 0]
        nodes[vehicle], nodes[other] = k, other_at(t)
        return not grid_collides(problem, tuple(nodes))

    reachable = {0} if free(0, 0) else set()
    for t in range(horizon):
        if n_k in reachable and all(free(n_k, u) for u in range(t, first_schedule.size + 1)):
            return t
        reachable = {k2 for k in reachable for k2 in (k, k + 1) if k2 <= n_k and free(k2, t + 1)}
    return None


@pytest.mark.parametrize("seed", range(4))
def test_prioritized_second_vehicle_arrives_as_early_as_possible(seed: int) -> None:
    rng = np.random.default_rng(seed)
    paths = (
        np.array([[0.0, -9.0], [0.0, 9.0]]),
        np.array([[-8.0, rng.uniform(-3, 3)], [8.0, rng.uniform(-3, 3)]]),
    )
    problem = CoordinationProblem(paths, 1.0, np.array([1.0, rng.uniform(0.8, 1.2)]), 0.5)
    result = deconflict(problem, method="prioritized")
    check_schedule(problem, result)
    first = int(np.argmax(problem.n_steps))  # the longer vehicle is planned first, unhindered
    second = 1 - first
    steps = np.rint(result.progress[first] / problem.step_lengths[first]).astype(int)
    steps = np.minimum(steps, problem.n_steps[first])
    assert result.delays[first] < problem.time_step
    expected = earliest_arrival_brute_force(problem, steps, second, first)
    assert expected is not None
    assert result.arrival_times[second] == pytest.approx(expected * problem.time_step)


def test_coarsening_returns_the_coarse_schedule_on_the_fine_grid() -> None:
    problem = crossing([0.0, 90.0], half_length=12.0, time_step=0.1)
    coarse = CoordinationProblem(problem.paths, 1.0, problem.cruise_speeds, 0.5)
    for method, weight in METHODS:
        result = deconflict(problem, method=method, weight=weight, coarsening=5)
        reference = deconflict(coarse, method=method, weight=weight)
        check_schedule(problem, result)
        assert result.time[1] == pytest.approx(0.1)
        np.testing.assert_allclose(result.progress[:, ::5], reference.progress)
        assert result.min_separation >= reference.min_separation - 1e-12
    with pytest.raises(InputError, match="coarsening"):
        deconflict(problem, coarsening=0)


def vectorised_dense_min_separation(
    problem: CoordinationProblem, result: CoordinationResult, n_per_step: int
) -> float:
    fine = np.linspace(0.0, result.time[-1], (result.time.size - 1) * n_per_step + 1)
    points = []
    for i, path in enumerate(problem.paths):
        arc = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))))
        s = np.interp(fine, result.time, result.progress[i])
        points.append(
            np.column_stack([np.interp(s, arc, path[:, 0]), np.interp(s, arc, path[:, 1])])
        )
    return min(
        float(np.hypot(*(points[i] - points[j]).T).min())
        for i in range(problem.n_vehicles)
        for j in range(i + 1, problem.n_vehicles)
    )


def star_of_vehicles(n_vehicles: int, duration: float, time_step: float) -> CoordinationProblem:
    rng = np.random.default_rng(n_vehicles)
    paths = []
    for i in range(n_vehicles):
        heading = np.pi * i / n_vehicles + rng.uniform(-0.1, 0.1)
        before = duration * rng.uniform(0.45, 0.55)
        s = np.linspace(-before, duration - before, int(duration) + 1)
        bend = 0.02 * duration * np.sin(np.pi * (s + before) / duration) * rng.uniform(-1, 1)
        paths.append(
            np.column_stack(
                [
                    s * np.cos(heading) - bend * np.sin(heading),
                    s * np.sin(heading) + bend * np.cos(heading),
                ]
            )
        )
    return CoordinationProblem(tuple(paths), 2.5, np.ones(n_vehicles), time_step)


def test_eight_vehicles_through_one_point_prioritized() -> None:
    problem = star_of_vehicles(8, 60.0, 0.05)
    result = deconflict(problem, method="prioritized")
    assert result.certificate.holds
    assert vectorised_dense_min_separation(problem, result, 5) >= problem.separation - 1e-9
    assert result.delays.max() > 5.0  # the centre is crowded: real waits were needed


@pytest.mark.slow
def test_sixteen_vehicles_ten_minutes_at_the_papers_grid() -> None:
    problem = star_of_vehicles(16, 600.0, 0.01)
    result = deconflict(problem, method="prioritized")
    assert result.certificate.holds
    assert vectorised_dense_min_separation(problem, result, 3) >= problem.separation - 1e-9


@pytest.mark.parametrize(
    ("max_expanded", "method"), [(60_000, DeconflictionMethod.ASTAR), (2_000, "prioritized")]
)
def test_auto_falls_back_when_astar_exhausts_its_budget(max_expanded: int, method: str) -> None:
    # four vehicles through one point at the paper's 0.01 s grid: exact A* exceeds its
    # budget; auto then searches a 25x coarser grid (5.5e4 expansions), else plans by priority
    problem = star_of_vehicles(4, 60.0, 0.01)
    with pytest.raises(SolverError, match="max_expanded"):
        deconflict(problem, method="astar", max_expanded=max_expanded)
    result = deconflict(problem, max_expanded=max_expanded)
    check_schedule(problem, result)
    assert result.method == method
    assert f"max_expanded = {max_expanded}" in result.fallback
    assert result.fallback in result.message
    assert result.time[1] == pytest.approx(0.01)


@pytest.mark.slow
def test_auto_falls_back_at_the_default_budget() -> None:
    # the failure of issue 11: "A* expanded max_expanded=1000000 ... use method='prioritized'"
    problem = star_of_vehicles(4, 60.0, 0.01)
    result = deconflict(problem)
    check_schedule(problem, result)
    assert result.method is DeconflictionMethod.ASTAR
    assert "max_expanded = 1000000" in result.fallback
    assert "25x coarser" in result.fallback


def test_auto_uses_prioritized_planning_beyond_four_vehicles() -> None:
    problem = crossing([0.0, 30.0, 60.0, 90.0, 120.0, 150.0], half_length=12.0, time_step=0.5)
    result = deconflict(problem)
    check_schedule(problem, result)
    assert result.method is DeconflictionMethod.PRIORITIZED
    assert "6 vehicles > 4" in result.fallback
    small = deconflict(crossing([0.0, 90.0], half_length=12.0, time_step=0.5))
    assert (small.method, small.fallback) == (DeconflictionMethod.ASTAR, "")
