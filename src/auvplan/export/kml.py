"""KML 2.2 for Google Earth: one timed ``gx:Track`` per vehicle, obstacles as outlines.

Each track pairs a ``<when>`` (UTC, ``start_time + t``) with a ``<gx:coord>`` (lon, lat,
altitude = the depth, negated, ``absolute`` altitude mode), so Google Earth's time slider
replays the plan. Obstacles are outlined polygons (circles as 72-gons) in their own folder.

The document is built element by element (lxml) in the order the OGC KML 2.2 and Google
extension schemas prescribe — ``name`` before styles in a ``Document``, ``altitudeMode``
before the ``when``/``gx:coord`` pairs of a track — with ``id`` values that are ``xs:ID``
(never starting with a digit), so that it validates against ``ogckml22.xsd``/``kml22gx.xsd``
and strict readers (fastkml 1.x) accept it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Final

import numpy as np
from lxml import etree

from auvplan._typing import FloatArray
from auvplan._version import __version__
from auvplan.export.plan import CircleZone, ExportPlan, PolygonZone, utc_text
from auvplan.export.waypoints import Waypoints
from auvplan.terrain.projection import LocalProjection

#: Vertices of the polygon that draws a circular obstacle.
CIRCLE_VERTICES: Final = 72
KML_NAMESPACE: Final = "http://www.opengis.net/kml/2.2"
GX_NAMESPACE: Final = "http://www.google.com/kml/ext/2.2"
#: Outline colour of the obstacles, KML ``aabbggrr`` (opaque red).
ZONE_COLOUR: Final = "ff0000ff"


def zone_outline(zone: CircleZone | PolygonZone) -> list[tuple[float, float]]:
    """``(lon, lat)`` [deg] of a zone's closed outline."""
    if isinstance(zone, PolygonZone):
        lat, lon = zone.lat, zone.lon
    else:
        angle = np.linspace(0.0, 2.0 * np.pi, CIRCLE_VERTICES, endpoint=False)
        lat, lon = LocalProjection(zone.lat, zone.lon).to_geographic(
            zone.radius * np.cos(angle), zone.radius * np.sin(angle)
        )
    return _closed(lon, lat)


def zone_holes(zone: CircleZone | PolygonZone) -> list[list[tuple[float, float]]]:
    """``(lon, lat)`` [deg] of each closed ring of a zone's holes (none for a circle)."""
    return [_closed(lon, lat) for lat, lon in zone.holes] if isinstance(zone, PolygonZone) else []


def _closed(lon: FloatArray, lat: FloatArray) -> list[tuple[float, float]]:
    """``(lon, lat)`` [deg] pairs of a ring, its first vertex repeated at the end."""
    ring = [(float(x), float(y)) for x, y in zip(lon, lat, strict=True)]
    return [*ring, ring[0]]


def _kml(tag: str) -> str:
    return f"{{{KML_NAMESPACE}}}{tag}"


def _child(
    parent: etree._Element, tag: str, text: str | None = None, **attributes: str
) -> etree._Element:
    element = etree.SubElement(parent, tag, attributes)
    element.text = text
    return element


def kml_document(plan: ExportPlan, fleet: Sequence[Waypoints]) -> str:
    """The KML text of the fleet's timed tracks and the obstacles."""
    root = etree.Element(_kml("kml"), nsmap={None: KML_NAMESPACE, "gx": GX_NAMESPACE})
    document = _child(root, _kml("Document"), id="auvplan_plan")
    _child(document, _kml("name"), f"auvplan {__version__} plan, {utc_text(plan.start_time)}")
    style = _child(document, _kml("Style"), id="zone_outline")
    line = _child(style, _kml("LineStyle"))
    _child(line, _kml("color"), ZONE_COLOUR)
    _child(line, _kml("width"), "2")
    _child(_child(style, _kml("PolyStyle")), _kml("fill"), "0")
    vehicles = _child(document, _kml("Folder"), id="vehicles")
    _child(vehicles, _kml("name"), "vehicles")
    for number, waypoints in enumerate(fleet, start=1):
        placemark = _child(vehicles, _kml("Placemark"), id=f"vehicle_{number}")
        _child(placemark, _kml("name"), waypoints.name)
        track = _child(placemark, f"{{{GX_NAMESPACE}}}Track")
        _child(track, _kml("altitudeMode"), "absolute")
        for seconds in waypoints.time:
            _child(track, _kml("when"), utc_text(plan.timestamp(seconds)))
        depths = plan.waypoint_depths(waypoints)
        for lat, lon, depth in zip(*waypoints.geographic(), depths, strict=True):
            coord = f"{float(lon)!r} {float(lat)!r} {0.0 - float(depth)!r}"
            _child(track, f"{{{GX_NAMESPACE}}}coord", coord)
    if plan.zones:
        obstacles = _child(document, _kml("Folder"), id="obstacles")
        _child(obstacles, _kml("name"), "obstacles")
        for number, zone in enumerate(plan.zones, start=1):
            placemark = _child(obstacles, _kml("Placemark"), id=f"obstacle_{number}")
            _child(placemark, _kml("name"), zone.name)
            _child(placemark, _kml("styleUrl"), "#zone_outline")
            polygon = _child(placemark, _kml("Polygon"))
            rings = [("outerBoundaryIs", zone_outline(zone))]
            rings += [("innerBoundaryIs", hole) for hole in zone_holes(zone)]
            for boundary, outline in rings:
                ring = _child(_child(polygon, _kml(boundary)), _kml("LinearRing"))
                points = " ".join(f"{lon!r},{lat!r},0" for lon, lat in outline)
                _child(ring, _kml("coordinates"), points)
    text: bytes = etree.tostring(root, xml_declaration=True, encoding="UTF-8", pretty_print=True)
    return text.decode()


def render(plan: ExportPlan, fleet: Sequence[Waypoints]) -> dict[str, str]:
    """``trajectories.kml``."""
    return {"trajectories.kml": kml_document(plan, fleet)}


__all__ = ["CIRCLE_VERTICES", "kml_document", "render", "zone_holes", "zone_outline"]
