"""A plan with a depth profile: every export carries each waypoint's own depth."""

from __future__ import annotations

import dataclasses
import json
from xml.etree import ElementTree

import gpxpy
import numpy as np
import pytest

from auvplan.export import render_exports
from auvplan.export.moos import LEG_VARIABLE
from auvplan.export.plan import ExportPlan, file_stems
from auvplan.export.waypoints import Waypoints, thin_track

from ._plans import synthetic_plan
from ._readers import parse_moos, validate_json

TOLERANCE = 0.5
GX = "{http://www.google.com/kml/ext/2.2}"


def _profiled_plan() -> ExportPlan:
    """The synthetic plan with depths of 5 to 11 m varying along each track."""
    plan = synthetic_plan()
    tracks = tuple(
        dataclasses.replace(track, depth=8.0 + 3.0 * np.sin(track.time / 17.0 + k))
        for k, track in enumerate(plan.tracks)
    )
    return dataclasses.replace(plan, tracks=tracks)


@pytest.fixture(scope="module")
def plan() -> ExportPlan:
    return _profiled_plan()


@pytest.fixture(scope="module")
def fleet(plan: ExportPlan) -> list[Waypoints]:
    return [thin_track(track, TOLERANCE) for track in plan.tracks]


def _depths(plan: ExportPlan, waypoints: Waypoints) -> np.ndarray:
    """The track's depth at each waypoint, taken from the track (not the exporter)."""
    (track,) = [track for track in plan.tracks if track.name == waypoints.name]
    assert track.depth is not None
    depth = track.depth[waypoints.index]
    assert np.ptp(depth) > 1.0  # the waypoints really differ in depth
    return depth


def test_gpx_and_kml_elevations_are_minus_each_waypoint_depth(
    plan: ExportPlan, fleet: list[Waypoints]
) -> None:
    files = render_exports(plan, ["gpx", "kml"], tolerance=TOLERANCE)
    gpx = gpxpy.parse(files["trajectories.gpx"])
    kml = ElementTree.fromstring(files["trajectories.kml"])
    tracks = kml.iter(f"{GX}Track")
    for track, kml_track, waypoints in zip(gpx.tracks, tracks, fleet, strict=True):
        depth = _depths(plan, waypoints)
        elevation = np.array([point.elevation for point in track.segments[0].points])
        np.testing.assert_allclose(elevation, -depth, atol=1e-4)  # written with %g
        coords = [c.text.split() for c in kml_track.iter(f"{GX}coord") if c.text]
        np.testing.assert_allclose([float(c[2]) for c in coords], -depth, rtol=1e-15)


def test_geojson_waypoints_and_lines_carry_each_depth(
    plan: ExportPlan, fleet: list[Waypoints]
) -> None:
    files = render_exports(plan, ["geojson"], tolerance=TOLERANCE)
    points = validate_json(files["waypoints.geojson"], "geojson_waypoints")["features"]
    lines = validate_json(files["trajectories.geojson"], "geojson_trajectories")["features"]
    for line, waypoints in zip(lines, fleet, strict=True):
        depth = _depths(plan, waypoints)
        own = [p for p in points if p["properties"]["name"] == waypoints.name]
        np.testing.assert_allclose([p["properties"]["depth_m"] for p in own], depth)
        np.testing.assert_allclose(
            [p["geometry"]["coordinates"][2] for p in own], -depth, atol=1e-7
        )
        np.testing.assert_allclose(
            [position[2] for position in line["geometry"]["coordinates"]], -depth, atol=1e-7
        )
        assert line["properties"]["depth_m"] == pytest.approx(depth.max())


def test_qgc_items_and_imc_points_carry_each_depth(
    plan: ExportPlan, fleet: list[Waypoints]
) -> None:
    files = render_exports(plan, ["qgc", "imc"], tolerance=TOLERANCE)
    stems = file_stems([track.name for track in plan.tracks])
    for stem, waypoints in zip(stems, fleet, strict=True):
        depth = _depths(plan, waypoints)
        items = validate_json(files[f"{stem}.plan"], "qgc_plan")["mission"]["items"]
        altitude = [item["params"][6] for item in items if item["command"] == 16]
        np.testing.assert_allclose(altitude, -depth)
        assert [item["Altitude"] for item in items if item["command"] == 16] == altitude
        message = json.loads(files[f"{stem}.imc.json"])
        trajectory = message["maneuvers"][0]["data"]
        offsets = [point["z"] for point in trajectory["points"]]
        assert trajectory["z"] == pytest.approx(depth[0])
        np.testing.assert_allclose(trajectory["z"] + np.array(offsets), depth)


def test_moos_sets_each_legs_depth_while_the_leg_is_flown(
    plan: ExportPlan, fleet: list[Waypoints]
) -> None:
    files = render_exports(plan, ["moos"], tolerance=TOLERANCE)
    stems = file_stems([track.name for track in plan.tracks])
    for stem, waypoints in zip(stems, fleet, strict=True):
        depth = _depths(plan, waypoints)
        _, blocks = parse_moos(files[f"{stem}.bhv"])
        legs = {
            block["condition"].split(" & ")[1]: block
            for block in blocks
            if block["Behavior"] in ("BHV_Waypoint", "BHV_Timer")
        }
        depths = {
            block["condition"].split(" & ")[1]: float(block["depth"])
            for block in blocks
            if block["Behavior"] == "BHV_ConstantDepth"
        }
        assert depths.keys() == legs.keys()  # one depth per leg, active with it
        ordered = [depths[f"{LEG_VARIABLE} = {k + 1}"] for k in range(len(legs))]
        np.testing.assert_allclose(ordered, depth[1:], atol=5e-3)  # written with 2 decimals


def test_a_constant_depth_plan_keeps_one_depth_behaviour() -> None:
    files = render_exports(synthetic_plan(), ["moos"], tolerance=TOLERANCE)
    _, blocks = parse_moos(files["blue.bhv"])
    (depth,) = [block for block in blocks if block["Behavior"] == "BHV_ConstantDepth"]
    assert float(depth["depth"]) == 3.0
