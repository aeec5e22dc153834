"""GPX 1.1 (topografix.com/GPX/1/1): one track per vehicle, timed track points.

``<time>`` is the UTC time of each waypoint (``start_time + t``), so a GPX viewer replays the
time law; ``<ele>`` is metres above the sea surface (the depth, negated). Written with the
standard library's ElementTree (the tests read it back with gpxpy, an independent reader).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Final
from xml.etree import ElementTree

from auvplan._version import __version__
from auvplan.export.plan import ExportPlan, utc_text
from auvplan.export.waypoints import Waypoints

NAMESPACE: Final = "http://www.topografix.com/GPX/1/1"


def gpx_document(plan: ExportPlan, fleet: Sequence[Waypoints]) -> str:
    """The GPX text of the fleet's waypoints."""
    root = ElementTree.Element(
        "gpx", {"version": "1.1", "creator": f"auvplan {__version__}", "xmlns": NAMESPACE}
    )
    metadata = ElementTree.SubElement(root, "metadata")
    ElementTree.SubElement(metadata, "time").text = utc_text(plan.start_time)
    for waypoints in fleet:
        track = ElementTree.SubElement(root, "trk")
        ElementTree.SubElement(track, "name").text = waypoints.name
        segment = ElementTree.SubElement(track, "trkseg")
        depths = plan.waypoint_depths(waypoints)
        lats, lons = waypoints.geographic()
        for lat, lon, seconds, depth in zip(lats, lons, waypoints.time, depths, strict=True):
            point = ElementTree.SubElement(
                segment, "trkpt", {"lat": f"{lat:.9f}", "lon": f"{lon:.9f}"}
            )
            ElementTree.SubElement(point, "ele").text = f"{0.0 - depth:g}"
            ElementTree.SubElement(point, "time").text = utc_text(plan.timestamp(seconds))
    ElementTree.indent(root)
    return ElementTree.tostring(root, encoding="unicode", xml_declaration=True) + "\n"


def render(plan: ExportPlan, fleet: Sequence[Waypoints]) -> dict[str, str]:
    """``trajectories.gpx``."""
    return {"trajectories.gpx": gpx_document(plan, fleet)}


__all__ = ["NAMESPACE", "gpx_document", "render"]
