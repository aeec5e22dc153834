"""KML for Google Earth: one timed ``gx:Track`` per vehicle (simplekml).

Each track pairs a ``<when>`` (UTC, ``start_time + t``) with a ``<gx:coord>`` (lon, lat,
altitude = the depth, negated, ``absolute`` altitude mode), so Google Earth's time slider
replays the plan. Obstacles are drawn as outlined polygons (circles as 72-gons).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Final

import numpy as np

from auvplan import __version__
from auvplan.export.plan import CircleZone, ExportPlan, PolygonZone, utc_text
from auvplan.export.waypoints import Waypoints
from auvplan.terrain.projection import LocalProjection

#: Vertices of the polygon that draws a circular obstacle.
CIRCLE_VERTICES: Final = 72


def zone_outline(zone: CircleZone | PolygonZone) -> list[tuple[float, float]]:
    """``(lon, lat)`` [deg] of a zone's closed outline."""
    if isinstance(zone, PolygonZone):
        lat, lon = zone.lat, zone.lon
    else:
        angle = np.linspace(0.0, 2.0 * np.pi, CIRCLE_VERTICES, endpoint=False)
        lat, lon = LocalProjection(zone.lat, zone.lon).to_geographic(
            zone.radius * np.cos(angle), zone.radius * np.sin(angle)
        )
    ring = [(float(x), float(y)) for x, y in zip(lon, lat, strict=True)]
    return [*ring, ring[0]]


def kml_document(plan: ExportPlan, fleet: Sequence[Waypoints]) -> str:
    """The KML text of the fleet's timed tracks and the obstacles."""
    import simplekml

    simplekml.Kml.resetidcounter()  # element ids from 0: the same plan gives the same file
    document = simplekml.Kml(name=f"auvplan {__version__} plan, {utc_text(plan.start_time)}")
    for waypoints in fleet:
        track = document.newgxtrack(name=waypoints.name)
        track.altitudemode = simplekml.AltitudeMode.absolute
        track.newwhen([utc_text(plan.timestamp(seconds)) for seconds in waypoints.time])
        track.newgxcoord(
            [
                (float(lon), float(lat), 0.0 - plan.depth)
                for lat, lon in zip(waypoints.lat, waypoints.lon, strict=True)
            ]
        )
    for zone in plan.zones:
        outline = document.newpolygon(name=zone.name, outerboundaryis=zone_outline(zone))
        outline.style.polystyle.fill = 0
    return str(document.kml())


def render(plan: ExportPlan, fleet: Sequence[Waypoints]) -> dict[str, str]:
    """``trajectories.kml``."""
    return {"trajectories.kml": kml_document(plan, fleet)}


__all__ = ["CIRCLE_VERTICES", "kml_document", "render", "zone_outline"]
