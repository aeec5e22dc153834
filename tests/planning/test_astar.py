"""A* optimality against an independent Dijkstra (scipy.sparse.csgraph) on random grids."""

from __future__ import annotations

import _planning_reference as ref
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvplan.errors import InputError
from auvplan.planning import EdgeModel, PlanningProblem, SearchStatus, plan_astar
from auvplan.planning.astar import MAX_BUCKETS, heuristic_map, search_grid

QUEUES = ("auto", "buckets", "heap")


def random_problem(
    seed: int,
    n_rows: int,
    n_cols: int,
    hole_fraction: float,
    cost_ratio: float,
    is_anisotropic: bool,
) -> PlanningProblem:
    """Cost in [low, low * ratio], NaN holes, blocked cells, random passable start/goal."""
    rng = np.random.default_rng(seed)
    low = rng.uniform(0.2, 12.0)
    cost = low * (1.0 + (cost_ratio - 1.0) * rng.random((n_rows, n_cols)))
    cost[rng.random((n_rows, n_cols)) < hole_fraction] = np.nan
    cost[rng.random((n_rows, n_cols)) < 0.3 * hole_fraction] = np.inf
    blocked = rng.random((n_rows, n_cols)) < hole_fraction
    passable = np.isfinite(cost) & ~blocked
    free = np.argwhere(passable)
    if len(free) == 0:
        cost[0, 0] = low
        blocked[0, 0] = False
        free = np.array([[0, 0]])
    start = tuple(int(i) for i in free[rng.integers(len(free))])
    goal = tuple(int(i) for i in free[rng.integers(len(free))])
    spacing_north, spacing_east = (
        (rng.uniform(0.5, 3.0), rng.uniform(0.5, 3.0)) if is_anisotropic else (1.0, 1.0)
    )
    return PlanningProblem(cost, blocked, start, goal, spacing_north, spacing_east)  # type: ignore[arg-type]


problems = st.builds(
    random_problem,
    seed=st.integers(0, 2**32 - 1),
    n_rows=st.integers(1, 14),
    n_cols=st.integers(1, 14),
    hole_fraction=st.sampled_from([0.0, 0.1, 0.25, 0.4]),
    cost_ratio=st.sampled_from([1.0, 2.0, 10.0, 1e4]),
    is_anisotropic=st.booleans(),
)


def assert_valid_path(problem: PlanningProblem, cells: np.ndarray) -> None:
    assert cells.dtype == np.int64
    assert cells.ndim == 2
    assert cells.shape[1] == 2
    assert tuple(cells[0]) == problem.start
    assert tuple(cells[-1]) == problem.goal
    assert np.all((cells >= 0) & (cells < np.array(problem.shape)))
    steps = np.diff(cells, axis=0)
    assert np.all(np.abs(steps) <= 1), "not 8-connected"
    assert np.all(np.any(steps != 0, axis=1)), "repeated cell"
    assert np.all(problem.passable[cells[:, 0], cells[:, 1]]), "path through an impassable cell"


@settings(max_examples=150, deadline=None, derandomize=True)
@given(problem=problems, model=st.sampled_from(list(EdgeModel)), queue=st.sampled_from(QUEUES))
def test_cost_equals_dijkstra(problem: PlanningProblem, model: EdgeModel, queue: str) -> None:
    graph = ref.build_graph(
        problem.cost, problem.blocked, model.value, problem.spacing_north, problem.spacing_east
    )
    expected = ref.dijkstra_cost(graph, problem.shape[1], problem.start)[
        problem.goal[0] * problem.shape[1] + problem.goal[1]
    ]
    try:
        result = search_grid(problem, edge_model=model, queue=queue)  # type: ignore[arg-type]
    except InputError:
        assert queue == "buckets"  # too wide a cost range for MAX_BUCKETS buckets
        return
    if not np.isfinite(expected):
        assert result.status is SearchStatus.UNREACHABLE
        assert not result.success
        assert result.cells.shape == (0, 2)
        assert result.cost == np.inf
        return
    assert result.status is SearchStatus.EXACT
    assert result.success
    assert result.cost == pytest.approx(expected, rel=1e-12, abs=0.0)
    assert_valid_path(problem, result.cells)
    summed = ref.path_cost(
        problem.cost, result.cells, model.value, problem.spacing_north, problem.spacing_east
    )
    assert summed == pytest.approx(result.cost, rel=1e-12, abs=0.0)
    assert 1 <= result.n_expanded <= int(problem.passable.sum())


@settings(max_examples=60, deadline=None, derandomize=True)
@given(problem=problems, model=st.sampled_from(list(EdgeModel)))
def test_heuristic_admissible_and_consistent(problem: PlanningProblem, model: EdgeModel) -> None:
    graph = ref.build_graph(
        problem.cost, problem.blocked, model.value, problem.spacing_north, problem.spacing_east
    )
    h = heuristic_map(problem, edge_model=model)
    assert h[problem.goal] == 0.0
    to_go = ref.cost_to_go(graph, problem.shape[1], problem.goal).reshape(problem.shape)
    reachable = np.isfinite(to_go)
    assert np.all(h[reachable] <= to_go[reachable] * (1 + 1e-12))
    coo = graph.tocoo()
    h_flat = h.ravel()
    assert np.all(h_flat[coo.row] <= coo.data + h_flat[coo.col] + 1e-9 * coo.data)


@pytest.mark.parametrize("model", list(EdgeModel))
def test_heuristic_is_at_least_min_cost_times_euclidean(model: EdgeModel) -> None:
    cost = np.full((6, 9), 3.0)
    problem = PlanningProblem(cost, None, (0, 0), (4, 7), 2.0, 0.5)
    h = heuristic_map(problem, edge_model=model)
    rows, cols = np.indices(cost.shape)
    if model is EdgeModel.PAPER:
        euclid = np.hypot(rows - 4, cols - 7)  # in cells
    else:
        euclid = np.hypot(2.0 * (rows - 4), 0.5 * (cols - 7))  # in metres
    # the paper's Euclidean-in-cells heuristic needs omega >= sqrt(2); ours dominates it then
    scale = 1.0 / np.sqrt(2.0) if model is EdgeModel.PAPER else 1.0
    assert np.all(h >= 3.0 * euclid * scale - 1e-12)


def test_hand_computed_detour() -> None:
    cost = np.array(
        [
            [1.0, 1.0, 1.0, 1.0],
            [1.0, np.nan, 5.0, 1.0],
            [1.0, 1.0, 1.0, 1.0],
        ]
    )
    result = plan_astar(PlanningProblem(cost, None, (1, 0), (1, 3)))
    assert result.cost == 3.0
    assert result.cells.tolist() in (
        [[1, 0], [0, 1], [0, 2], [1, 3]],
        [[1, 0], [2, 1], [2, 2], [1, 3]],
    )


def test_crossed_model_hand_computed() -> None:
    # 1 x 3 strip, spacing_east = 2 m: cost = 2 * (1 + 3) / 2 + 2 * (3 + 5) / 2 = 12
    cost = np.array([[1.0, 3.0, 5.0]])
    problem = PlanningProblem(cost, None, (0, 0), (0, 2), 1.0, 2.0)
    result = plan_astar(problem, edge_model=EdgeModel.CROSSED)
    assert result.cost == pytest.approx(12.0, rel=1e-15)
    assert plan_astar(problem, edge_model=EdgeModel.PAPER).cost == 8.0


def test_start_equals_goal() -> None:
    result = plan_astar(PlanningProblem(np.ones((3, 3)), None, (1, 1), (1, 1)))
    assert result.success
    assert result.cost == 0.0
    assert result.cells.tolist() == [[1, 1]]


def test_wall_makes_goal_unreachable() -> None:
    cost = np.ones((5, 5))
    blocked = np.zeros((5, 5), dtype=bool)
    blocked[:, 2] = True
    result = plan_astar(PlanningProblem(cost, blocked, (0, 0), (4, 4)))
    assert result.status is SearchStatus.UNREACHABLE
    assert "unreachable" in result.message


def test_diagonal_squeeze_between_blocked_cells_is_allowed() -> None:
    # documented rule: no corner-cutting restriction (as skimage MCP and pyastar2d)
    cost = np.ones((2, 2))
    blocked = np.array([[False, True], [True, False]])
    result = plan_astar(PlanningProblem(cost, blocked, (0, 0), (1, 1)))
    assert result.cells.tolist() == [[0, 0], [1, 1]]


def test_wide_cost_range_falls_back_to_heap() -> None:
    rng = np.random.default_rng(3)
    cost = np.exp(rng.uniform(0.0, 12.0, (20, 20)))
    problem = PlanningProblem(cost, None, (0, 0), (19, 19))
    with pytest.raises(InputError, match=f"{MAX_BUCKETS} buckets"):
        search_grid(problem, edge_model=EdgeModel.PAPER, queue="buckets")
    heap = search_grid(problem, edge_model=EdgeModel.PAPER, queue="heap")
    assert plan_astar(problem).cost == heap.cost


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"cost": np.ones(4)}, "2-D"),
        ({"cost": np.ones((2, 2), dtype=np.float32)}, "float64"),
        ({"cost": np.array([[1.0, 0.0], [1.0, 1.0]])}, "> 0"),
        ({"cost": np.array([[1.0, -np.inf], [1.0, 1.0]])}, "> 0"),
        ({"blocked": np.zeros((3, 2), dtype=bool)}, "blocked"),
        ({"start": (2, 0)}, "start cell"),
        ({"goal": (0, -1)}, "goal cell"),
        ({"cost": np.array([[np.nan, 1.0], [1.0, 1.0]])}, "start cell .* impassable"),
        ({"blocked": np.array([[False, False], [False, True]])}, "goal cell .* impassable"),
        ({"spacing_east": 0.0}, "spacing"),
    ],
)
def test_problem_validation(kwargs: dict[str, object], match: str) -> None:
    args: dict[str, object] = {
        "cost": np.ones((2, 2)),
        "blocked": None,
        "start": (0, 0),
        "goal": (1, 1),
    }
    args.update(kwargs)
    with pytest.raises(InputError, match=match):
        PlanningProblem(**args)  # type: ignore[arg-type]


def test_edge_model_type_checked() -> None:
    with pytest.raises(InputError, match="EdgeModel"):
        plan_astar(PlanningProblem(np.ones((2, 2)), None, (0, 0), (1, 1)), edge_model="paper")  # type: ignore[arg-type]


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("model", list(EdgeModel))
def test_cost_equals_dijkstra_on_larger_grids(seed: int, model: EdgeModel) -> None:
    # larger frontiers exercise many buckets at once (out-of-order closing would show here)
    problem = random_problem(seed, 45, 60, 0.15, 1.0 + seed / 2.0, seed % 2 == 1)
    graph = ref.build_graph(
        problem.cost, problem.blocked, model.value, problem.spacing_north, problem.spacing_east
    )
    expected = ref.dijkstra_cost(graph, problem.shape[1], problem.start)
    for queue in QUEUES:
        result = search_grid(problem, edge_model=model, queue=queue)  # type: ignore[arg-type]
        goal = expected[problem.goal[0] * problem.shape[1] + problem.goal[1]]
        if np.isfinite(goal):
            assert result.cost == pytest.approx(goal, rel=1e-12, abs=0.0)
            assert_valid_path(problem, result.cells)
        else:
            assert result.status is SearchStatus.UNREACHABLE


def with_move_factors(problem: PlanningProblem, seed: int, spread: float) -> PlanningProblem:
    """``problem`` with random move factors in ``[1/spread, spread]``, some moves barred."""
    rng = np.random.default_rng(seed)
    factor = np.exp(rng.uniform(-np.log(spread), np.log(spread), (8, *problem.shape)))
    factor[rng.random(factor.shape) < 0.1] = np.inf
    factor[rng.random(factor.shape) < 0.02] = np.nan
    return PlanningProblem(
        problem.cost, problem.blocked, problem.start, problem.goal, problem.spacing_north,
        problem.spacing_east, factor,
    )  # fmt: skip


@settings(max_examples=120, deadline=None, derandomize=True)
@given(
    problem=problems,
    seed=st.integers(0, 2**32 - 1),
    spread=st.sampled_from([1.0, 1.5, 10.0]),
    model=st.sampled_from(list(EdgeModel)),
    queue=st.sampled_from(QUEUES),
)
def test_cost_with_move_factors_equals_dijkstra(
    problem: PlanningProblem, seed: int, spread: float, model: EdgeModel, queue: str
) -> None:
    """A current's direction-dependent weights: still the exact optimum of the directed graph."""
    problem = with_move_factors(problem, seed, spread)
    graph = ref.build_graph(
        problem.cost, problem.blocked, model.value, problem.spacing_north, problem.spacing_east,
        problem.move_factor,
    )  # fmt: skip
    expected = ref.dijkstra_cost(graph, problem.shape[1], problem.start)[
        problem.goal[0] * problem.shape[1] + problem.goal[1]
    ]
    try:
        result = search_grid(problem, edge_model=model, queue=queue)  # type: ignore[arg-type]
    except InputError:
        assert queue == "buckets"
        return
    if not np.isfinite(expected):
        assert result.status is SearchStatus.UNREACHABLE
        return
    assert result.cost == pytest.approx(expected, rel=1e-12, abs=0.0)
    assert_valid_path(problem, result.cells)
    h = heuristic_map(problem, edge_model=model)
    to_go = ref.cost_to_go(graph, problem.shape[1], problem.goal).reshape(problem.shape)
    finite = np.isfinite(to_go)
    assert np.all(h[finite] <= to_go[finite] * (1 + 1e-12))  # admissible with the factors


def test_unit_move_factors_change_nothing() -> None:
    problem = random_problem(7, 12, 13, 0.2, 10.0, is_anisotropic=True)
    ones = PlanningProblem(
        problem.cost, problem.blocked, problem.start, problem.goal, problem.spacing_north,
        problem.spacing_east, np.ones((8, *problem.shape)),
    )  # fmt: skip
    for model in EdgeModel:
        plain, factored = plan_astar(problem, edge_model=model), plan_astar(ones, edge_model=model)
        assert factored.cost == plain.cost
        np.testing.assert_array_equal(factored.cells, plain.cells)


def test_move_factor_is_validated() -> None:
    with pytest.raises(
        InputError, match=r"move_factor must be a float64 array of shape \(8, 2, 3\)"
    ):
        PlanningProblem(np.ones((2, 3)), None, (0, 0), (1, 2), move_factor=np.ones((8, 3, 2)))
    with pytest.raises(InputError, match="move_factor must be > 0"):
        PlanningProblem(np.ones((2, 3)), None, (0, 0), (1, 2), move_factor=np.zeros((8, 2, 3)))
