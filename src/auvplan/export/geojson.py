"""GeoJSON (RFC 7946) of the optimised trajectories: one ``LineString`` feature per vehicle.

Coordinates are ``[lon, lat]`` in WGS 84 (shapely's ``mapping``); the time law travels in the
feature's properties: ``times`` (UTC, ISO 8601), ``t_s`` (seconds after the start) per point,
``leg_speed_m_s`` per leg, and ``depth_m``.
"""

from __future__ import annotations

import json
from collections.abc import Sequence

from auvplan.export.plan import ExportPlan, utc_text
from auvplan.export.waypoints import Waypoints


def feature_collection(plan: ExportPlan, fleet: Sequence[Waypoints]) -> str:
    """The GeoJSON text of the fleet's waypoints."""
    from shapely import LineString
    from shapely.geometry import mapping

    features = [
        {
            "type": "Feature",
            "properties": {
                "name": waypoints.name,
                "depth_m": plan.depth,
                "start_time": utc_text(plan.start_time),
                "times": [utc_text(plan.timestamp(seconds)) for seconds in waypoints.time],
                "t_s": waypoints.time.tolist(),
                "leg_speed_m_s": waypoints.leg_speeds.tolist(),
            },
            "geometry": mapping(LineString(zip(waypoints.lon, waypoints.lat, strict=True))),
        }
        for waypoints in fleet
    ]
    collection = {"type": "FeatureCollection", "features": features}
    return json.dumps(collection, indent=1, allow_nan=False) + "\n"


def render(plan: ExportPlan, fleet: Sequence[Waypoints]) -> dict[str, str]:
    """``trajectories.geojson``."""
    return {"trajectories.geojson": feature_collection(plan, fleet)}


__all__ = ["feature_collection", "render"]
