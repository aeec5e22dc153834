from __future__ import annotations

import itertools

import numpy as np
import pytest

from auvplan.deconfliction import CoordinationProblem, build_conflict_table
from auvplan.deconfliction._conflict_kernels import (
    DEAD_END,
    pair_cost_to_go,
    pair_reachability,
    shadow_cells,
)
from auvplan.deconfliction.conflicts import build_pair_heuristic, inflated_radius


def random_problem(rng: np.random.Generator, n_vehicles: int = 3) -> CoordinationProblem:
    paths = tuple(np.cumsum(rng.uniform(-6, 6, size=(4, 2)), axis=0) for _ in range(n_vehicles))
    return CoordinationProblem(
        paths=paths,
        safety_radius=rng.uniform(0.5, 2.0),
        cruise_speeds=rng.uniform(0.5, 1.5, size=n_vehicles),
        time_step=0.7,
    )


def dense_forbidden(problem: CoordinationProblem, i: int, j: int) -> np.ndarray:
    points_i = problem.grid_points(i)
    points_j = problem.grid_points(j)
    distance = np.hypot(*(points_i[:, None, :] - points_j[None, :, :]).transpose(2, 0, 1))
    return distance <= inflated_radius(problem, i, j)


def table_as_bitmap(problem: CoordinationProblem, table, i: int, j: int) -> np.ndarray:  # type: ignore[no-untyped-def]
    bitmap = np.zeros((problem.n_steps[i] + 1, problem.n_steps[j] + 1), dtype=bool)
    for k_i in range(problem.n_steps[i] + 1):
        intervals = table.forbidden(i, j, k_i)
        for (a, b), (c, _) in itertools.pairwise([*intervals, (10**9, 0)]):
            assert a <= b < c - 1 or c == 10**9  # sorted, disjoint, not adjacent
        for a, b in intervals:
            bitmap[k_i, a : b + 1] = True
    return bitmap


@pytest.mark.parametrize("seed", range(5))
def test_intervals_match_brute_force_distances(seed: int) -> None:
    problem = random_problem(np.random.default_rng(seed))
    table = build_conflict_table(problem)
    for i, j in itertools.permutations(range(3), 2):
        np.testing.assert_array_equal(
            table_as_bitmap(problem, table, i, j), dense_forbidden(problem, i, j)
        )


def brute_cost_to_go(forbidden: np.ndarray) -> np.ndarray:
    n_i, n_j = forbidden.shape[0] - 1, forbidden.shape[1] - 1
    cost = np.full(forbidden.shape, np.inf)
    for a in range(n_i, -1, -1):
        for b in range(n_j, -1, -1):
            if forbidden[a, b]:
                continue
            if (a, b) == (n_i, n_j):
                cost[a, b] = 0
                continue
            options = [
                cost[a + da, b + db]
                for da, db in ((1, 0), (0, 1), (1, 1))
                if a + da <= n_i and b + db <= n_j
            ]
            cost[a, b] = 1 + min(options)
    return cost


@pytest.mark.parametrize("seed", range(6))
def test_pair_cost_to_go_and_reachability_match_brute_force(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    problem = random_problem(rng, n_vehicles=2)
    table = build_conflict_table(problem, ordered_pairs=((0, 1),))
    forbidden = dense_forbidden(problem, 0, 1)
    expected = brute_cost_to_go(forbidden)
    n_i, n_j = (int(n) for n in problem.n_steps)
    rows = table.row_ptr[: n_i + 2]
    first, start, length, values, count, n_cells = pair_cost_to_go(
        rows, table.lo, table.hi, n_i, n_j, np.empty(8, dtype=np.uint16), 0, 10**9
    )
    assert count == int(length.sum()) <= n_cells
    # the estimate made before allocating counts at least every forbidden cell
    assert shadow_cells(rows, table.lo, table.hi, n_i, n_j) >= int(forbidden.sum())
    # a budget below the windows stops the programme and says so
    *_, n_stopped = pair_cost_to_go(
        rows, table.lo, table.hi, n_i, n_j, np.empty(8, dtype=np.uint16), 0, n_cells - 1
    )
    assert n_cells == 0 or n_stopped > n_cells - 1
    for a in range(n_i + 1):
        for b in range(n_j + 1):
            if forbidden[a, b]:
                continue
            column = b - first[a]
            stored = int(values[start[a] + column]) if 0 <= column < length[a] else 0
            if np.isinf(expected[a, b]):
                assert stored == DEAD_END
            else:
                assert max(n_i - a, n_j - b) + stored == expected[a, b]
    reachable, _, _ = pair_reachability(rows, table.lo, table.hi, n_i, n_j)
    assert reachable == bool(np.isfinite(expected[0, 0]))


def test_pair_heuristic_skips_pairs_that_never_meet() -> None:
    far = CoordinationProblem(
        paths=(np.array([[0.0, 0.0], [10.0, 0.0]]), np.array([[0.0, 50.0], [10.0, 50.0]])),
        safety_radius=1.0,
        cruise_speeds=np.ones(2),
        time_step=0.5,
    )
    table = build_conflict_table(far, ordered_pairs=((0, 1),))
    assert table.lo.size == 0
    heuristic = build_pair_heuristic(far, table)
    assert heuristic is not None
    assert heuristic.pair_base.tolist() == [-1, -1, -1, -1]


def test_shadow_estimate_is_exact_for_a_crossing() -> None:
    # two straight 40 m paths crossing at 60 degrees: the raised cost-to-go fills exactly the
    # diagonal shadow of the forbidden blob (what the budget check relies on)
    direction = np.array([[np.cos(a), np.sin(a)] for a in (0.3, 0.3 + np.pi / 3)])
    s = np.linspace(-20.0, 20.0, 3)[:, None]
    problem = CoordinationProblem((s * direction[0], s * direction[1] + 0.5), 2.0, np.ones(2), 0.05)
    table = build_conflict_table(problem, ordered_pairs=((0, 1),))
    n_i, n_j = (int(n) for n in problem.n_steps)
    rows = table.row_ptr[: n_i + 2]
    heuristic = build_pair_heuristic(problem, table)
    assert heuristic is not None
    assert shadow_cells(rows, table.lo, table.hi, n_i, n_j) == heuristic.excess.size > 10_000
    assert build_pair_heuristic(problem, table, max_cells=heuristic.excess.size - 1) is None
