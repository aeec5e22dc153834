"""GeoJSON (RFC 7946) of a plan, in three layers a GIS opens side by side.

* ``trajectories.geojson``: one ``LineString`` per vehicle; the time law travels in the
  feature's properties: ``times`` (UTC, ISO 8601), ``t_s`` (seconds after the start) per
  point, ``leg_speed_m_s`` per leg, ``depth_m`` (the deepest point's, for a depth profile),
  and the feature's ``start_time``/``end_time``.
* ``waypoints.geojson``: one ``Point`` per waypoint with its own ``time`` (UTC, ISO 8601), so
  QGIS's temporal controller ("single field with date/time") animates the fleet, and the
  speed of the leg that leaves it.
* ``obstacles.geojson`` (when the mission has obstacles): one ``Polygon`` per keep-out zone
  (circles as 72-gons, counter-clockwise exterior rings as RFC 7946 §3.1.6 asks).

Coordinates are ``[lon, lat]`` in WGS 84 with :data:`DECIMALS` decimals (≈ 1 cm, RFC 7946
§11.2 advises against more precision than is meaningful); a plan with a depth profile
(``[mission] altitude_m``) adds each position's altitude ``-depth`` [m] (sea level as the
datum), and each waypoint's ``depth_m`` is its own.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from typing import Any, Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.export.kml import zone_holes, zone_outline
from auvplan.export.plan import ExportPlan, utc_text
from auvplan.export.waypoints import Waypoints

#: Decimals of the coordinates [deg]: 1e-7 deg is about 1 cm.
DECIMALS: Final = 7


def _positions(
    lon: FloatArray, lat: FloatArray, depth: FloatArray | None = None
) -> list[list[float]]:
    columns = [lon, lat] if depth is None else [lon, lat, 0.0 - depth]
    positions: list[list[float]] = np.round(np.column_stack(columns), DECIMALS).tolist()
    return positions


def _collection(features: list[dict[str, Any]]) -> str:
    document = {"type": "FeatureCollection", "features": features}
    return json.dumps(document, indent=1, allow_nan=False) + "\n"


def trajectory_features(plan: ExportPlan, fleet: Sequence[Waypoints]) -> list[dict[str, Any]]:
    """One ``LineString`` feature per vehicle (module notes)."""
    return [
        {
            "type": "Feature",
            "properties": {
                "name": waypoints.name,
                "depth_m": float(np.max(plan.waypoint_depths(waypoints))),
                "start_time": utc_text(plan.timestamp(waypoints.time[0])),
                "end_time": utc_text(plan.timestamp(waypoints.time[-1])),
                "times": [utc_text(plan.timestamp(seconds)) for seconds in waypoints.time],
                "t_s": waypoints.time.tolist(),
                "leg_speed_m_s": waypoints.leg_speeds.tolist(),
            },
            "geometry": {
                "type": "LineString",
                "coordinates": _positions(*waypoints.geographic()[::-1], waypoints.depth),
            },
        }
        for waypoints in fleet
    ]


def waypoint_features(plan: ExportPlan, fleet: Sequence[Waypoints]) -> list[dict[str, Any]]:
    """One ``Point`` feature per waypoint, with its time (module notes)."""
    features = []
    for waypoints in fleet:
        speeds = [*waypoints.leg_speeds.tolist(), 0.0]  # the last waypoint: arrived
        depths = plan.waypoint_depths(waypoints)
        positions = _positions(*waypoints.geographic()[::-1], waypoints.depth)
        for k, position in enumerate(positions):
            properties = {
                "name": waypoints.name,
                "waypoint": k,
                "time": utc_text(plan.timestamp(waypoints.time[k])),
                "t_s": float(waypoints.time[k]),
                "speed_m_s": speeds[k],
                "depth_m": float(depths[k]),
            }
            geometry = {"type": "Point", "coordinates": position}
            features.append({"type": "Feature", "properties": properties, "geometry": geometry})
    return features


def obstacle_features(plan: ExportPlan) -> list[dict[str, Any]]:
    """One ``Polygon`` feature per keep-out zone, holes included.

    Exterior rings are counter-clockwise and holes clockwise (RFC 7946 §3.1.6).
    """

    def wound(outline: list[tuple[float, float]], counter_clockwise: bool) -> list[list[float]]:
        ring = np.array(outline)
        lon, lat = ring[:, 0], ring[:, 1]
        area = np.dot(lon, np.roll(lat, -1)) - np.dot(lat, np.roll(lon, -1))
        if (area > 0.0) != counter_clockwise:
            lon, lat = lon[::-1], lat[::-1]
        return _positions(lon, lat)

    features = []
    for zone in plan.zones:
        rings = [wound(zone_outline(zone), True), *(wound(h, False) for h in zone_holes(zone))]
        geometry = {"type": "Polygon", "coordinates": rings}
        properties = {"name": zone.name, "kind": "keep-out"}
        features.append({"type": "Feature", "properties": properties, "geometry": geometry})
    return features


def render(plan: ExportPlan, fleet: Sequence[Waypoints]) -> dict[str, str]:
    """``trajectories.geojson``, ``waypoints.geojson``, with obstacles ``obstacles.geojson``."""
    files = {
        "trajectories.geojson": _collection(trajectory_features(plan, fleet)),
        "waypoints.geojson": _collection(waypoint_features(plan, fleet)),
    }
    if plan.zones:
        files["obstacles.geojson"] = _collection(obstacle_features(plan))
    return files


__all__ = [
    "DECIMALS",
    "obstacle_features",
    "render",
    "trajectory_features",
    "waypoint_features",
]
