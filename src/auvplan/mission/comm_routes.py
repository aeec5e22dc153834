"""Stage 1 for ``[[comm]]`` pairs: the corridor that keeps a route in range of its partner's.

Routes are planned one vehicle at a time (:func:`~auvplan.mission.preplan.plan_routes`), so a
vehicle of a communication pair is routed after its partner when it comes later in the
mission; its A* search is then confined to the cells within ``max_range − margin`` of the
partner's smoothed path. Without the corridor two paired vehicles may pass an obstacle on
opposite sides, out of range, and the optimiser cannot drag them together through it.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import shapely

from auvplan._typing import FloatArray
from auvplan.mission.config import CommConfig
from auvplan.planning import OperatingArea, PolygonObstacle
from auvplan.terrain import GridGeometry


def comm_margin(clearance: float, deviation: float) -> float:
    """Distance [m] a corridor keeps inside a pair's communication range.

    ``deviation`` [m] is how far the vehicle's smoothed path may stray from its grid route
    (at least half a cell): once for that smoothing and once more for the optimiser's own
    departure from either desired path, plus two safety radii ``clearance`` [m] of slack
    for the barrier. On a grid of cell ``c`` and a vehicle that turns within the cell this is
    ``c + 2 r_c``.
    """
    return 2.0 * clearance + 2.0 * deviation


def comm_corridor(
    index: int,
    names: tuple[str, ...],
    comms: tuple[CommConfig, ...],
    paths: Sequence[FloatArray],
    starts: FloatArray,
    goals: FloatArray,
    *,
    geometry: GridGeometry,
    clearance: float,
    deviation: float,
) -> tuple[OperatingArea, ...]:
    """Areas that confine vehicle ``index``'s A* route to its routed partners' ranges.

    One :class:`~auvplan.planning.OperatingArea` per ``[[comm]]`` pair of vehicle ``index``
    whose partner is already routed (its index is below ``index``; ``paths`` holds the
    smoothed paths routed so far, each ``(n, 2)`` north/east [m]). The area is the partner's
    path buffered by ``max_range − margin + clearance`` (:func:`comm_margin`), so that a
    cell A* keeps (one ``clearance`` [m] inside the area's rim) lies wholly within
    ``max_range − margin`` of the partner's path. The segments from the vehicle's start
    (goal) to its partner's start (goal), buffered by a cell's diagonal of ``geometry``
    plus ``clearance``, join the area so that the vehicle's own start and goal
    cells stay open (the pair starts and ends in range: preplan checks it).
    ``starts`` and ``goals`` have shape ``(n_vehicles, >= 2)``: north/east [m] first.
    Empty when no routed partner exists, e.g. for every mission without ``[[comm]]``.
    """
    link = float(np.hypot(geometry.spacing_north, geometry.spacing_east)) + clearance
    margin = comm_margin(clearance, deviation)
    areas = []
    for comm in comms:
        if names[index] not in comm.pair:
            continue
        partner = names.index(comm.pair[1] if comm.pair[0] == names[index] else comm.pair[0])
        if partner >= index:
            continue  # routed later, within this vehicle's range
        reach = max(comm.max_range - margin, 0.0) + clearance
        region = shapely.union_all(
            [
                shapely.LineString(paths[partner]).buffer(reach),
                shapely.LineString([starts[index, :2], starts[partner, :2]]).buffer(link),
                shapely.LineString([goals[index, :2], goals[partner, :2]]).buffer(link),
            ]
        )
        # pieces that each touch the partner's path: one polygon (shapely's x, y = north, east),
        # but for the slivers GEOS may leave apart from a wide buffer of a dense curve
        region = max(shapely.get_parts(region), key=lambda part: part.area)
        areas.append(
            OperatingArea(
                PolygonObstacle(
                    np.asarray(region.exterior.coords)[:-1],
                    tuple(np.asarray(ring.coords)[:-1] for ring in region.interiors),
                )
            )
        )
    return tuple(areas)
