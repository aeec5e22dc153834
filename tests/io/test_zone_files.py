"""GIS zones: GeoJSON (EPSG:4326) and, with pyogrio, shapefiles and GeoPackages in any CRS,
read into the local frame with their holes; every bad file is one line naming it."""

from __future__ import annotations

import json
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import shapely
from pyproj import Transformer
from shapely.geometry import MultiPolygon, Point, Polygon, mapping

from auvplan.errors import DataFormatError, InputError
from auvplan.io.zones import read_zones
from auvplan.terrain import LocalProjection

PROJECTION = LocalProjection(36.79, -121.815)
#: A 100 m square with a 40 m square hole, north/east [m] in PROJECTION's frame.
SQUARE = np.array([[100.0, 100.0], [100.0, 200.0], [200.0, 200.0], [200.0, 100.0]])
HOLE = np.array([[130.0, 130.0], [130.0, 170.0], [170.0, 170.0], [170.0, 130.0]])


def lon_lat(ring: np.ndarray) -> list[tuple[float, float]]:
    """A local ring [m] as (lon, lat) [deg] vertices."""
    lat, lon = PROJECTION.to_geographic(ring[:, 0], ring[:, 1])
    return list(zip(lon.tolist(), lat.tolist(), strict=True))


def geographic_polygon(ring: np.ndarray = SQUARE, *holes: np.ndarray) -> Polygon:
    return Polygon(lon_lat(ring), [lon_lat(hole) for hole in holes])


def write_geojson(path: Path, *geometries: Any, ids: tuple[Any, ...] = ()) -> Path:
    features = [
        {"type": "Feature", "properties": {}, "geometry": mapping(geometry)}
        | ({"id": ids[k]} if k < len(ids) else {})
        for k, geometry in enumerate(geometries)
    ]
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


def write_ogr(path: Path, polygon: Polygon, crs: str | None, driver: str) -> Path:
    """``polygon`` (lon/lat) written with pyogrio in ``crs`` (None: no CRS)."""
    pyogrio = pytest.importorskip("pyogrio")
    if crs is not None:
        transformer = Transformer.from_crs("EPSG:4326", crs, always_xy=True)
        polygon = shapely.transform(
            polygon, lambda xy: np.column_stack(transformer.transform(*xy.T))
        )
    wkb = np.array([shapely.to_wkb(polygon)], dtype=object)
    with warnings.catch_warnings():  # pyogrio warns of a file written without a CRS
        warnings.simplefilter("ignore", UserWarning)
        pyogrio.raw.write(path, wkb, [], [], geometry_type="Polygon", crs=crs, driver=driver)
    return path


def assert_same_ring(ring: np.ndarray, expected: np.ndarray, tol: float = 1e-3) -> None:
    """Same polygon boundary (vertex order and start may differ) to ``tol`` [m]."""
    got = Polygon(ring[:, ::-1])
    want = Polygon(expected[:, ::-1])
    assert got.symmetric_difference(want).area < tol * want.length
    assert len(ring) == len(expected)


def test_a_geojson_square_with_a_hole_lands_on_its_local_coordinates(tmp_path: Path) -> None:
    path = write_geojson(tmp_path / "zones.geojson", geographic_polygon(SQUARE, HOLE))
    (zone,) = read_zones(path, PROJECTION)
    assert zone.label == "feature 0"
    assert_same_ring(zone.exterior, SQUARE)
    assert len(zone.holes) == 1
    assert_same_ring(zone.holes[0], HOLE)


def test_multipolygon_parts_are_zones_of_their_own_and_points_are_skipped(tmp_path: Path) -> None:
    other = SQUARE + 300.0
    parts = MultiPolygon([geographic_polygon(SQUARE), geographic_polygon(other)])
    path = write_geojson(tmp_path / "z.json", Point(0.0, 0.0), parts)
    zones = read_zones(path, PROJECTION)
    assert [zone.label for zone in zones] == ["feature 1.0", "feature 1.1"]
    assert_same_ring(zones[1].exterior, other)


@pytest.mark.parametrize(
    ("crs", "driver", "suffix"),
    [
        ("EPSG:32610", "ESRI Shapefile", ".shp"),  # UTM zone 10 N, metres
        ("EPSG:3857", "GPKG", ".gpkg"),  # web Mercator (scale 1.25 here)
        ("EPSG:4326", "GPKG", ".gpkg"),
        ("EPSG:4326", "KML", ".kml"),
    ],
)
def test_files_in_any_crs_are_reprojected(
    tmp_path: Path, crs: str, driver: str, suffix: str
) -> None:
    path = write_ogr(tmp_path / f"zones{suffix}", geographic_polygon(SQUARE, HOLE), crs, driver)
    (zone,) = read_zones(path, PROJECTION)
    assert_same_ring(zone.exterior, SQUARE)
    assert_same_ring(zone.holes[0], HOLE)


def test_a_file_without_a_crs_is_refused(tmp_path: Path) -> None:
    path = write_ogr(tmp_path / "bare.shp", geographic_polygon(), None, "ESRI Shapefile")
    with pytest.raises(DataFormatError, match=r"bare\.shp: the file declares no CRS"):
        read_zones(path, PROJECTION)


@pytest.mark.parametrize(
    ("geometry", "ids", "match"),
    [
        (
            Polygon([(0.0, 0.0), (0.001, 0.001), (0.0, 0.001), (0.001, 0.0)]),
            ("reef",),
            r"z\.geojson: feature 1 \(id 'reef'\): invalid polygon \(Self-intersection",
        ),
        (
            Polygon(
                [(0.0, 0.0), (0.001, 0.0), (0.001, 0.001)],
                [[(0.01, 0.01), (0.02, 0.01), (0.02, 0.02)]],
            ),
            (),
            r"feature 1: invalid polygon \(Hole lies outside shell",
        ),
        (Point(0.0, 0.0), (), r"no polygon or multipolygon feature"),
    ],
)
def test_invalid_geometry_names_the_file_the_feature_and_the_problem(
    tmp_path: Path, geometry: Any, ids: tuple[Any, ...], match: str
) -> None:
    first = Point(1.0, 1.0) if isinstance(geometry, Point) else geographic_polygon()
    path = write_geojson(tmp_path / "z.geojson", first, geometry, ids=(0, *ids))
    with pytest.raises(DataFormatError, match=match) as error:
        read_zones(path, PROJECTION)
    assert "\n" not in str(error.value)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("[1, 2]", "not a GeoJSON object"),
        ('{"type": "FeatureCollection"}', "without a features list"),
        ('{"type": "FeatureCollection", "features": [3]}', "feature 0 is not a GeoJSON Feature"),
        ('{"type": "Polygon", "coordinates": "x"}', "feature 0: not a GeoJSON geometry"),
        ('{"type": "Polygon", "coordinates": [[[0, 0], [1, NaN], [1, 1], [0, 0]]]}', "not finite"),
        ("{", "not valid JSON"),
    ],
)
def test_malformed_geojson_is_one_line(tmp_path: Path, text: str, match: str) -> None:
    path = tmp_path / "z.geojson"
    path.write_text(text)
    with pytest.raises(DataFormatError, match=match) as error:
        read_zones(path, PROJECTION)
    assert "\n" not in str(error.value)


def test_a_legacy_crs_member_is_honoured(tmp_path: Path) -> None:
    transformer = Transformer.from_crs("EPSG:4326", "EPSG:32610", always_xy=True)
    utm = shapely.transform(
        geographic_polygon(), lambda xy: np.column_stack(transformer.transform(*xy.T))
    )
    document = {
        "type": "Feature",
        "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::32610"}},
        "geometry": mapping(utm),
    }
    path = tmp_path / "utm.geojson"
    path.write_text(json.dumps(document))
    (zone,) = read_zones(path, PROJECTION)
    assert_same_ring(zone.exterior, SQUARE)


def test_terrain_without_geographic_reference_and_layers_of_geojson_are_refused(
    tmp_path: Path,
) -> None:
    path = write_geojson(tmp_path / "z.geojson", geographic_polygon())
    with pytest.raises(InputError, match="geographic reference"):
        read_zones(path, None)
    with pytest.raises(InputError, match="no layers"):
        read_zones(path, PROJECTION, layer="reefs")


def test_without_pyogrio_the_error_names_the_extra(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import sys

    monkeypatch.setitem(sys.modules, "pyogrio", None)  # import pyogrio raises ImportError
    with pytest.raises(InputError, match=r"zones\.shp: .*pip install 'auvplan\[gis\]'"):
        read_zones(tmp_path / "zones.shp", PROJECTION)


def test_a_named_layer_of_a_geopackage(tmp_path: Path) -> None:
    pyogrio = pytest.importorskip("pyogrio")
    path = tmp_path / "zones.gpkg"
    for layer, ring in (("first", SQUARE + 500.0), ("reefs", SQUARE)):
        wkb = np.array([shapely.to_wkb(geographic_polygon(ring))], dtype=object)
        pyogrio.raw.write(
            path, wkb, [], [], geometry_type="Polygon", crs="EPSG:4326", driver="GPKG", layer=layer
        )
    (zone,) = read_zones(path, PROJECTION, layer="reefs")
    assert_same_ring(zone.exterior, SQUARE)
    (default,) = read_zones(path, PROJECTION)
    assert_same_ring(default.exterior, SQUARE + 500.0)
    with pytest.raises(DataFormatError, match=r"zones\.gpkg: cannot read"):
        read_zones(path, PROJECTION, layer="missing")
