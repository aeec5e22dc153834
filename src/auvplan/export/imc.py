"""Neptus / IMC plans (JSON): one ``PlanSpecification`` with a ``FollowTrajectory`` per vehicle.

Message definitions: LSTS IMC (``IMC.xml``): ``FollowTrajectory`` (id 463) gives the start
point in WGS 84 **radians**, the depth ``z`` with ``z_units`` 1 (DEPTH), a speed with
``speed_units`` 0 (metres per second) and the list of ``TrajectoryPoint``: ``x`` north, ``y``
east, ``z`` down offsets [m] from the start point and ``t``, the time [s] after the previous
point, so that the vehicle follows the time law, not only the path. The offsets are taken in a
transverse Mercator tangent at the start point. The JSON layout is the one of LSTS's Neptus
integration (``abbrev`` names each message).

The top-level message carries IMC's header (``IMC.xml`` v5.4.31 ``<header>``): ``mgid`` 551
(PlanSpecification), ``timestamp`` (the plan's start, seconds since 1970 UTC) and the
"unknown" addresses ``src``/``dst`` 0xFFFF and entities ``src_ent``/``dst_ent`` 0xFF, which
the sending console replaces with its own and the vehicle's. With an IMC library the message is
serialised as is and sent to a DUNE vehicle in a ``PlanDB`` (``op`` SET) to store it, or a
``PlanControl`` (``op`` START) to run it; ``sync`` and ``size`` belong to the binary encoding
and are not written.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from typing import Any, Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.export.plan import ExportPlan
from auvplan.export.waypoints import Waypoints, by_file_stem
from auvplan.terrain.projection import LocalProjection

#: IMC message ids (``IMC.xml``).
PLAN_SPECIFICATION_ID: Final = 551
#: IMC's "unknown" system address and entity id: the sender fills in its own.
UNKNOWN_ADDRESS: Final = 0xFFFF
UNKNOWN_ENTITY: Final = 0xFF
Z_UNITS_DEPTH: Final = 1
SPEED_UNITS_METERS_PS: Final = 0
#: Manoeuvre timeout as a multiple of the trajectory's duration (IMC field ``timeout``, uint16).
TIMEOUT_FACTOR: Final = 1.5
MAX_TIMEOUT_S: Final = 65_535


def trajectory_points(waypoints: Waypoints, depths: FloatArray) -> list[dict[str, Any]]:
    """``TrajectoryPoint`` messages: offsets [m] from the first waypoint, ``t`` after the last.

    ``z`` is the down offset [m] of each waypoint's depth ``depths`` from the first's.
    """
    lat, lon = waypoints.geographic()
    north, east = LocalProjection(float(lat[0]), float(lon[0])).to_local(lat, lon)
    north, east = north - north[0], east - east[0]  # exactly 0 at the start (not 1e-9)
    steps = np.diff(waypoints.time, prepend=waypoints.time[0])
    return [
        {"abbrev": "TrajectoryPoint", "x": float(n), "y": float(e), "z": float(z), "t": float(t)}
        for n, e, z, t in zip(north, east, depths - depths[0], steps, strict=True)
    ]


def plan_specification(plan: ExportPlan, waypoints: Waypoints) -> dict[str, Any]:
    """The ``PlanSpecification`` of one vehicle."""
    duration = float(waypoints.time[-1] - waypoints.time[0])
    depths = plan.waypoint_depths(waypoints)
    lat, lon = waypoints.geographic()
    maneuver = {
        "abbrev": "FollowTrajectory",
        "timeout": min(MAX_TIMEOUT_S, math.ceil(TIMEOUT_FACTOR * duration)),
        "lat": math.radians(float(lat[0])),
        "lon": math.radians(float(lon[0])),
        "z": float(depths[0]),
        "z_units": Z_UNITS_DEPTH,
        "speed": waypoints.mean_speed,
        "speed_units": SPEED_UNITS_METERS_PS,
        "custom": "",
        "points": trajectory_points(waypoints, depths),
    }
    return {
        "abbrev": "PlanSpecification",
        "mgid": PLAN_SPECIFICATION_ID,
        "timestamp": plan.start_time.timestamp(),
        "src": UNKNOWN_ADDRESS,
        "src_ent": UNKNOWN_ENTITY,
        "dst": UNKNOWN_ADDRESS,
        "dst_ent": UNKNOWN_ENTITY,
        "plan_id": waypoints.name,
        "description": f"auvplan plan for {waypoints.name}, starting {plan.start_time.isoformat()}",
        "vnamespace": "",
        "variables": [],
        "start_man_id": "follow_trajectory",
        "maneuvers": [
            {
                "abbrev": "PlanManeuver",
                "maneuver_id": "follow_trajectory",
                "data": maneuver,
                "start_actions": [],
                "end_actions": [],
            }
        ],
        "transitions": [],
        "start_actions": [],
        "end_actions": [],
    }


def render(plan: ExportPlan, fleet: Sequence[Waypoints]) -> dict[str, str]:
    """``NAME.imc.json`` per vehicle."""
    return {
        f"{stem}.imc.json": json.dumps(plan_specification(plan, waypoints), indent=2) + "\n"
        for stem, waypoints in by_file_stem(fleet)
    }


__all__ = ["plan_specification", "render", "trajectory_points"]
