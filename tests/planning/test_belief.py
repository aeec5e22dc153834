"""Belief-space search: optimal on its graph, the budget kept, the smallest budget found."""

from __future__ import annotations

import heapq
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


#: Moves in the kernel's order (:func:`auvplan.planning._belief_kernel.moves`): the label
#: numbers, the last tie-break, follow it.
KERNEL_MOVES = [
    (-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1),
    (-2, -1), (-2, 1), (-1, -2), (-1, 2), (1, -2), (1, 2), (2, -1), (2, 1),
]  # fmt: skip


def _label_setting(
    problem: PlanningProblem, model: BeliefModel, *, bottleneck: bool = False
) -> tuple[list[tuple[int, int]], float, int]:
    """Label setting with the σ-bin dominance and no other pruning, popped with ``heapq`` in
    the order ``(key, σ², peak, label number)``: the path, its cost and the labels created."""
    cost, fisher, spacing = problem.cost, model.fisher, problem.spacing_north
    n_rows, n_cols = cost.shape
    width = model.bin_width if bottleneck else model.width
    n_bins = 160 if bottleneck else model.n_bins
    max_error = math.inf if bottleneck else model.max_error
    goal = np.array(problem.goal)
    rate = float(np.min(cost[np.isfinite(cost)]))
    heuristic = rate * np.hypot(*((np.indices(cost.shape) - goal[:, None, None]) * spacing))

    def bin_of(variance: float) -> int:
        return min(int(math.sqrt(variance) / width), n_bins - 1)

    f = fisher[problem.start]
    info = np.diag([1.0, 1.0]) / model.initial_sigma**2 + [[f[0], f[1]], [f[1], f[2]]]
    det = info[0, 0] * info[1, 1] - info[0, 1] ** 2
    # label: cell, parent, g, p00, p01, p11, grown, distance, peak
    labels = [(problem.start, -1, 0.0, info[1, 1] / det, -info[0, 1] / det, info[0, 0] / det)]
    labels[0] += (0.0, 0.0, 0.0)
    heap = [
        (
            0.0 if bottleneck else float(heuristic[problem.start]),
            labels[0][3] + labels[0][5],
            0.0,
            0,
        )
    ]
    closed = np.full(cost.shape, n_bins)
    while heap:
        *_, label = heapq.heappop(heap)
        (r, c), _, g, p00, p01, p11, grown, distance, peak = labels[label]
        if bin_of(p00 + p11) >= closed[r, c]:
            continue
        closed[r, c] = bin_of(p00 + p11)
        if (r, c) == problem.goal:
            path = []
            while label >= 0:
                path.append(labels[label][0])
                label = labels[label][1]
            return path[::-1], g, len(labels)
        for dr, dc in KERNEL_MOVES:
            v = (r + dr, c + dc)
            cells = [v, *_crossed(r, c, dr, dc)]
            if not all(
                0 <= a < n_rows and 0 <= b < n_cols and np.isfinite(cost[a, b]) for a, b in cells
            ):
                continue
            ell = math.hypot(dr * spacing, dc * spacing)
            n = ell * model.updates_per_metre
            q00, q01, q11, q_grown = propagate(
                p00, p01, p11, grown, model.drift_rate**2, ell, n * model.process_variance,
                *(0.5 * n * (fisher[r, c] + fisher[v])),
            )  # fmt: skip
            sigma_v = math.sqrt(q00 + q11)
            if bin_of(q00 + q11) >= closed[v]:
                continue
            q_peak = peak
            if distance + ell > model.settle_distance:
                if sigma_v > max_error:
                    continue
                q_peak = max(peak, sigma_v)
            sigma_u = math.sqrt(p00 + p11)
            q_g = g + ell * 1.0 * 0.5 * (cost[r, c] + cost[v])
            q_g += model.error_weight * ell * 0.5 * (sigma_u * sigma_u + sigma_v * sigma_v)
            key = q_peak * 1e9 + q_g if bottleneck else q_g + heuristic[v]
            heapq.heappush(heap, (key, q00 + q11, q_peak, len(labels)))
            labels.append((v, label, q_g, q00, q01, q11, q_grown, distance + ell, q_peak))
    return [], math.inf, len(labels)


@pytest.mark.parametrize("informative_side", ["north", "south"])
def test_of_exactly_tied_routes_the_search_keeps_the_one_of_lower_sigma(
    informative_side: str,
) -> None:
    # a wall across the middle: the routes north and south of it are mirror images (equal
    # costs to the last bit); only the south one crosses informative seabed. A budget that
    # never binds gives the search its σ bins (plain A*, one bin, breaks ties by key only)
    cost = np.ones((11, 21))
    cost[2:9, 10] = np.nan
    fisher = np.zeros((11, 21, 3))
    fisher[9:, :, 0] = fisher[9:, :, 2] = 0.05
    if informative_side == "north":
        fisher = fisher[::-1].copy()
    problem = PlanningProblem(cost, None, (5, 0), (5, 20), 10.0, 10.0)
    found = search_belief(problem, _model(fisher, max_error=100.0))
    rows = found.path.cells[:, 0]
    assert (rows.max() >= 9) if informative_side == "south" else (rows.min() <= 1)
    mirrored = search_belief(problem, _model(fisher[::-1].copy(), max_error=100.0))
    assert found.path.cost == mirrored.path.cost
    np.testing.assert_array_equal(mirrored.path.cells[:, 0], 10 - rows)
    assert found.sigma[-1] < _replay_sigma(mirrored.path.cells, _model(fisher), 10.0)[-1]


@pytest.mark.parametrize(
    ("seed", "options", "bottleneck"),
    [
        (0, {"max_error": 6.0, "settle_distance": 40.0}, False),
        (1, {"max_error": 9.0, "settle_distance": 40.0, "error_weight": 0.02}, False),
        (2, {"error_weight": 0.05}, False),
        (3, {"settle_distance": 40.0}, True),
    ],
)
def test_the_search_pops_labels_in_the_order_of_a_plain_label_setting(
    seed: int, options: dict[str, float], bottleneck: bool
) -> None:
    # unit costs: many labels of exactly equal cost, ordered by σ, peak and label number; the
    # kernel's push-time dominance must not change which labels pop, only how many are made
    rng = np.random.default_rng(seed)
    cost = np.ones((12, 16))
    cost[rng.uniform(size=cost.shape) < 0.12] = np.nan
    cost[6, 0] = cost[5, 15] = 1.0
    fisher = np.zeros((12, 16, 3))
    fisher[..., 0] = fisher[..., 2] = rng.uniform(0.0, 0.3, cost.shape) ** 3
    model = _model(fisher, **options)
    problem = PlanningProblem(cost, None, (6, 0), (5, 15), 10.0, 10.0)
    found = search_belief(problem, model, bottleneck=bottleneck)
    path, expected_cost, n_reference = _label_setting(problem, model, bottleneck=bottleneck)
    assert found.path.success
    assert found.path.cells.tolist() == [list(cell) for cell in path]
    assert found.path.cost == expected_cost
    assert found.n_labels < n_reference  # the push-time dominance created fewer labels
