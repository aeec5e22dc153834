"""MOOS-IvP: one ``BHV_Waypoint`` behaviour file per vehicle and the ``.moos`` origin lines.

pHelmIvP reads waypoints in a local frame of metres, ``x`` east and ``y`` north of the
``LatOrigin``/``LongOrigin`` declared in the community's ``.moos`` file. The origin written is
that of the plan's local frame (the map's south-west corner), and the waypoints are projected
into a transverse Mercator tangent at that origin, so ``x, y`` agree with the plan's
``east, north`` to well under a centimetre over a few kilometres.

``BHV_Waypoint`` has one speed: the vehicle's mean speed along its waypoints (arrival on time);
the per-leg times and speeds that keep the full time law are listed in comments. The capture
radius is the fleet's safety radius ``r_c``, the slip radius three times that (MOOS-IvP's
defaults, 3 m and 15 m, keep the same ratio order).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from auvplan import __version__
from auvplan.export.plan import ExportPlan, utc_text
from auvplan.export.waypoints import Waypoints, by_file_stem
from auvplan.terrain.projection import LocalProjection

#: Slip radius as a multiple of the capture radius.
SLIP_FACTOR = 3.0


def local_xy(plan: ExportPlan, waypoints: Waypoints) -> tuple[np.ndarray, np.ndarray]:
    """``x`` east and ``y`` north [m] of the waypoints from the MOOS origin."""
    north, east = LocalProjection(plan.origin_lat, plan.origin_lon).to_local(
        waypoints.lat, waypoints.lon
    )
    return east, north


def behavior_block(plan: ExportPlan, waypoints: Waypoints, *, name: str) -> str:
    """The ``Behavior = BHV_Waypoint { ... }`` block ``name`` of one vehicle, with its legs."""
    x, y = local_xy(plan, waypoints)
    legs = [
        f"//   leg {k + 1}: {length:.2f} m in {duration:.2f} s at {speed:.3f} m/s "
        f"(reach by t = {end:.2f} s)"
        for k, (length, duration, speed, end) in enumerate(
            zip(
                waypoints.leg_lengths,
                waypoints.leg_durations,
                waypoints.leg_speeds,
                waypoints.time[1:],
                strict=True,
            )
        )
    ]
    points = " : ".join(f"{east:.2f},{north:.2f}" for east, north in zip(x, y, strict=True))
    capture = plan.capture_radius
    title = f"// vehicle {waypoints.name}: auvplan {__version__} plan, {utc_text(plan.start_time)}"
    return "\n".join(
        [
            title,
            "// points: x = east, y = north [m] from LatOrigin/LongOrigin (origin.moos)",
            *legs,
            "Behavior = BHV_Waypoint",
            "{",
            f"  name           = {name}",
            "  pwt            = 100",
            "  condition      = DEPLOY = true",
            f"  speed          = {waypoints.mean_speed:.3f}",
            f"  capture_radius = {capture:g}",
            f"  slip_radius    = {SLIP_FACTOR * capture:g}",
            f"  points         = {points}",
            "}",
            "",
        ]
    )


def render(plan: ExportPlan, fleet: Sequence[Waypoints]) -> dict[str, str]:
    """``NAME.bhv`` per vehicle and ``origin.moos``."""
    files = {
        f"{stem}.bhv": behavior_block(plan, waypoints, name=f"{stem}_plan")
        for stem, waypoints in by_file_stem(fleet)
    }
    files["origin.moos"] = (
        f"// auvplan {__version__}: origin of the x (east) / y (north) frame of the .bhv files\n"
        f"LatOrigin  = {plan.origin_lat:.9f}\n"
        f"LongOrigin = {plan.origin_lon:.9f}\n"
    )
    return files


__all__ = ["SLIP_FACTOR", "behavior_block", "local_xy", "render"]
