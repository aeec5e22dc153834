"""plan_route: world coordinates in, optimal cells and points out, one-line named errors."""

from __future__ import annotations

import _planning_reference as ref
import numpy as np
import pytest

from auvplan.errors import InfeasibleError, InputError
from auvplan.planning import (
    CircleObstacle,
    EdgeModel,
    Obstacle,
    PolygonObstacle,
    blocked_cells,
    blocked_lookup,
    plan_route,
)
from auvplan.terrain.grid import GridGeometry


@pytest.fixture
def grid() -> GridGeometry:
    return GridGeometry(20, 30, 5.0, 4.0, origin_north=-10.0, origin_east=100.0)


@pytest.fixture
def cost(rng: np.random.Generator) -> np.ndarray:
    cost = 10.0 + 10.0 * rng.random((20, 30))
    cost[5:15, 10] = np.nan  # a wall of land with gaps at both ends
    return cost


@pytest.mark.parametrize("model", list(EdgeModel))
def test_route_is_optimal_and_avoids_obstacles(
    grid: GridGeometry, cost: np.ndarray, model: EdgeModel
) -> None:
    obstacles: list[Obstacle] = [
        CircleObstacle(40.0, 160.0, 8.0),
        PolygonObstacle(np.array([[0.0, 190.0], [20.0, 200.0], [0.0, 210.0]])),
    ]
    start, goal = (-9.0, 101.0), (83.0, 213.0)
    route = plan_route(
        cost, grid, start, goal, obstacles=obstacles, clearance=2.0, edge_model=model, name="auv1"
    )
    assert route.success
    assert route.name == "auv1"
    assert route.edge_model is model
    blocked = blocked_cells(cost, grid, obstacles=obstacles, clearance=2.0)
    assert not blocked[route.cells[:, 0], route.cells[:, 1]].any()
    graph = ref.build_graph(
        np.where(blocked, np.nan, cost), None, model.value, grid.spacing_north, grid.spacing_east
    )
    start_cell = tuple(int(i[()]) for i in grid.to_index(np.array(start[0]), np.array(start[1])))
    goal_cell = tuple(int(i[()]) for i in grid.to_index(np.array(goal[0]), np.array(goal[1])))
    assert tuple(route.cells[0]) == start_cell
    assert tuple(route.cells[-1]) == goal_cell
    expected = ref.dijkstra_cost(graph, grid.n_cols, start_cell)[  # type: ignore[arg-type]
        goal_cell[0] * grid.n_cols + goal_cell[1]
    ]
    assert route.cost == pytest.approx(expected, rel=1e-12)
    # points: exact endpoints, cell centres in between
    assert route.points.shape == route.cells.shape
    np.testing.assert_array_equal(route.points[0], start)
    np.testing.assert_array_equal(route.points[-1], goal)
    north, east = grid.to_world(route.cells[1:-1, 0], route.cells[1:-1, 1])
    np.testing.assert_array_equal(route.points[1:-1], np.column_stack((north, east)))


def test_start_and_goal_in_one_cell(grid: GridGeometry, cost: np.ndarray) -> None:
    route = plan_route(cost, grid, (0.0, 120.0), (1.0, 121.0))
    assert route.cells.shape == (1, 2)
    assert route.cost == 0.0
    np.testing.assert_array_equal(route.points, [[0.0, 120.0], [1.0, 121.0]])


@pytest.mark.parametrize(
    ("start", "goal", "obstacles", "error", "match"),
    [
        ((-30.0, 120.0), (50.0, 150.0), [], InputError, "auv7: start .* outside the map"),
        ((0.0, 120.0), (50.0, 500.0), [], InputError, "auv7: goal .* outside the map"),
        ((np.nan, 120.0), (50.0, 150.0), [], InputError, "auv7: start .* not finite"),
        ((0.0, 120.0), (40.0, 140.0), [], InfeasibleError, "auv7: goal .* on land or a no-data"),
        (
            (0.0, 120.0),
            (50.0, 150.0),
            [CircleObstacle(50.0, 150.0, 3.0)],
            InfeasibleError,
            "auv7: goal .* inside obstacle 'obstacle 0'$",
        ),
        (
            (0.0, 120.0),
            (50.0, 150.0),
            [CircleObstacle(50.0, 155.0, 3.0)],
            InfeasibleError,
            "auv7: goal .* within the clearance 2 m of obstacle 'obstacle 0' \\(2 m from it;",
        ),
        (
            (0.0, 120.0),
            (50.0, 150.0),
            [PolygonObstacle(np.array([[28.0, 0.0], [28.0, 300.0], [32.0, 300.0], [32.0, 0.0]]))],
            InfeasibleError,
            "auv7: goal .* unreachable",
        ),
    ],
)
def test_errors_name_vehicle_and_reason(
    grid: GridGeometry,
    cost: np.ndarray,
    start: tuple[float, float],
    goal: tuple[float, float],
    obstacles: list[CircleObstacle | PolygonObstacle],
    error: type[Exception],
    match: str,
) -> None:
    # (40, 140) m is cell (10, 10) on the land wall; the polygon strip cuts the grid in two
    with pytest.raises(error, match=match) as info:
        plan_route(cost, grid, start, goal, obstacles=obstacles, clearance=2.0, name="auv7")
    assert "\n" not in str(info.value)


def test_a_polygon_over_the_start_is_named(grid: GridGeometry, cost: np.ndarray) -> None:
    """One line naming the vehicle, the obstacle and the start (not the polygon's numpy repr)."""
    reef = PolygonObstacle(np.array([[-5.0, 110.0], [-5.0, 130.0], [5.0, 130.0], [5.0, 110.0]]))
    with pytest.raises(InfeasibleError) as info:
        plan_route(
            cost, grid, (0.0, 120.0), (50.0, 150.0), obstacles=[reef], obstacle_names=["reef"],
            name="auv7",
        )  # fmt: skip
    assert str(info.value) == "auv7: start (0, 120) m is inside obstacle 'reef'"


def test_shape_mismatch(grid: GridGeometry) -> None:
    with pytest.raises(InputError, match="does not match"):
        plan_route(np.ones((3, 3)), grid, (0.0, 120.0), (1.0, 121.0))


def test_bad_cost_values_name_the_vehicle(grid: GridGeometry, cost: np.ndarray) -> None:
    cost = cost.copy()
    cost[0, 0] = -1.0
    with pytest.raises(InputError, match="auv3: cost must be > 0"):
        plan_route(cost, grid, (0.0, 120.0), (1.0, 121.0), name="auv3")


def test_blocked_lookup_matches_cells(grid: GridGeometry, cost: np.ndarray) -> None:
    blocked = blocked_cells(cost, grid)
    is_blocked = blocked_lookup(grid, blocked)
    north, east = grid.to_world(*np.indices(grid.shape))
    np.testing.assert_array_equal(is_blocked(north.ravel(), east.ravel()), blocked.ravel())
    assert is_blocked(np.array([-1e3]), np.array([0.0])).tolist() == [True]
