"""Belief-space search: optimal on its graph, the budget kept, the smallest budget found."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.sparse import lil_matrix
from scipy.sparse.csgraph import dijkstra

from auvplan.errors import InputError
from auvplan.navigation._prediction_kernel import propagate
from auvplan.planning import PlanningProblem
from auvplan.planning.belief import BeliefModel, search_belief

#: The 16 moves: king moves and knight moves.
MOVES_16 = [
    (dr, dc)
    for dr in range(-2, 3)
    for dc in range(-2, 3)
    if (abs(dr), abs(dc)) in {(0, 1), (1, 0), (1, 1), (1, 2), (2, 1)}
]


def _crossed(r: int, c: int, dr: int, dc: int) -> list[tuple[int, int]]:
    """Cells a move must find passable: the cell entered, and for a knight move the two cells
    beside the midpoint of its segment."""
    if abs(dr) == 2:
        return [(r + dr, c + dc), (r + dr // 2, c), (r + dr // 2, c + dc)]
    if abs(dc) == 2:
        return [(r + dr, c + dc), (r, c + dc // 2), (r + dr, c + dc // 2)]
    return [(r + dr, c + dc)]


def _ridge_fisher(n_rows: int, n_cols: int, row: int, value: float = 0.05) -> np.ndarray:
    """Information only on one row of cells (a ridge), none elsewhere."""
    fisher = np.zeros((n_rows, n_cols, 3))
    fisher[row, :, 0] = fisher[row, :, 2] = value
    return fisher


def _model(fisher: np.ndarray, **kwargs: float) -> BeliefModel:
    return BeliefModel(fisher, 0.2, 0.01, 0.0, 3.0, **kwargs)  # type: ignore[arg-type]


def _replay_sigma(cells: np.ndarray, model: BeliefModel, spacing: float) -> np.ndarray:
    """σ along a cell path recomputed move by move with the recursion's step."""
    fisher = model.fisher
    p00, p01, p11, grown = model.initial_sigma**2, 0.0, model.initial_sigma**2, 0.0
    f = fisher[tuple(cells[0])]
    j = np.linalg.inv(np.array([[p00, p01], [p01, p11]])) + np.array([[f[0], f[1]], [f[1], f[2]]])
    cov = np.linalg.inv(j)
    p00, p01, p11 = cov[0, 0], cov[0, 1], cov[1, 1]
    sigma = [math.sqrt(p00 + p11)]
    for a, b in itertools.pairwise(cells):
        ell = spacing * float(np.hypot(*(b - a)))
        n = ell * model.updates_per_metre
        f = 0.5 * n * (fisher[tuple(a)] + fisher[tuple(b)])
        p00, p01, p11, grown = propagate(
            p00, p01, p11, grown, model.drift_rate**2, ell, n * model.process_variance, *f
        )
        sigma.append(math.sqrt(p00 + p11))
    return np.array(sigma)


def test_without_a_budget_the_search_is_the_shortest_16_connected_path() -> None:
    rng = np.random.default_rng(4)
    cost = rng.uniform(1.0, 3.0, (9, 11))
    cost[2:7, 5] = np.nan
    n_rows, n_cols = cost.shape
    graph = lil_matrix((cost.size, cost.size))
    for r in range(n_rows):
        for c in range(n_cols):
            for dr, dc in MOVES_16:
                rr, cc = r + dr, c + dc
                if not (0 <= rr < n_rows and 0 <= cc < n_cols):
                    continue
                if any(np.isnan(cost[x]) for x in [(r, c), *_crossed(r, c, dr, dc)]):
                    continue
                length = 10.0 * math.hypot(dr, dc)
                graph[r * n_cols + c, rr * n_cols + cc] = length * 0.5 * (cost[r, c] + cost[rr, cc])
    expected = dijkstra(graph.tocsr(), indices=4 * n_cols)[4 * n_cols + n_cols - 1]
    problem = PlanningProblem(cost, None, (4, 0), (4, n_cols - 1), 10.0, 10.0)
    found = search_belief(problem, _model(np.zeros((*cost.shape, 3))))
    assert found.path.cost == pytest.approx(expected, rel=1e-12)


def test_a_budget_is_kept_and_costs_a_detour() -> None:
    fisher = _ridge_fisher(30, 60, row=25)
    problem = PlanningProblem(np.ones((30, 60)), None, (5, 0), (5, 59), 10.0, 10.0)
    free = search_belief(problem, _model(fisher))
    assert set(free.path.cells[:, 0]) == {5}  # the straight line, far from the ridge
    budget = 0.8 * free.peak
    kept = search_belief(problem, _model(fisher, max_error=budget, settle_distance=50.0))
    assert kept.path.success
    assert kept.path.cost > free.path.cost
    assert kept.path.cells[:, 0].max() >= 24  # it had to reach the ridge
    replay = _replay_sigma(kept.path.cells, kept_model := _model(fisher), 10.0)
    np.testing.assert_allclose(replay, kept.sigma, rtol=1e-9)
    travelled = np.concatenate(
        [[0.0], np.cumsum(10.0 * np.hypot(*np.diff(kept.path.cells, axis=0).T))]
    )
    assert np.all(replay[travelled > 50.0] <= budget + 1e-9)
    assert kept_model.n_bins == 1


def test_the_bottleneck_is_the_smallest_feasible_budget() -> None:
    fisher = _ridge_fisher(30, 60, row=20)
    problem = PlanningProblem(np.ones((30, 60)), None, (5, 0), (5, 59), 10.0, 10.0)
    floor = search_belief(problem, _model(fisher, settle_distance=50.0), bottleneck=True).peak
    wide = _model(fisher, max_error=floor + 0.5, settle_distance=50.0)
    assert search_belief(problem, wide).path.success
    tight = _model(fisher, max_error=floor - 0.5, settle_distance=50.0)
    assert not search_belief(problem, tight).path.success


def test_a_soft_weight_trades_length_for_error() -> None:
    fisher = _ridge_fisher(30, 60, row=12)
    problem = PlanningProblem(np.ones((30, 60)), None, (5, 0), (5, 59), 10.0, 10.0)
    free = search_belief(problem, _model(fisher))
    priced = search_belief(problem, _model(fisher, error_weight=1.0))
    assert priced.path.cells[:, 0].max() >= 11
    rms = [float(np.sqrt(np.mean(found.sigma**2))) for found in (free, priced)]
    assert rms[1] < rms[0]


def test_mismatched_fisher_map_and_label_limit_are_input_errors() -> None:
    problem = PlanningProblem(np.ones((10, 10)), None, (0, 0), (9, 9))
    with pytest.raises(InputError, match="does not match"):
        search_belief(problem, _model(np.zeros((9, 10, 3))))
    limited = BeliefModel(np.zeros((10, 10, 3)), 0.2, 0.01, 0.0, 3.0, max_labels=5)
    with pytest.raises(InputError, match="more than 5 labels"):
        search_belief(problem, limited)
