"""Stage-1 routes of ``[[comm]]`` pairs stay in range of each other around an obstacle."""

from __future__ import annotations

import logging

import numpy as np
import pytest
import shapely

from auvplan._typing import FloatArray
from auvplan.mission.comm_routes import comm_corridor, comm_margin
from auvplan.mission.config import CommConfig, PlannerConfig
from auvplan.mission.preplan import plan_routes
from auvplan.planning import CircleObstacle
from auvplan.terrain import BathymetryGrid, GridGeometry, TerrainMaps, compute_terrain_maps

SPACING = 10.0  # [m]
N = 100  # 1 km square
CLEARANCE = 5.0  # [m]
#: A disc midway; blue starts and ends 25 m west of its centre line, green 25 m east.
OBSTACLE = CircleObstacle(500.0, 500.0, 100.0)
STARTS = np.array([[150.0, 475.0, 0.0], [150.0, 525.0, 0.0]])
GOALS = np.array([[850.0, 475.0, 0.0], [850.0, 525.0, 0.0]])
NAMES = ("blue", "green")
MAX_RANGE = 70.0  # [m]


@pytest.fixture(scope="module")
def plain() -> TerrainMaps:
    """Maps of a gently sloping, featureless plain."""
    depth = 60.0 + 0.02 * np.arange(N)[None, :] + np.zeros((N, N))
    return compute_terrain_maps(BathymetryGrid(depth, GridGeometry(N, N, SPACING, SPACING)))


def _paths(maps: TerrainMaps, comms: tuple[CommConfig, ...]) -> tuple[FloatArray, ...]:
    return plan_routes(
        maps, NAMES, STARTS, GOALS, (OBSTACLE,),
        clearance=CLEARANCE, planner=PlannerConfig(edge_model="crossed"), comms=comms,
    )[1]  # fmt: skip


def _east_abreast(path: FloatArray) -> float:
    """East [m] of ``path`` where it passes the obstacle's centre."""
    return float(np.interp(OBSTACLE.north, path[:, 0], path[:, 1]))


def _farthest(path: FloatArray, partner: FloatArray) -> float:
    """Largest distance [m] from a point of ``path`` to the polyline ``partner``."""
    a, b = partner[:-1], partner[1:]
    ab = b - a
    t = np.einsum("pkj,kj->pk", path[:, None, :] - a, ab) / np.einsum("kj,kj->k", ab, ab)
    nearest = a + np.clip(t, 0.0, 1.0)[..., None] * ab
    return float(np.max(np.min(np.linalg.norm(path[:, None, :] - nearest, axis=-1), axis=1)))


def test_a_comm_pair_passes_the_obstacle_on_one_side(plain: TerrainMaps) -> None:
    free = _paths(plain, ())
    # without the pair the routes split around the disc, far out of range
    assert _east_abreast(free[0]) < OBSTACLE.east < _east_abreast(free[1])
    assert _farthest(free[1], free[0]) > 2.0 * OBSTACLE.radius
    comm = CommConfig.model_validate({"pair": ["blue", "green"], "max_range_m": MAX_RANGE})
    paired = _paths(plain, (comm,))
    np.testing.assert_array_equal(paired[0], free[0])  # blue, routed first, keeps its route
    assert _east_abreast(paired[1]) < OBSTACLE.east  # green follows blue west of the disc
    # every point of green's path in range of blue's path, with the margin's 2 r_c to spare
    assert _farthest(paired[1], paired[0]) <= MAX_RANGE - 2.0 * CLEARANCE
    # the same pair named the other way round: blue is still the one routed first
    swapped = CommConfig.model_validate({"pair": ["green", "blue"], "max_range_m": MAX_RANGE})
    for one, other in zip(_paths(plain, (swapped,)), paired, strict=True):
        np.testing.assert_array_equal(one, other)


def test_a_corridor_too_narrow_falls_back_with_a_warning(
    plain: TerrainMaps, caplog: pytest.LogCaptureFixture
) -> None:
    # a range no wider than the margin leaves no cell in range of blue's path
    range_m = comm_margin(CLEARANCE, 0.5 * SPACING)
    comm = CommConfig.model_validate({"pair": ["blue", "green"], "max_range_m": range_m})
    with caplog.at_level(logging.WARNING, logger="auvplan.mission.preplan"):
        paths = _paths(plain, (comm,))
    free = _paths(plain, ())
    for one, other in zip(paths, free, strict=True):
        np.testing.assert_array_equal(one, other)
    assert any("green: no route stays" in record.getMessage() for record in caplog.records)


def test_a_wide_corridor_around_a_curved_path_is_one_area() -> None:
    """GEOS buffers this gently curving partner path (a REMUS 100 route's 18 samples) by
    839 m into a polygon and a 16 m^2 sliver 1 km away; the corridor is the polygon (the
    sliver made the planner fail with a traceback)."""
    partner = np.array([
        [365.3, 394.2], [365.0, 392.2], [364.6, 390.2], [364.3, 388.2], [364.1, 386.3],
        [363.6, 382.3], [363.4, 380.3], [363.3, 378.3], [363.1, 376.3], [363.1, 374.3],
        [363.1, 372.3], [363.1, 370.3], [363.3, 368.3], [363.4, 366.3], [363.7, 364.3],
        [364.4, 360.4], [364.9, 358.5], [365.5, 356.5],
    ])  # fmt: skip
    starts = np.array([partner[0], [600.0, 100.0]])
    goals = np.array([partner[-1], [200.0, 200.0]])
    deviation = 18.4  # a REMUS 100's corner cut
    max_range = 839.0 - CLEARANCE + comm_margin(CLEARANCE, deviation)  # a buffer of 839 m
    comm = CommConfig.model_validate({"pair": ["blue", "green"], "max_range_m": max_range})
    (area,) = comm_corridor(
        1, NAMES, (comm,), [partner], starts, goals,
        geometry=GridGeometry(N, N, SPACING, SPACING), clearance=CLEARANCE, deviation=deviation,
    )  # fmt: skip
    polygon = shapely.Polygon(area.region.vertices)
    assert polygon.area > 0.99 * np.pi * 839.0**2  # the whole buffer, not the sliver
    assert polygon.contains(shapely.LineString(partner))
