from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from _deconfliction_oracles import dense_min_separation, distance_to_polyline

from auvplan.deconfliction import (
    CoordinationProblem,
    arrival_times_of,
    certify_separation,
    deconflict,
    retime_for_arrival,
    timed_positions,
)
from auvplan.errors import InfeasibleError, InputError


def four_way() -> CoordinationProblem:
    paths = []
    for angle in np.radians([0.0, 45.0, 90.0, 135.0]):
        direction = np.array([np.cos(angle), np.sin(angle)])
        paths.append(np.array([-8.0 * direction, 8.0 * direction]))
    return CoordinationProblem(tuple(paths), 1.0, np.array([1.0, 0.8, 1.2, 1.0]), 0.5)


def test_certificate_is_a_lower_bound_and_tight_side_by_side(rng: np.random.Generator) -> None:
    problem = four_way()
    time = np.linspace(0.0, 20.0, 41)
    for _ in range(5):
        progress = np.sort(rng.uniform(0, 1, size=(4, 41)), axis=1) * problem.path_lengths[:, None]
        certificate = certify_separation(problem, time, progress)
        fine = np.linspace(0.0, 20.0, 4001)
        positions = np.stack(
            [
                np.column_stack(
                    [
                        np.interp(
                            np.interp(fine, time, progress[i]),
                            problem.arc_lengths[i],
                            problem.paths[i][:, axis],
                        )
                        for axis in (0, 1)
                    ]
                )
                for i in range(4)
            ]
        )
        true_min = min(
            np.hypot(*(positions[i] - positions[j]).T).min()
            for i in range(4)
            for j in range(i + 1, 4)
        )
        assert certificate.min_separation <= true_min + 1e-9
        assert certificate.min_sampled_separation >= certificate.min_separation
    # two vehicles side by side at the same speed: the bound loses exactly (Δs_i + Δs_j)/2
    side = CoordinationProblem(
        (np.array([[0.0, 0.0], [10.0, 0.0]]), np.array([[0.0, 3.0], [10.0, 3.0]])),
        1.0,
        np.ones(2),
        1.0,
    )
    time = np.arange(11.0)
    certificate = certify_separation(side, time, np.vstack([time, time]))
    assert certificate.min_separation == pytest.approx(3.0 - 1.0)
    assert certificate.min_sampled_separation == pytest.approx(3.0)


def test_certificate_rejects_bad_shapes() -> None:
    problem = four_way()
    with pytest.raises(InputError, match="progress"):
        certify_separation(problem, np.arange(3.0), np.zeros((2, 3)))
    with pytest.raises(InputError, match="increasing"):
        certify_separation(problem, np.array([0.0, 0.0, 1.0]), np.zeros((4, 3)))


@pytest.mark.parametrize("method", ["astar", "prioritized"])
def test_retime_for_arrival_keeps_separation_and_arrives_together(method: str) -> None:
    problem = four_way()
    result = deconflict(problem, method=method)
    assert np.ptp(result.arrival_times) > 0  # some would arrive early
    final_time = result.makespan * 1.3 + 2.0
    retimed = retime_for_arrival(result, problem, final_time)
    assert retimed.success
    assert retimed.certificate.holds
    np.testing.assert_allclose(retimed.arrival_times, final_time)
    assert retimed.time[-1] == pytest.approx(final_time)
    assert dense_min_separation(problem, retimed) >= problem.separation - 1e-9
    np.testing.assert_array_equal(retimed.progress[:, -1], problem.path_lengths)
    speed = np.diff(retimed.progress, axis=1) / np.diff(retimed.time)
    assert np.all(speed >= -1e-12)
    assert np.all(speed <= problem.cruise_speeds[:, None] * result.makespan / final_time + 1e-9)
    positions = timed_positions(retimed, problem, np.linspace(0, final_time, 23))
    for i, path in enumerate(problem.paths):
        assert max(distance_to_polyline(path, p) for p in positions[i]) < 1e-9
    np.testing.assert_allclose(retimed.delays, final_time - problem.nominal_arrival_times)


def test_retime_at_the_makespan_keeps_configurations() -> None:
    problem = four_way()
    result = deconflict(problem, method="prioritized")
    retimed = retime_for_arrival(result, problem, result.makespan)
    np.testing.assert_allclose(retimed.arrival_times, result.makespan)
    assert retimed.min_separation >= problem.separation - 1e-9


def test_retime_rejects_a_final_time_before_the_makespan() -> None:
    problem = four_way()
    result = deconflict(problem, method="prioritized")
    with pytest.raises(InputError, match="makespan"):
        retime_for_arrival(result, problem, result.makespan - 1.0)


def test_uncertified_schedule_is_never_returned() -> None:
    problem = four_way()
    result = deconflict(problem, method="prioritized")
    nominal = np.minimum(
        problem.cruise_speeds[:, None] * result.time[None, :], problem.path_lengths[:, None]
    )
    nominal[:, -1] = problem.path_lengths
    collide = dataclasses.replace(result, progress=nominal)
    with pytest.raises(InfeasibleError, match=r"vehicles \d and \d .*not certified"):
        retime_for_arrival(collide, problem, result.makespan + 1.0)


def test_arrival_times_of_requires_arrival() -> None:
    problem = four_way()
    with pytest.raises(InputError, match="does not reach"):
        arrival_times_of(problem, np.arange(2.0), np.zeros((4, 2)))
