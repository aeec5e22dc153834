"""QGroundControl ``.plan`` files (JSON) for ArduSub, one per vehicle.

Format: QGroundControl developer guide, "Plan File Format" (plan version 1, mission version 2,
geofence version 2). The mission is for ArduPilot (``firmwareType`` 3 = MAV_AUTOPILOT_ARDUPILOTMEGA)
on a submarine (``vehicleType`` 12 = MAV_TYPE_SUBMARINE):

* a ``MAV_CMD_NAV_WAYPOINT`` (16) per waypoint, frame 3 (MAV_FRAME_GLOBAL_RELATIVE_ALT), params
  ``[hold, acceptance radius, pass radius 0, yaw unchanged (null), lat, lon, altitude]``;
  the altitude is the waypoint's depth (along a depth profile, its own) as a negative
  number, since ArduSub refuses a waypoint above home
  ("Alt above home must be negative"). ArduSub's ``do_nav_wp`` reads an altitude of exactly 0
  as "keep the current depth", so a surface plan (depth 0) is written at
  :data:`SURFACE_DEPTH` (1 cm, the resolution of ArduPilot's ``Location`` altitudes), which
  brings the vehicle up rather than leaving it wherever it is. QGroundControl 4.x reads the
  same altitude from the item's ``Altitude`` with ``AltitudeMode`` 1 (relative to home,
  ``globalPlanAltitudeMode`` 1) and ``AMSLAltAboveTerrain`` null;
* a ``MAV_CMD_DO_CHANGE_SPEED`` (178, frame 2 = MAV_FRAME_MISSION, params
  ``[1 = ground speed, speed, -1 = throttle unchanged, 0, 0, 0, 0]``) before each leg, so
  that the legs keep their durations; a leg slower than
  :data:`~auvplan.export.waypoints.STOP_SPEED` (a wait) is a hold [s] at its first waypoint
  instead;
* every obstacle as an exclusion geofence (``inclusion: false``): circles as circles, polygons
  with their vertices in clockwise order, as the format asks.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from typing import Any, Final

import numpy as np

from auvplan.export.plan import CircleZone, ExportPlan, PolygonZone
from auvplan.export.waypoints import Waypoints, by_file_stem

NAV_WAYPOINT: Final = 16
DO_CHANGE_SPEED: Final = 178
FRAME_GLOBAL_RELATIVE_ALT: Final = 3
FRAME_MISSION: Final = 2
FIRMWARE_ARDUPILOT: Final = 3
VEHICLE_SUBMARINE: Final = 12
#: QGroundControl's ``AltitudeMode`` of an item (and ``globalPlanAltitudeMode``): relative to home.
ALTITUDE_MODE_RELATIVE: Final = 1
#: Depth [m] written for a surface plan: ArduSub reads altitude 0 as "keep the current depth".
SURFACE_DEPTH: Final = 0.01


def _geofence(plan: ExportPlan) -> dict[str, Any]:
    circles, polygons = [], []
    for zone in plan.zones:
        if isinstance(zone, CircleZone):
            circles.append(
                {
                    "circle": {"center": [zone.lat, zone.lon], "radius": zone.radius},
                    "inclusion": False,
                    "version": 1,
                }
            )
        elif isinstance(zone, PolygonZone):
            lat, lon = zone.lat, zone.lon
            # shoelace area in (x = lon, y = lat): positive means counter-clockwise
            area = np.dot(lon, np.roll(lat, -1)) - np.dot(lat, np.roll(lon, -1))
            order = slice(None, None, -1) if area > 0.0 else slice(None)
            vertices = np.column_stack([lat, lon])[order]
            polygons.append({"inclusion": False, "polygon": vertices.tolist(), "version": 1})
    return {"circles": circles, "polygons": polygons, "version": 2}


def mission_items(plan: ExportPlan, waypoints: Waypoints) -> list[dict[str, Any]]:
    """The mission's simple items: waypoints (holding through waits), speed changes before legs."""
    speeds = waypoints.leg_speeds
    is_wait = waypoints.waits
    holds = np.append(np.where(is_wait, waypoints.leg_durations, 0.0), 0.0)
    commands: list[tuple[int, int, list[float | None]]] = []
    altitudes = 0.0 - np.maximum(plan.waypoint_depths(waypoints), SURFACE_DEPTH)
    lat, lon = waypoints.geographic()
    speed = None
    for k in range(waypoints.time.size):
        if k > 0 and not is_wait[k - 1]:
            leg_speed = float(speeds[k - 1])
            if leg_speed != speed:
                commands.append((DO_CHANGE_SPEED, FRAME_MISSION, [1, leg_speed, -1, 0, 0, 0, 0]))
                speed = leg_speed
        position = [float(lat[k]), float(lon[k]), float(altitudes[k])]
        parameters: list[float | None] = [float(holds[k]), plan.capture_radius, 0, None, *position]
        commands.append((NAV_WAYPOINT, FRAME_GLOBAL_RELATIVE_ALT, parameters))
    return [
        {
            "type": "SimpleItem",
            "autoContinue": True,
            "command": command,
            "doJumpId": number,
            "frame": frame,
            "params": parameters,
            **(
                {
                    "Altitude": parameters[6],
                    "AltitudeMode": ALTITUDE_MODE_RELATIVE,
                    "AMSLAltAboveTerrain": None,
                }
                if command == NAV_WAYPOINT
                else {}
            ),
        }
        for number, (command, frame, parameters) in enumerate(commands, start=1)
    ]


def plan_document(plan: ExportPlan, waypoints: Waypoints) -> dict[str, Any]:
    """The ``.plan`` document of one vehicle."""
    home_lat, home_lon = waypoints.geographic()
    return {
        "fileType": "Plan",
        "version": 1,
        "groundStation": "QGroundControl",
        "geoFence": _geofence(plan),
        "rallyPoints": {"points": [], "version": 2},
        "mission": {
            "version": 2,
            "firmwareType": FIRMWARE_ARDUPILOT,
            "globalPlanAltitudeMode": ALTITUDE_MODE_RELATIVE,
            "vehicleType": VEHICLE_SUBMARINE,
            "cruiseSpeed": waypoints.mean_speed,
            "hoverSpeed": waypoints.mean_speed,
            "plannedHomePosition": [float(home_lat[0]), float(home_lon[0]), 0],
            "items": mission_items(plan, waypoints),
        },
    }


def render(plan: ExportPlan, fleet: Sequence[Waypoints]) -> dict[str, str]:
    """``NAME.plan`` per vehicle."""
    return {
        f"{stem}.plan": json.dumps(plan_document(plan, waypoints), indent=2, allow_nan=False) + "\n"
        for stem, waypoints in by_file_stem(fleet)
    }


__all__ = ["mission_items", "plan_document", "render"]
