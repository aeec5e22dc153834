"""A zone's holes in the exports: GeoJSON rings (holes clockwise) and KML inner boundaries;
QGroundControl fences, which have no holes, keep the exterior."""

from __future__ import annotations

import dataclasses
import json
from xml.etree import ElementTree

import numpy as np

from auvplan.export import render_exports
from auvplan.export.plan import ExportPlan, PolygonZone
from auvplan.terrain import LocalProjection

from ._plans import ORIGIN, synthetic_plan
from ._readers import validate_json

KML = "{http://www.opengis.net/kml/2.2}"


def holed_plan() -> tuple[ExportPlan, np.ndarray]:
    """The synthetic plan with one more zone: a 60 m square with a 20 m square hole."""
    projection = LocalProjection(*ORIGIN)
    outer_lat, outer_lon = projection.to_geographic(
        np.array([200.0, 200.0, 260.0, 260.0]), np.array([50.0, 110.0, 110.0, 50.0])
    )
    hole_lat, hole_lon = projection.to_geographic(
        np.array([220.0, 240.0, 240.0, 220.0]), np.array([70.0, 70.0, 90.0, 90.0])
    )
    zone = PolygonZone("lagoon", outer_lat, outer_lon, ((hole_lat, hole_lon),))
    plan = synthetic_plan()
    return dataclasses.replace(plan, zones=(*plan.zones, zone)), np.column_stack(
        (hole_lon, hole_lat)
    )


def _signed_area(ring: np.ndarray) -> float:
    lon, lat = ring[:, 0], ring[:, 1]
    return float(np.dot(lon, np.roll(lat, -1)) - np.dot(lat, np.roll(lon, -1)))


def test_geojson_writes_holes_clockwise_inside_a_counter_clockwise_exterior() -> None:
    plan, hole = holed_plan()
    files = render_exports(plan, ["geojson"], tolerance=0.5)
    document = validate_json(files["obstacles.geojson"], "geojson_obstacles")
    lagoon = next(f for f in document["features"] if f["properties"]["name"] == "lagoon")
    exterior, inner = (np.array(ring) for ring in lagoon["geometry"]["coordinates"])
    assert _signed_area(exterior) > 0.0
    assert _signed_area(inner) < 0.0
    assert inner[0].tolist() == inner[-1].tolist()
    np.testing.assert_allclose(np.sort(inner[:-1], axis=0), np.sort(hole, axis=0), atol=1e-7)
    others = [f for f in document["features"] if f["properties"]["name"] != "lagoon"]
    assert all(len(f["geometry"]["coordinates"]) == 1 for f in others)


def test_kml_writes_holes_as_inner_boundaries() -> None:
    plan, hole = holed_plan()
    text = render_exports(plan, ["kml"], tolerance=0.5)["trajectories.kml"]
    root = ElementTree.fromstring(text)
    polygons = {
        placemark.find(f"{KML}name").text: placemark.find(f"{KML}Polygon")  # type: ignore[union-attr]
        for placemark in root.iter(f"{KML}Placemark")
        if placemark.find(f"{KML}Polygon") is not None
    }
    (inner,) = polygons["lagoon"].findall(f"{KML}innerBoundaryIs")  # type: ignore[union-attr]
    text_ring = inner.find(f"{KML}LinearRing/{KML}coordinates").text  # type: ignore[union-attr]
    ring = np.array([[float(v) for v in p.split(",")[:2]] for p in text_ring.split()])
    np.testing.assert_allclose(ring[:-1], hole, atol=1e-9)
    assert not polygons["wreck"].findall(f"{KML}innerBoundaryIs")  # type: ignore[union-attr]
    from fastkml.validator import get_schema_parser
    from lxml import etree

    schema = get_schema_parser()  # OGC KML 2.2
    assert schema.validate(etree.fromstring(text.encode())), list(schema.error_log)


def test_a_qgc_fence_keeps_the_exterior_of_a_holed_zone() -> None:
    plan, _ = holed_plan()
    files = render_exports(plan, ["qgc"], tolerance=0.5)
    fence = json.loads(next(iter(files.values())))["geoFence"]
    assert len(fence["polygons"]) == 2  # the wreck and the lagoon's exterior
    assert all(len(polygon["polygon"]) == 4 for polygon in fence["polygons"])


def test_summary_polygons_keep_their_holes_in_the_export_plan() -> None:
    from auvplan.record.export import _zone
    from auvplan.record.summary import PolygonObstacle

    def ring(corners: list[tuple[float, float]]) -> list[dict[str, float]]:
        return [{"north": 0.0, "east": 0.0, "lat": a, "lon": o} for a, o in corners]

    outer = [(36.0, -121.0), (36.0, -120.9), (36.1, -120.9)]
    hole = [(36.01, -120.95), (36.02, -120.95), (36.02, -120.94)]
    obstacle = PolygonObstacle.model_validate(
        {"name": "lagoon", "shape": "polygon", "vertices": ring(outer), "holes": [ring(hole)]}
    )
    zone = _zone(obstacle)
    assert isinstance(zone, PolygonZone)
    np.testing.assert_array_equal(zone.lat, [a for a, _ in outer])
    ((lat, lon),) = zone.holes
    np.testing.assert_array_equal(lat, [a for a, _ in hole])
    np.testing.assert_array_equal(lon, [o for _, o in hole])
