"""A record's optimised plan as an :class:`~auvplan.export.plan.ExportPlan`.

``auvplan export``, ``plan --export`` and :meth:`auvplan.MissionPlan.save` export from a
:class:`~auvplan.record.PlanRecord`: the one read from the folder, or the one just written, so
an export made later is the same as one made with the plan.
"""

from __future__ import annotations

import logging

import numpy as np

from auvplan.errors import InputError
from auvplan.export.plan import CircleZone, ExportPlan, PolygonZone, VehicleTrack
from auvplan.record.files import MAIN_PLAN
from auvplan.record.folder import PlanRecord
from auvplan.record.summary import AreaObstacle, CircleObstacle, PolygonObstacle

logger = logging.getLogger(__name__)


def export_plan(record: PlanRecord) -> ExportPlan:
    """The optimised plan of ``record``, ready to export.

    On terrain without geographic reference (the synthetic bank) the plan has no lat/lon
    and no keep-out zones: only :func:`auvplan.export.check_georeference`'s formats are
    written of it.

    Raises
    ------
    InputError
        If the record holds no optimised plan (``--stage`` stopped early or the optimiser
        failed).
    """
    summary = record.summary
    outcome = summary.optimization
    if not record.has_plan or outcome is None:
        reason = f"the optimiser {outcome.plan_status}" if outcome else f"--stage {summary.stage}"
        raise InputError(f"the record holds no optimised plan ({reason}); nothing to export")
    projection = record.maps.bathymetry.projection
    origin = summary.terrain.origin
    if origin.lat is None or origin.lon is None:
        projection = None
    if outcome.plan_status != "CONVERGED":
        logger.warning(
            "the plan is %s (see summary.json): check it before a vehicle flies it",
            outcome.plan_status,
        )
    tracks = []
    for table in record.plans[MAIN_PLAN]:
        north, east = table.state("north"), table.state("east")
        lat, lon = (None, None) if projection is None else projection.to_geographic(north, east)
        tracks.append(VehicleTrack(table.name, table.time, north, east, lat, lon, table.depth))
    return ExportPlan(
        tracks=tuple(tracks),
        start_time=summary.start,
        depth=record.depth,
        origin_lat=None if projection is None else origin.lat,
        origin_lon=None if projection is None else origin.lon,
        capture_radius=summary.fleet.safety_radius_m,
        zones=()
        if projection is None
        else tuple(  # the operating area is kept in, not out
            _zone(obstacle)
            for obstacle in summary.obstacles
            if not isinstance(obstacle, AreaObstacle)
        ),
    )


def _zone(obstacle: CircleObstacle | PolygonObstacle) -> CircleZone | PolygonZone:
    """A keep-out zone from an obstacle of ``summary.json`` (lat/lon required), holes kept."""
    if isinstance(obstacle, PolygonObstacle):
        rings = []
        for ring in (obstacle.vertices, *obstacle.holes):
            corners = [(v.lat, v.lon) for v in ring]
            if any(lat is None or lon is None for lat, lon in corners):
                raise InputError(f"obstacle {obstacle.name!r} has no lat/lon in summary.json")
            rings.append(np.array(corners, dtype=np.float64).T)
        return PolygonZone(
            obstacle.name, rings[0][0], rings[0][1], tuple((h[0], h[1]) for h in rings[1:])
        )
    center = obstacle.center
    if center.lat is None or center.lon is None:
        raise InputError(f"obstacle {obstacle.name!r} has no lat/lon in summary.json")
    return CircleZone(obstacle.name, center.lat, center.lon, obstacle.radius_m)


__all__ = ["export_plan"]
