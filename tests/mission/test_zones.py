"""No-go zones from GIS files and the operating area, through the whole mission.

A GeoJSON zone (EPSG:4326) and a shapefile zone in UTM (EPSG:32610) are avoided with
clearance ``r_c`` by the pre-planned paths and, in the slow suite, by the optimised plan's
closed-loop replay; an operating area keeps every path ``r_c`` inside it; holes are free
water in a zone and islands in an area; the verdict names a replay that leaves the area.
"""

from __future__ import annotations

import json
import re
import tomllib
import warnings
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
import shapely
from pyproj import Transformer
from shapely.geometry import LineString, Polygon, mapping

from auvplan.cli.main import main
from auvplan.io.bathymetry import read_bathymetry
from auvplan.mission.checks import PlanStatus, judge_plan
from auvplan.mission.config import AREA_NAME, parse_mission
from auvplan.record.labels import Pair
from auvplan.scenarios import check
from auvplan.terrain import LocalProjection
from export._plans import write_geographic_grid

SAFETY_RADIUS = 5.0
#: Zones and areas as local ``[north, east]`` [m] rings on the 500 m grid of ``write_grid``.
REEF = np.array([[130.0, 215.0], [130.0, 285.0], [170.0, 285.0], [170.0, 215.0]])
WRECK = np.array([[195.0, 250.0], [195.0, 320.0], [225.0, 320.0], [225.0, 250.0]])
CORRIDOR = np.array([[30.0, 170.0], [30.0, 330.0], [290.0, 330.0], [290.0, 170.0]])


def write_grid(path: Path) -> LocalProjection:
    """The exports' 500 m x 500 m lat/lon grid (depths 20-40 m) at ``path``; its local frame."""
    write_geographic_grid(path)
    projection = read_bathymetry(path).projection
    assert projection is not None
    return projection


def geographic(projection: LocalProjection, ring: np.ndarray, *holes: np.ndarray) -> Polygon:
    """A local polygon [m] as a (lon, lat) shapely polygon."""

    def lon_lat(points: np.ndarray) -> list[tuple[float, float]]:
        lat, lon = projection.to_geographic(points[:, 0], points[:, 1])
        return list(zip(lon.tolist(), lat.tolist(), strict=True))

    return Polygon(lon_lat(ring), [lon_lat(hole) for hole in holes])


def write_geojson(path: Path, polygon: Polygon) -> str:
    feature = {"type": "Feature", "properties": {}, "geometry": mapping(polygon)}
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    return path.name


def write_utm_shapefile(path: Path, polygon: Polygon) -> str:
    """``polygon`` (lon/lat) as a shapefile in UTM zone 10 N (EPSG:32610), with pyogrio."""
    pyogrio = pytest.importorskip("pyogrio")
    transformer = Transformer.from_crs("EPSG:4326", "EPSG:32610", always_xy=True)
    utm = shapely.transform(polygon, lambda xy: np.column_stack(transformer.transform(*xy.T)))
    wkb = np.array([shapely.to_wkb(utm)], dtype=object)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        pyogrio.raw.write(
            path, wkb, [], [], geometry_type="Polygon", crs="EPSG:32610", driver="ESRI Shapefile"
        )
    return path.name


def mission_text(start: tuple[float, float], goal: tuple[float, float], tables: str) -> str:
    return f"""
[terrain]
file = "grid.nc"
[fleet]
horizon_s = 300.0
safety_radius_m = {SAFETY_RADIUS}
[[vehicle]]
name = "blue"
start = {{ north = {start[0]}, east = {start[1]}, speed = 0.5 }}
goal = {{ north = {goal[0]}, east = {goal[1]} }}
[planner]
edge_model = "crossed"
[solver]
dt_s = 1.0
{tables}
"""


def lat_lon_vertices(projection: LocalProjection, ring: np.ndarray) -> str:
    lat, lon = projection.to_geographic(ring[:, 0], ring[:, 1])
    pairs = zip(lat.tolist(), lon.tolist(), strict=True)
    return ", ".join(f"{{ lat = {a!r}, lon = {o!r} }}" for a, o in pairs)


def reef_wreck_corridor(root: Path) -> Path:
    """A mission whose straight line crosses a GeoJSON reef, past a UTM shapefile wreck,
    inside a lat/lon corridor (the operating area)."""
    projection = write_grid(root / "grid.nc")
    reef = write_geojson(root / "reef.geojson", geographic(projection, REEF))
    wreck = write_utm_shapefile(root / "wreck.shp", geographic(projection, WRECK))
    tables = f"""
[[obstacle]]
name = "reef"
file = "{reef}"
[[obstacle]]
name = "wreck"
file = "{wreck}"
[area]
polygon = [{lat_lon_vertices(projection, CORRIDOR)}]
"""
    path = root / "mission.toml"
    path.write_text(mission_text((60.0, 250.0), (260.0, 250.0), tables))
    return path


def preplan(mission: Path) -> dict[str, Any]:
    return preplan_into(mission, mission.parent / "out")


def preplan_into(mission: Path, out: Path) -> dict[str, Any]:
    argv = ["-q", "plan", str(mission), "-o", str(out), "--stage", "preplan", "--no-figures"]
    assert main(argv) == 0
    summary: dict[str, Any] = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    return summary


def path_of(summary: dict[str, Any]) -> np.ndarray:
    return np.asarray(summary["vehicles"][0]["preplan"]["points_north_east_m"], dtype=float)


def clearance(path: np.ndarray, region: Polygon) -> float:
    """Least distance [m] of the path's points to ``region`` (local, x = east, y = north)."""
    return float(np.min(shapely.distance(region, shapely.points(path[:, 1], path[:, 0]))))


def inside_by(path: np.ndarray, area: Polygon) -> float:
    """Least distance [m] of the path's points inside ``area`` from its boundary (< 0: out)."""
    points = shapely.points(path[:, 1], path[:, 0])
    distance = shapely.distance(area.boundary, points)
    return float(np.min(np.where(area.contains(points), distance, -distance)))


def local(ring: np.ndarray, *holes: np.ndarray) -> Polygon:
    return Polygon(ring[:, ::-1], [hole[:, ::-1] for hole in holes])


def test_gis_zones_and_a_lat_lon_area_shape_the_preplanned_path(tmp_path: Path) -> None:
    summary = preplan(reef_wreck_corridor(tmp_path))
    path = path_of(summary)
    straight = LineString([(250.0, 60.0), (250.0, 260.0)])
    assert straight.intersects(local(REEF))  # the zone is in the way
    assert clearance(path, local(REEF)) >= SAFETY_RADIUS
    assert clearance(path, local(WRECK)) >= SAFETY_RADIUS
    assert inside_by(path, local(CORRIDOR)) >= SAFETY_RADIUS
    shapes = {obstacle["name"]: obstacle for obstacle in summary["obstacles"]}
    assert set(shapes) == {"reef feature 0", "wreck feature 0", AREA_NAME}
    assert shapes[AREA_NAME]["shape"] == "area"
    # the UTM shapefile and the lat/lon vertices land where they were drawn (pyproj, to 1 mm)
    for name, ring in (("wreck feature 0", WRECK), (AREA_NAME, CORRIDOR)):
        drawn = np.array([(v["north"], v["east"]) for v in shapes[name]["vertices"]])
        assert local(drawn).symmetric_difference(local(ring)).area < 1e-3 * local(ring).length


def test_an_output_folder_carries_its_zone_files_and_reruns_without_them(tmp_path: Path) -> None:
    """summary.json fingerprints the GIS files; the folder's mission.toml names its copies."""
    mission = reef_wreck_corridor(tmp_path)
    first = preplan(mission)
    assert [zone["path"] for zone in first["inputs"]["zones"]] == ["reef.geojson", "wreck.shp"]
    for path in tmp_path.glob("*"):  # the inputs go: only the output folder is left
        if path.is_file():
            path.unlink()
    rerun = tmp_path / "out" / "mission.toml"
    again = preplan_into(rerun, tmp_path / "again")
    assert again["obstacles"] == first["obstacles"]
    np.testing.assert_allclose(path_of(again), path_of(first))


def test_an_l_shaped_area_file_keeps_the_path_off_the_short_cut(tmp_path: Path) -> None:
    """The straight line leaves the L; the path keeps r_c inside it, around its island."""
    projection = write_grid(tmp_path / "grid.nc")
    ell = np.array(
        [[40.0, 60.0], [40.0, 440.0], [160.0, 440.0], [160.0, 160.0], [330.0, 160.0],
         [330.0, 60.0]]
    )  # fmt: skip
    island = np.array([[80.0, 250.0], [80.0, 290.0], [120.0, 290.0], [120.0, 250.0]])
    area = write_geojson(tmp_path / "area.geojson", geographic(projection, ell, island))
    mission = tmp_path / "mission.toml"
    tables = f'[area]\nfile = "{area}"\n'
    mission.write_text(mission_text((100.0, 400.0), (300.0, 110.0), tables))
    path = path_of(preplan(mission))
    straight = LineString([(400.0, 100.0), (110.0, 300.0)])
    assert not local(ell).contains(straight)
    assert inside_by(path, local(ell, island)) >= SAFETY_RADIUS


def test_a_hole_of_a_zone_is_free_water(tmp_path: Path) -> None:
    """Start and goal inside a zone's hole: planned (a polygon without holes would refuse)."""
    projection = write_grid(tmp_path / "grid.nc")
    frame = np.array([[40.0, 40.0], [40.0, 460.0], [460.0, 460.0], [460.0, 40.0]])
    hole = np.array([[100.0, 100.0], [100.0, 400.0], [400.0, 400.0], [400.0, 100.0]])
    zone = write_geojson(tmp_path / "lagoon.geojson", geographic(projection, frame, hole))
    mission = tmp_path / "mission.toml"
    mission.write_text(
        mission_text((150.0, 150.0), (350.0, 330.0), f'[[obstacle]]\nfile = "{zone}"\n')
    )
    summary = preplan(mission)
    assert clearance(path_of(summary), local(frame, hole)) >= SAFETY_RADIUS
    (shape,) = summary["obstacles"]
    assert len(shape["holes"]) == 1


def test_a_replay_outside_the_area_is_a_violation_naming_it() -> None:
    config = parse_mission(
        tomllib.loads(
            """
[terrain]
synthetic = true
[fleet]
horizon_s = 100.0
safety_radius_m = 5.0
[[vehicle]]
name = "a"
start = { north = 10.0, east = 10.0 }
goal = { north = 50.0, east = 10.0 }
[area]
polygon = [[0.0, 0.0], [0.0, 100.0], [100.0, 100.0], [100.0, 0.0]]
"""
        )
    )
    time = np.linspace(0.0, 100.0, 101)
    distance = np.full(time.size, 10.0)
    result = SimpleNamespace(success=True, status=SimpleNamespace(name="CONVERGED"))
    inside = judge_plan(config, ("a",), result, time, {Pair("a", AREA_NAME): distance}, np.zeros(1))
    assert inside.status is PlanStatus.CONVERGED
    distance[40] = -0.5  # one sample half a metre outside the area
    verdict = judge_plan(
        config, ("a",), result, time, {Pair("a", AREA_NAME): distance}, np.zeros(1)
    )
    assert verdict.status is PlanStatus.CONSTRAINT_VIOLATED
    (violation,) = verdict.violations
    assert (violation.kind, violation.value, violation.limit) == (AREA_NAME, -0.5, 5.0)
    assert verdict.message.startswith(f"{AREA_NAME}: a / {AREA_NAME} at -0.50 m < 5 m (t = 40 s)")
    assert "\n" not in verdict.message


@pytest.mark.slow
def test_the_optimised_replay_keeps_clear_of_gis_zones_and_inside_the_area(
    tmp_path: Path,
) -> None:
    """The full plan: exit 0, converged, the replay r_c from each zone and inside the area."""
    mission = reef_wreck_corridor(tmp_path)
    out = tmp_path / "out"
    argv = ["-q", "plan", str(mission), "-o", str(out), "--no-figures", "--export", "geojson"]
    assert main(argv) == 0
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert summary["optimization"]["plan_status"] == "CONVERGED"
    minima = summary["optimization"]["vehicles"]["blue"]["min_separation_m"]
    assert set(minima) == {"reef feature 0", "wreck feature 0", AREA_NAME}
    assert min(minima.values()) >= SAFETY_RADIUS - 1e-3
    report = check(out)  # independent of the solver, from the folder's own mission.toml
    assert report.failures == ()
    independent = report.min_obstacle_clearance_m
    assert set(independent) == {
        "blue / obstacle 0 feature 0", "blue / obstacle 1 feature 0", f"blue / {AREA_NAME}"
    }  # fmt: skip
    assert min(independent.values()) >= SAFETY_RADIUS
    zones = json.loads((out / "export" / "obstacles.geojson").read_text(encoding="utf-8"))
    names = sorted(feature["properties"]["name"] for feature in zones["features"])
    assert names == ["reef feature 0", "wreck feature 0"]  # the area is kept in, not out


BOWTIE = np.array([[100.0, 100.0], [150.0, 150.0], [100.0, 150.0], [150.0, 100.0]])
SQUARE = np.array([[300.0, 300.0], [300.0, 400.0], [400.0, 400.0], [400.0, 300.0]])


def write_two_polygons(root: Path, projection: LocalProjection) -> str:
    geometries = [geographic(projection, SQUARE), geographic(projection, SQUARE - 200.0)]
    features = [{"type": "Feature", "properties": {}, "geometry": mapping(g)} for g in geometries]
    (root / "two.geojson").write_text(
        json.dumps({"type": "FeatureCollection", "features": features})
    )
    return "two.geojson"


def write_bowtie(root: Path, projection: LocalProjection) -> str:
    document = {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "properties": {},
                "geometry": mapping(geographic(projection, SQUARE)),
            },
            {
                "type": "Feature",
                "id": "kelp",
                "properties": {},
                "geometry": mapping(geographic(projection, BOWTIE)),
            },
        ],
    }
    (root / "bad.geojson").write_text(json.dumps(document))
    return "bad.geojson"


BOX = "[[0.0, 0.0], [0.0, 450.0], [450.0, 450.0], [450.0, 0.0]]"
NORTH_BAND = "[[300.0, 0.0], [300.0, 450.0], [450.0, 450.0], [450.0, 0.0]]"
TRIANGLE = "[[0.0, 0.0], [0.0, 9.0], [9.0, 0.0]]"
MIXED = "[[0.0, 0.0], [0.0, 9.0], {{ lat = 36.79, lon = -121.81 }}]"
CIRCLE = "center = {{ north = 1.0, east = 1.0 }}\nradius_m = 3.0"
NAMED_AREA = (
    '[[vehicle]]\nname = "operating area"\nstart = {{ north = 60.0, east = 100.0 }}\n'
    "goal = {{ north = 260.0, east = 100.0 }}\n"
)
ALONG = ((60.0, 250.0), (260.0, 250.0))


@pytest.mark.parametrize(
    ("poses", "tables", "expected"),
    [
        (
            ALONG, '[[obstacle]]\nname = "z"\nfile = "{bad}"\n',
            r"bad\.geojson: feature 1 \(id 'kelp'\): invalid polygon \(Self-intersection\[",
        ),
        (
            ((350.0, 350.0), (60.0, 60.0)), '[[obstacle]]\nname = "z"\nfile = "{two}"\n',
            r"blue: start \(350, 350\) m is inside obstacle 'z feature 0'",
        ),
        (
            ((350.0, 350.0), (60.0, 60.0)),
            f'[area]\npolygon = {BOX}\n[[obstacle]]\nfile = "{{two}}"',
            r"blue: start \(350, 350\) m is inside obstacle 'obstacle 0 feature 0'",
        ),
        (
            ((350.0, 350.0), (480.0, 60.0)), f"[area]\npolygon = {NORTH_BAND}\n",
            r"blue: goal \(480, 60\) m is outside the operating area",
        ),
        (
            ((350.0, 350.0), (400.0, 60.0)), '[area]\nfile = "{two}"\n',
            r"two\.geojson: an operating area is one polygon, the file holds 2",
        ),
        (
            ALONG, '[[obstacle]]\nfile = "missing.geojson"\n',
            r"zones file .*missing\.geojson: file not found",
        ),
        (
            ALONG, '[[obstacle]]\nfile = "{two}"\nlayer = "x"\n',
            r"two\.geojson: a GeoJSON file has no layers",
        ),
        (ALONG, f'[[obstacle]]\nlayer = "x"\n{CIRCLE}\n', r"obstacle\[0\]: layer needs a file"),
        (
            ALONG, f'[area]\nfile = "{{two}}"\npolygon = {TRIANGLE}\n',
            r"area: give a polygon or a file \(one of them\)",
        ),
        (
            ALONG, f"[area]\npolygon = {MIXED}\n",
            r"area: give every vertex as \[north, east\] or every one as \{ lat, lon \}",
        ),
        (
            ALONG, NAMED_AREA + '[area]\nfile = "{two}"\n',
            r"names must be unique: operating area",
        ),
    ],
)  # fmt: skip
def test_bad_zones_and_areas_are_one_line_exit_2_and_write_nothing(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    poses: tuple[tuple[float, float], tuple[float, float]],
    tables: str,
    expected: str,
) -> None:
    projection = write_grid(tmp_path / "grid.nc")
    names = {
        "bad": write_bowtie(tmp_path, projection),
        "two": write_two_polygons(tmp_path, projection),
    }
    mission = tmp_path / "mission.toml"
    mission.write_text(mission_text(*poses, tables.format(**names)))
    before = sorted(tmp_path.iterdir())
    capsys.readouterr()
    code = main(["plan", str(mission), "-o", str(tmp_path / "out"), "--stage", "preplan"])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1, err
    assert re.search(expected, err), err
    assert sorted(tmp_path.iterdir()) == before  # nothing written


def test_lat_lon_zones_on_terrain_without_a_geographic_reference_are_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    vertices = "[{ lat = 1.0, lon = 2.0 }, { lat = 1.0, lon = 2.1 }, { lat = 1.1, lon = 2.0 }]"
    text = mission_text((10.0, 400.0), (200.0, 400.0), f"[area]\npolygon = {vertices}\n")
    mission = tmp_path / "mission.toml"
    mission.write_text(text.replace('file = "grid.nc"', "synthetic = true"))
    code = main(["plan", str(mission), "-o", str(tmp_path / "out"), "--stage", "preplan"])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert err == (
        "auvplan: error: operating area is given in lat/lon but the terrain has no geographic "
        "reference"
    )


def test_zone_tables_survive_the_resolved_document(tmp_path: Path) -> None:
    """Files become absolute, lat/lon vertices stay tables: parsing the document gives back
    the mission (as the output folder's mission.toml does)."""
    from auvplan.mission.config import resolved_document

    document = tomllib.loads(
        """
[terrain]
synthetic = true
[fleet]
horizon_s = 100.0
safety_radius_m = 5.0
[[vehicle]]
start = { north = 10.0, east = 10.0 }
goal = { north = 50.0, east = 10.0 }
[[obstacle]]
file = "zones/reef.geojson"
layer = "reefs"
[[obstacle]]
polygon = [{ lat = 36.79, lon = -121.81 }, { lat = 36.791, lon = -121.81 }, { lat = 36.79, lon = -121.809 }]
[area]
polygon = [[0.0, 0.0], [0.0, 100.0], [100.0, 100.0]]
"""  # noqa: E501
    )
    config = parse_mission(document, base_dir=tmp_path)
    assert config.obstacles[0].file == tmp_path / "zones" / "reef.geojson"
    resolved = resolved_document(config)
    assert resolved["obstacle"][1]["polygon"][0] == {"lat": 36.79, "lon": -121.81}
    assert parse_mission(resolved) == config
