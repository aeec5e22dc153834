"""Every export format read back by an independent reader carries the waypoints and times."""

from __future__ import annotations

import dataclasses
import json
import math
from datetime import datetime, timedelta
from xml.etree import ElementTree

import gpxpy
import numpy as np
import pytest
from pyproj import Geod, Proj

from auvplan.errors import InputError
from auvplan.export import FORMATS, parse_formats, qgc, render_exports
from auvplan.export.moos import moos_xy
from auvplan.export.plan import CircleZone, ExportPlan, PolygonZone, file_stems
from auvplan.export.waypoints import Waypoints, thin_track
from auvplan.terrain import LocalProjection

from ._plans import synthetic_plan
from ._readers import fly_moos, moos_points, parse_moos, validate_json

TOLERANCE = 0.5
GEOD = Geod(ellps="WGS84")
KML = "{http://www.opengis.net/kml/2.2}"
GX = "{http://www.google.com/kml/ext/2.2}"


def _fleet(plan: ExportPlan) -> list[Waypoints]:
    return [thin_track(track, TOLERANCE) for track in plan.tracks]


def _render(plan: ExportPlan, name: str) -> dict[str, str]:
    return render_exports(plan, [name], tolerance=TOLERANCE)


def _distance_m(
    lat_a: np.ndarray, lon_a: np.ndarray, lat_b: np.ndarray, lon_b: np.ndarray
) -> np.ndarray:
    return np.asarray(GEOD.inv(lon_a, lat_a, lon_b, lat_b)[2])


def _times(plan: ExportPlan, waypoints: Waypoints) -> list[datetime]:
    return [plan.start_time + timedelta(seconds=float(t)) for t in waypoints.time]


def test_gpx_tracks_read_by_gpxpy(export_plan: ExportPlan) -> None:
    text = _render(export_plan, "gpx")["trajectories.gpx"]
    assert ElementTree.fromstring(text).tag == "{http://www.topografix.com/GPX/1/1}gpx"
    gpx = gpxpy.parse(text)
    assert gpx.version == "1.1"
    assert len(gpx.tracks) == len(export_plan.tracks)
    for track, waypoints in zip(gpx.tracks, _fleet(export_plan), strict=True):
        assert track.name == waypoints.name  # "r&d <2>" escaped and read back
        points = track.segments[0].points
        lat = np.array([p.latitude for p in points])
        lon = np.array([p.longitude for p in points])
        assert np.max(_distance_m(lat, lon, waypoints.lat, waypoints.lon)) < 1e-3
        assert [p.time for p in points] == _times(export_plan, waypoints)
        assert {p.elevation for p in points} == {-export_plan.depth}


def test_kml_timed_tracks_and_obstacle_outlines(export_plan: ExportPlan) -> None:
    root = ElementTree.fromstring(_render(export_plan, "kml")["trajectories.kml"].encode())
    assert root.tag == f"{KML}kml"
    tracks = root.findall(f".//{GX}Track")
    assert len(tracks) == len(export_plan.tracks)
    names = [p.findtext(f"{KML}name") for p in root.iter(f"{KML}Placemark")]
    for track, waypoints in zip(tracks, _fleet(export_plan), strict=True):
        assert waypoints.name in names
        when = [datetime.fromisoformat(w.text or "") for w in track.findall(f"{KML}when")]
        coords = np.array([c.text.split() for c in track.findall(f"{GX}coord")], dtype=float)
        assert when == _times(export_plan, waypoints)
        assert np.max(_distance_m(coords[:, 1], coords[:, 0], waypoints.lat, waypoints.lon)) < 1e-6
        np.testing.assert_array_equal(coords[:, 2], -export_plan.depth)
    outlines = {
        p.findtext(f"{KML}name"): np.array(
            [c.split(",") for c in (p.findtext(f".//{KML}coordinates") or "").split()], dtype=float
        )
        for p in root.iter(f"{KML}Placemark")
        if p.find(f".//{KML}Polygon") is not None
    }
    assert sorted(outlines) == sorted(zone.name for zone in export_plan.zones)
    for zone in export_plan.zones:
        ring = outlines[zone.name]
        if isinstance(zone, CircleZone):
            centre = (np.full(len(ring), zone.lat), np.full(len(ring), zone.lon))
            radius = _distance_m(*centre, ring[:, 1], ring[:, 0])
            np.testing.assert_allclose(radius, zone.radius, atol=1e-3)
        else:
            np.testing.assert_allclose(ring[:-1, 1], zone.lat)
            np.testing.assert_allclose(ring[:-1, 0], zone.lon)


def test_kml_validates_against_the_ogc_schema(export_plan: ExportPlan) -> None:
    """OGC KML 2.2 + Google extension XSDs (shipped by fastkml), and fastkml's strict reader."""
    from fastkml import KML as FastKML
    from fastkml.validator import get_schema_parser
    from lxml import etree

    text = _render(export_plan, "kml")["trajectories.kml"]
    schema = get_schema_parser()
    document = etree.fromstring(text.encode())
    assert schema.validate(document), [error.message for error in schema.error_log]
    parsed = FastKML.from_string(etree.tostring(document, encoding="unicode"), strict=True)
    (kml_document,) = parsed.features
    placemarks = [p for folder in kml_document.features for p in folder.features]
    names = [placemark.name for placemark in placemarks]
    assert names == [t.name for t in export_plan.tracks] + [z.name for z in export_plan.zones]


def test_qgc_numbers_are_mavlinks() -> None:
    """Every MAVLink number of the QGC export, checked against pymavlink's enums."""
    from pymavlink.dialects.v20 import ardupilotmega as mavlink

    assert qgc.NAV_WAYPOINT == mavlink.MAV_CMD_NAV_WAYPOINT
    assert qgc.DO_CHANGE_SPEED == mavlink.MAV_CMD_DO_CHANGE_SPEED
    assert qgc.FRAME_GLOBAL_RELATIVE_ALT == mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT
    assert qgc.FRAME_MISSION == mavlink.MAV_FRAME_MISSION
    assert qgc.FIRMWARE_ARDUPILOT == mavlink.MAV_AUTOPILOT_ARDUPILOTMEGA
    assert qgc.VEHICLE_SUBMARINE == mavlink.MAV_TYPE_SUBMARINE


def test_qgc_surface_plan_is_not_keep_current_depth() -> None:
    """ArduSub reads altitude 0 as "keep the current depth": a surface plan must not write 0."""
    plan = dataclasses.replace(synthetic_plan(), depth=0.0)
    document = json.loads(render_exports(plan, ["qgc"])["blue.plan"])
    nav = [item for item in document["mission"]["items"] if item["command"] == 16]
    assert {item["params"][6] for item in nav} == {-0.01}
    assert {item["Altitude"] for item in nav} == {-0.01}


def test_qgc_plans_for_ardusub(export_plan: ExportPlan) -> None:
    files = _render(export_plan, "qgc")
    stems = file_stems([track.name for track in export_plan.tracks])
    assert sorted(files) == sorted(f"{stem}.plan" for stem in stems)
    for stem, waypoints in zip(stems, _fleet(export_plan), strict=True):
        document = validate_json(files[f"{stem}.plan"], "qgc_plan")
        mission = document["mission"]
        assert (mission["firmwareType"], mission["vehicleType"]) == (3, 12)
        items = mission["items"]
        assert [item["doJumpId"] for item in items] == list(range(1, len(items) + 1))
        nav = [item for item in items if item["command"] == 16]
        lat, lon = (np.array([item["params"][k] for item in nav]) for k in (4, 5))
        assert np.max(_distance_m(lat, lon, waypoints.lat, waypoints.lon)) < 1e-6
        # a surface plan (the Monterey example) 1 cm down: ArduSub reads 0 as "keep depth"
        altitude = -max(export_plan.depth, qgc.SURFACE_DEPTH)
        assert all(item["frame"] == 3 and item["params"][6] == altitude for item in nav)
        assert all(item["Altitude"] == altitude for item in nav)  # QGC 4.x keys
        assert all((item["AltitudeMode"], item["AMSLAltAboveTerrain"]) == (1, None) for item in nav)
        assert mission["globalPlanAltitudeMode"] == 1
        # fly the items: hold, then each leg at the last commanded speed: the plan's times
        speed, clock, arrivals, last = None, 0.0, [], None
        for item in items:
            if item["command"] == 178:
                assert item["frame"] == 2
                assert item["params"][0] == 1
                speed = item["params"][1]
                continue
            if last is not None:
                length = _distance_m(
                    *(np.array([x["params"][k]]) for x in (last, item) for k in (4, 5))
                )
                clock += last["params"][0] + (float(length[0]) / speed if length[0] > 0 else 0.0)
            arrivals.append(clock)
            last = item
        np.testing.assert_allclose(arrivals, waypoints.time - waypoints.time[0], atol=0.01)
        fence = document["geoFence"]
        assert not any(zone["inclusion"] for zone in fence["circles"] + fence["polygons"])
        circles = [zone for zone in export_plan.zones if isinstance(zone, CircleZone)]
        assert [(c["circle"]["center"], c["circle"]["radius"]) for c in fence["circles"]] == [
            ([zone.lat, zone.lon], zone.radius) for zone in circles
        ]
        polygons = [zone for zone in export_plan.zones if isinstance(zone, PolygonZone)]
        assert len(fence["polygons"]) == len(polygons)
        for polygon, zone in zip(fence["polygons"], polygons, strict=True):
            vertices = np.array(polygon["polygon"])  # [lat, lon], clockwise on the map
            lat, lon = vertices[:, 0], vertices[:, 1]
            assert np.dot(lon, np.roll(lat, -1)) - np.dot(lat, np.roll(lon, -1)) < 0.0
            assert sorted(map(tuple, vertices)) == sorted(zip(zone.lat, zone.lon, strict=True))


#: Field names of IMC.xml v5.4.31 (LSTS/imc): the header and the messages the export writes.
IMC_FIELDS = {
    "PlanSpecification": (
        *("mgid", "timestamp", "src", "src_ent", "dst", "dst_ent"),  # header, less sync/size
        *("plan_id", "description", "vnamespace", "variables", "start_man_id", "maneuvers"),
        *("transitions", "start_actions", "end_actions"),
    ),
    "FollowTrajectory": (
        *("timeout", "lat", "lon", "z", "z_units", "speed", "speed_units", "points", "custom"),
    ),
    "TrajectoryPoint": ("x", "y", "z", "t"),
}


def test_imc_follow_trajectory_plans(export_plan: ExportPlan) -> None:
    files = _render(export_plan, "imc")
    stems = file_stems([track.name for track in export_plan.tracks])
    for stem, waypoints in zip(stems, _fleet(export_plan), strict=True):
        document = validate_json(files[f"{stem}.imc.json"], "imc_plan")
        assert document["plan_id"] == waypoints.name
        assert document["timestamp"] == export_plan.start_time.timestamp()
        assert set(IMC_FIELDS["PlanSpecification"]) <= set(document)
        (maneuver,) = document["maneuvers"]
        assert maneuver["maneuver_id"] == document["start_man_id"]
        data = maneuver["data"]
        assert set(data) == {"abbrev", *IMC_FIELDS["FollowTrajectory"]}
        assert all(set(p) == {"abbrev", *IMC_FIELDS["TrajectoryPoint"]} for p in data["points"])
        lat_0, lon_0 = math.degrees(data["lat"]), math.degrees(data["lon"])
        assert (data["z"], data["z_units"], data["speed_units"]) == (export_plan.depth, 1, 0)
        points = data["points"]
        np.testing.assert_allclose(np.cumsum([p["t"] for p in points]), waypoints.time)
        lat, lon = LocalProjection(lat_0, lon_0).to_geographic(
            np.array([p["x"] for p in points]), np.array([p["y"] for p in points])
        )
        assert np.max(_distance_m(lat, lon, waypoints.lat, waypoints.lon)) < 1e-6
        assert data["timeout"] >= waypoints.time[-1]


def _utm_offsets(plan: ExportPlan, lat: np.ndarray, lon: np.ndarray) -> np.ndarray:
    """MOOSGeodesy's LatLong2LocalUTM, independently: PROJ's UTM of the origin's zone."""
    zone = int((plan.origin_lon + 180.0) // 6.0) + 1
    utm = Proj(proj="utm", zone=zone, ellps="WGS84", south=plan.origin_lat < 0.0)
    east_0, north_0 = utm(plan.origin_lon, plan.origin_lat)
    east, north = utm(lon, lat)
    return np.column_stack([np.asarray(east) - east_0, np.asarray(north) - north_0])


@pytest.mark.parametrize("frame", ["utm", "local"])
def test_moos_flies_the_plans_path_and_timing(export_plan: ExportPlan, frame: str) -> None:
    files = render_exports(export_plan, ["moos"], tolerance=TOLERANCE, moos_frame=frame)
    origin, _ = parse_moos(files["origin.moos"])
    lat_0, lon_0 = float(origin["LatOrigin"]), float(origin["LongOrigin"])
    assert (lat_0, lon_0) == pytest.approx(
        (export_plan.origin_lat, export_plan.origin_lon), abs=1e-9
    )
    stems = file_stems([track.name for track in export_plan.tracks])
    for stem, waypoints in zip(stems, _fleet(export_plan), strict=True):
        settings, blocks = parse_moos(files[f"{stem}.bhv"])
        assert settings["initialize DEPLOY"] == "false"
        assert settings["initialize RETURN"] == "false"
        depths = [block for block in blocks if block["Behavior"] == "BHV_ConstantDepth"]
        if export_plan.depth > 0.0:
            (depth,) = depths
            assert float(depth["depth"]) == export_plan.depth
            assert depth["condition"] == "DEPLOY = true"
        else:  # a surface plan (the Monterey example): a surface helm has no depth variable
            assert depths == []
        legs = [block for block in blocks if block["Behavior"] == "BHV_Waypoint"]
        assert all(float(leg["capture_radius"]) == export_plan.capture_radius for leg in legs)
        assert all(float(leg["slip_radius"]) > export_plan.capture_radius for leg in legs)
        if frame == "utm":
            expected = _utm_offsets(export_plan, waypoints.lat, waypoints.lon)
        else:
            north, east = LocalProjection(lat_0, lon_0).to_local(waypoints.lat, waypoints.lon)
            expected = np.column_stack([east, north])
        flown = np.array(fly_moos(settings, blocks, start=tuple(expected[0])))
        # every waypoint in order, to 1 cm; a wait holds the position
        np.testing.assert_allclose(flown[:, 1:], expected, atol=0.01)
        # at the plan's times: leg speeds are true speeds, the grid scale differs by < 1e-3
        duration = waypoints.time[-1] - waypoints.time[0]
        planned = waypoints.time - waypoints.time[0]
        np.testing.assert_allclose(flown[:, 0], planned, atol=1e-3 * duration + 0.01)


def test_moos_utm_frame_is_not_the_tangent_plane_away_from_the_origin() -> None:
    """Near Monterey the two frames part by ≈ 1.2 % of the distance: UTM is MOOS-IvP's default."""
    plan = synthetic_plan()
    lat, lon = LocalProjection(plan.origin_lat, plan.origin_lon).to_geographic(
        np.array([300.0]), np.array([400.0])
    )
    utm = np.column_stack(moos_xy(plan, lat, lon, "utm"))
    local = np.column_stack(moos_xy(plan, lat, lon, "local"))
    np.testing.assert_allclose(local, [[400.0, 300.0]], atol=1e-6)
    np.testing.assert_allclose(utm, _utm_offsets(plan, lat, lon), atol=1e-3)
    assert 4.0 < float(np.hypot(*(utm - local)[0])) < 8.0
    with pytest.raises(InputError, match="MOOS frame 'grid'"):
        render_exports(plan, ["moos"], moos_frame="grid")  # type: ignore[arg-type]


def test_geojson_trajectories(export_plan: ExportPlan) -> None:
    document = validate_json(
        _render(export_plan, "geojson")["trajectories.geojson"], "geojson_trajectories"
    )
    for feature, waypoints in zip(document["features"], _fleet(export_plan), strict=True):
        properties = feature["properties"]
        assert properties["name"] == waypoints.name
        lon, lat = np.array(feature["geometry"]["coordinates"]).T
        np.testing.assert_allclose(lat, waypoints.lat, atol=0.6e-7)  # 7 decimals: ≈ 1 cm
        np.testing.assert_allclose(lon, waypoints.lon, atol=0.6e-7)
        times = _times(export_plan, waypoints)
        assert [datetime.fromisoformat(t) for t in properties["times"]] == times
        assert datetime.fromisoformat(properties["end_time"]) == times[-1]
        np.testing.assert_array_equal(properties["t_s"], waypoints.time)
        np.testing.assert_allclose(properties["leg_speed_m_s"], waypoints.leg_speeds)


def test_geojson_waypoints_carry_their_own_times(export_plan: ExportPlan) -> None:
    """One timed point per waypoint: what QGIS's temporal controller animates."""
    document = validate_json(
        _render(export_plan, "geojson")["waypoints.geojson"], "geojson_waypoints"
    )
    features = document["features"]
    for waypoints in _fleet(export_plan):
        mine = [f for f in features if f["properties"]["name"] == waypoints.name]
        assert [f["properties"]["waypoint"] for f in mine] == list(range(len(waypoints.time)))
        times = [datetime.fromisoformat(f["properties"]["time"]) for f in mine]
        assert times == _times(export_plan, waypoints)
        lon, lat = np.array([f["geometry"]["coordinates"] for f in mine]).T
        assert np.max(_distance_m(lat, lon, waypoints.lat, waypoints.lon)) < 0.02
        speeds = [f["properties"]["speed_m_s"] for f in mine]
        np.testing.assert_allclose(speeds[:-1], waypoints.leg_speeds)
    coordinates = np.array([f["geometry"]["coordinates"] for f in features])
    np.testing.assert_array_equal(coordinates, np.round(coordinates, 7))


def test_geojson_obstacles_are_closed_counter_clockwise_rings(export_plan: ExportPlan) -> None:
    files = _render(export_plan, "geojson")
    if not export_plan.zones:
        assert "obstacles.geojson" not in files
        return
    document = validate_json(files["obstacles.geojson"], "geojson_obstacles")
    names = [feature["properties"]["name"] for feature in document["features"]]
    assert names == [zone.name for zone in export_plan.zones]
    for feature, zone in zip(document["features"], export_plan.zones, strict=True):
        ring = np.array(feature["geometry"]["coordinates"][0])
        assert ring[0].tolist() == ring[-1].tolist()
        lon, lat = ring[:, 0], ring[:, 1]
        assert np.dot(lon, np.roll(lat, -1)) - np.dot(lat, np.roll(lon, -1)) > 0.0  # CCW
        if isinstance(zone, CircleZone):
            centre = (np.full(len(ring), zone.lat), np.full(len(ring), zone.lon))
            radius = _distance_m(*centre, lat, lon)
            np.testing.assert_allclose(radius, zone.radius, atol=0.02)


def test_every_format_renders_its_files(export_plan: ExportPlan) -> None:
    files = set(render_exports(export_plan, FORMATS))
    stems = file_stems([track.name for track in export_plan.tracks])
    per_vehicle = {f"{stem}.{suffix}" for stem in stems for suffix in ("bhv", "plan", "imc.json")}
    shared = {"origin.moos", "trajectories.gpx", "trajectories.kml", "trajectories.geojson"}
    shared |= {"waypoints.geojson"} | ({"obstacles.geojson"} if export_plan.zones else set())
    assert files == per_vehicle | shared


def test_file_stems_are_safe_and_unique() -> None:
    assert file_stems(["blue", "r&d <2>", "r&d_<2>", ".hidden"]) == (
        "blue", "r_d__2_", "r_d__2_-2", "hidden",
    )  # fmt: skip


@pytest.mark.parametrize("text", ["gpx,shp", "", " , "])
def test_unknown_formats_are_named(text: str) -> None:
    with pytest.raises(InputError, match="export format"):
        parse_formats(text)


def test_without_geographic_reference_only_moos_in_the_local_frame_is_written() -> None:
    """The synthetic bank's plans: every format that needs lat/lon refused by name; MOOS-IvP's
    local frame flies the plan's own north/east, the points the georeferenced plan gets."""
    plan = synthetic_plan()
    tracks = tuple(dataclasses.replace(track, lat=None, lon=None) for track in plan.tracks)
    local = dataclasses.replace(plan, tracks=tracks, origin_lat=None, origin_lon=None, zones=())
    assert plan.is_georeferenced
    assert not local.is_georeferenced
    for name in FORMATS:
        frame = "utm" if name == "moos" else "local"
        with pytest.raises(InputError, match=rf"^{name} export needs lat/lon, but") as info:
            render_exports(local, [name], moos_frame=frame)
        assert ("--moos-frame local" in str(info.value)) == (name == "moos")
    files = render_exports(local, ["moos"], tolerance=TOLERANCE, moos_frame="local")
    same = render_exports(plan, ["moos"], tolerance=TOLERANCE, moos_frame="local")
    assert "LatOrigin" not in parse_moos(files["origin.moos"])[0]
    stems = file_stems([track.name for track in plan.tracks])
    for stem, waypoints in zip(stems, _fleet(local), strict=True):
        settings, blocks = parse_moos(files[f"{stem}.bhv"])
        expected = np.column_stack([waypoints.east, waypoints.north])
        flown = np.array(fly_moos(settings, blocks, start=tuple(expected[0])))
        np.testing.assert_allclose(flown[:, 1:], expected, atol=0.01)
        planned = waypoints.time - waypoints.time[0]  # speeds written to 1 mm/s
        np.testing.assert_allclose(flown[:, 0], planned, atol=1e-3 * planned[-1] + 0.01)
        _, georeferenced = parse_moos(same[f"{stem}.bhv"])
        points = [moos_points(block["points"]) for block in blocks if "points" in block]
        expected_points = [moos_points(b["points"]) for b in georeferenced if "points" in b]
        np.testing.assert_allclose(points, expected_points, atol=0.011)  # written to 1 cm
