"""MOOS-IvP: a pHelmIvP behaviour file per vehicle that flies the plan's path *and* timing.

**Frame.** pHelmIvP reads waypoints in metres, ``x`` east and ``y`` north of the
``LatOrigin``/``LongOrigin`` of the community's ``.moos`` file, converted by ``CMOOSGeodesy``.
MOOS-IvP's build script configures ``-DUSE_UTM=ON``, and the geodesy then uses
``LatLong2LocalUTM``: UTM coordinates in the zone of the origin minus those of the origin
(frame ``"utm"``, the default). A build without it uses ``LatLong2LocalGrid``, a local tangent
grid (frame ``"local"``: the plan's own transverse-Mercator tangent at the origin). The two
differ by the meridian convergence and the UTM scale (≈ 1.2 % of the distance from the
origin near Monterey: 6–7 m at 500 m), so the file says which it is. On terrain without
geographic reference (the synthetic bank) only the ``local`` frame exists: the points are the
plan's own north/east, and ``origin.moos`` asks for the ``LatOrigin``/``LongOrigin`` of the
grid's south-west corner instead of giving them.

**Timing.** ``BHV_Waypoint`` has one ``speed``. To keep the plan's time law (the
deconfliction's waits and speed changes), each leg is its own behaviour at that leg's speed,
and the legs are chained by a helm variable: leg ``k`` runs under ``condition = PLAN_LEG = k``
and posts ``endflag = PLAN_LEG = k+1`` when its waypoint is captured; a leg slower than
:data:`~auvplan.export.waypoints.STOP_SPEED` (a wait) is a ``BHV_Timer`` of the leg's
duration. The last leg posts ``PLAN_DONE = true``. Everything runs under
``condition = DEPLOY = true``, with ``initialize DEPLOY = false``, ``RETURN = false`` and
``PLAN_LEG = 1`` as in MOOS-IvP's example missions.

**Depth.** Below the surface a ``BHV_ConstantDepth`` holds the plan's depth for the whole
mission (``duration = no-time-limit``); a surface plan (depth 0) has none, as a surface
vehicle's helm has no depth decision variable.

The capture radius is the fleet's safety radius ``r_c``, the slip radius three times that
(MOOS-IvP's defaults, 3 m and 15 m, keep the same ratio order).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Final

import numpy as np
from pyproj import CRS, Transformer

from auvplan._typing import FloatArray
from auvplan._version import __version__
from auvplan.errors import InputError
from auvplan.export import MoosFrame, check_georeference, check_moos_frame
from auvplan.export.plan import ExportPlan, utc_text
from auvplan.export.waypoints import Waypoints, by_file_stem
from auvplan.terrain.projection import GEOGRAPHIC_CRS, LocalProjection

#: Slip radius as a multiple of the capture radius.
SLIP_FACTOR: Final = 3.0
#: The helm variable that chains the legs.
LEG_VARIABLE: Final = "PLAN_LEG"


def utm_crs(lat: float, lon: float) -> CRS:
    """The WGS 84 UTM zone of ``lat, lon`` [deg] (with the Norway and Svalbard exceptions).

    Examples
    --------
    >>> utm_crs(36.8, -121.9).to_epsg(), utm_crs(-38.5, 145.0).to_epsg()
    (32610, 32755)
    >>> utm_crs(60.0, 5.0).to_epsg(), utm_crs(78.0, 20.0).to_epsg()  # 32V, 33X
    (32632, 32633)
    """
    zone = int((lon + 180.0) // 6.0) % 60 + 1
    if 56.0 <= lat < 64.0 and 3.0 <= lon < 12.0:
        zone = 32
    elif 72.0 <= lat <= 84.0 and 0.0 <= lon < 42.0:
        zone = 31 + 2 * int((lon + 3.0) // 12.0)  # zones 31, 33, 35, 37
    return CRS.from_epsg((32600 if lat >= 0.0 else 32700) + zone)


def moos_xy(
    plan: ExportPlan, lat: FloatArray, lon: FloatArray, frame: MoosFrame = "utm"
) -> tuple[FloatArray, FloatArray]:
    """``x`` east and ``y`` north [m] of ``lat, lon`` [deg] in MOOS ``frame`` (module notes)."""
    lat_0, lon_0 = _origin(plan)
    if frame == "local":
        north, east = LocalProjection(lat_0, lon_0).to_local(lat, lon)
        return east, north
    check_moos_frame(frame)
    to_utm = Transformer.from_crs(GEOGRAPHIC_CRS, utm_crs(lat_0, lon_0), always_xy=True)
    east_0, north_0 = to_utm.transform(lon_0, lat_0)
    east, north = to_utm.transform(np.asarray(lon), np.asarray(lat))
    return np.asarray(east) - east_0, np.asarray(north) - north_0


def waypoint_xy(
    plan: ExportPlan, waypoints: Waypoints, frame: MoosFrame = "utm"
) -> tuple[FloatArray, FloatArray]:
    """``x`` east and ``y`` north [m] of the waypoints in MOOS ``frame``.

    Without geographic reference the plan's own ``east``, ``north`` (``local`` frame only).
    """
    if plan.is_georeferenced:
        return moos_xy(plan, *waypoints.geographic(), frame)
    check_georeference(["moos"], frame, "the plan's terrain")
    return waypoints.east, waypoints.north


def _origin(plan: ExportPlan) -> tuple[float, float]:
    """``LatOrigin``, ``LongOrigin`` [deg] of a georeferenced plan."""
    if plan.origin_lat is None or plan.origin_lon is None:
        raise InputError("the plan's terrain has no geographic reference: no LatOrigin/LongOrigin")
    return plan.origin_lat, plan.origin_lon


def frame_note(plan: ExportPlan, frame: MoosFrame) -> str:
    """One comment line naming the frame of the ``points``."""
    if not plan.is_georeferenced:
        return (
            "// points: the plan's own frame [m] (origin: the south-west corner of its terrain "
            "grid, which has no geographic reference), x = east, y = north"
        )
    if frame == "utm":
        zone = utm_crs(*_origin(plan)).utm_zone
        return (
            f"// points: UTM zone {zone} offsets [m] from LatOrigin/LongOrigin, x = east, "
            "y = north (CMOOSGeodesy::LatLong2LocalUTM, MOOS-IvP's default -DUSE_UTM=ON)"
        )
    return (
        "// points: local tangent grid [m] at LatOrigin/LongOrigin, x = east, y = north "
        "(CMOOSGeodesy::LatLong2LocalGrid, MOOS-IvP built with -DUSE_UTM=OFF)"
    )


def _block(kind: str, parameters: Sequence[tuple[str, str]]) -> list[str]:
    width = max(len(key) for key, _ in parameters)
    return [
        f"Behavior = {kind}",
        "{",
        *(f"  {key.ljust(width)} = {value}" for key, value in parameters),
        "}",
        "",
    ]


def behavior_file(
    plan: ExportPlan, waypoints: Waypoints, *, stem: str, frame: MoosFrame = "utm"
) -> str:
    """The ``.bhv`` file of one vehicle: initial values, depth, and one behaviour per leg."""
    x, y = waypoint_xy(plan, waypoints, frame)
    capture = plan.capture_radius
    n_legs = len(waypoints.leg_durations)
    lines = [
        f"// vehicle {waypoints.name}: auvplan {__version__} plan, {utc_text(plan.start_time)}",
        frame_note(plan, frame),
        (
            f"// start at {x[0]:.2f},{y[0]:.2f}; {n_legs} legs chained by {LEG_VARIABLE}, each "
            "at its own speed (waits as BHV_Timer), so the plan's timing is flown"
        ),
        "",
        "initialize DEPLOY = false",
        "initialize RETURN = false",
        f"initialize {LEG_VARIABLE} = 1",
        "",
    ]
    if plan.has_profile:
        lines += leg_depths(plan, waypoints, stem=stem)
    elif plan.depth > 0.0:
        lines += _block(
            "BHV_ConstantDepth",
            [
                ("name", f"{stem}_depth"),
                ("pwt", "100"),
                ("condition", "DEPLOY = true"),
                ("depth", f"{plan.depth:g}"),
                ("duration", "no-time-limit"),
            ],
        )
    waits = waypoints.waits
    for k in range(n_legs):
        then = f"{LEG_VARIABLE} = {k + 2}" if k + 1 < n_legs else "PLAN_DONE = true"
        timing = (
            f"// leg {k + 1}: {waypoints.leg_lengths[k]:.2f} m in "
            f"{waypoints.leg_durations[k]:.2f} s (reach by t = {waypoints.time[k + 1]:.2f} s)"
        )
        common = [("pwt", "100"), ("condition", "DEPLOY = true")]
        common += [("condition", f"{LEG_VARIABLE} = {k + 1}")]
        if waits[k]:
            lines += [timing]
            lines += _block(
                "BHV_Timer",
                [
                    ("name", f"{stem}_wait_{k + 1}"),
                    *common,
                    ("duration", f"{waypoints.leg_durations[k]:.2f}"),
                    ("duration_idle_decay", "false"),
                    ("endflag", then),
                ],
            )
        else:
            lines += [timing]
            lines += _block(
                "BHV_Waypoint",
                [
                    ("name", f"{stem}_leg_{k + 1}"),
                    *common,
                    ("speed", f"{waypoints.leg_speeds[k]:.3f}"),
                    ("capture_radius", f"{capture:g}"),
                    ("slip_radius", f"{SLIP_FACTOR * capture:g}"),
                    ("points", f"{x[k + 1]:.2f},{y[k + 1]:.2f}"),
                    ("endflag", then),
                ],
            )
    return "\n".join(lines)


def leg_depths(plan: ExportPlan, waypoints: Waypoints, *, stem: str) -> list[str]:
    """One ``BHV_ConstantDepth`` per leg of a depth profile: the depth of the leg's end.

    Each is active while its leg is (``LEG = k``), so the vehicle reaches each waypoint's
    planned depth [m] along the leg to it (the plan's profile keeps the climb and dive rates
    and the minimum altitude; :mod:`auvplan.mission.depth_profile`).
    """
    depths = plan.waypoint_depths(waypoints)
    lines = []
    for k in range(len(waypoints.leg_durations)):
        lines += _block(
            "BHV_ConstantDepth",
            [
                ("name", f"{stem}_depth_{k + 1}"),
                ("pwt", "100"),
                ("condition", "DEPLOY = true"),
                ("condition", f"{LEG_VARIABLE} = {k + 1}"),
                ("depth", f"{float(depths[k + 1]):.2f}"),
                ("duration", "no-time-limit"),
            ],
        )
    return lines


def render(
    plan: ExportPlan, fleet: Sequence[Waypoints], *, frame: MoosFrame = "utm"
) -> dict[str, str]:
    """``NAME.bhv`` per vehicle and ``origin.moos`` (the origin lines of the community)."""
    files = {
        f"{stem}.bhv": behavior_file(plan, waypoints, stem=stem, frame=frame)
        for stem, waypoints in by_file_stem(fleet)
    }
    origin = (
        [
            f"LatOrigin  = {plan.origin_lat:.9f}",
            f"LongOrigin = {plan.origin_lon:.9f}",
        ]
        if plan.is_georeferenced
        else [
            "// set LatOrigin and LongOrigin to where the grid's south-west corner lies, and use",
            "// a MOOS-IvP built with -DUSE_UTM=OFF (CMOOSGeodesy::LatLong2LocalGrid)",
        ]
    )
    files["origin.moos"] = "\n".join(
        [
            f"// auvplan {__version__}: origin of the x (east) / y (north) frame of the .bhv files",
            frame_note(plan, frame),
            *origin,
            "",
        ]
    )
    return files


__all__ = [
    "LEG_VARIABLE",
    "SLIP_FACTOR",
    "behavior_file",
    "moos_xy",
    "render",
    "utm_crs",
    "waypoint_xy",
]
