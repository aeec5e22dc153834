"""Fuzzing the zone tables: ``[[obstacle]]`` and ``[area]`` polygons and GIS files.

Random tables as a careless user writes them — polygons of 0 to 7 vertices (self-crossing,
degenerate, extreme or non-finite numbers, ``[north, east]`` pairs mixed with ``{ lat, lon }``
tables), GeoJSON files holding polygons with holes, multipolygons, points, a legacy ``crs``
member, wrong types or no JSON at all, unknown ``layer`` keys — on a georeferenced mission
(Monterey, packaged), then mutated like ``test_fuzz_missions``. Each mission runs through
``auvplan plan MISSION -o OUT --stage preplan --no-figures`` and must end with exit code 0, 2
or 3, at most one line on stderr, no traceback and nothing left beside the mission but (on
success) the output folder (:func:`test_fuzz_missions.check_mission`). 15 missions by default,
300 in the slow suite.

Run as a script (``python tests/cli/test_fuzz_zones.py N SEED``) it tries ``N`` random
missions and prints every failure, for a longer campaign than the test suite's.
"""

from __future__ import annotations

import atexit
import itertools
import json
import random
import shutil
import sys
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, note, settings
from hypothesis import strategies as st
from test_fuzz_missions import EXTREMES, check_mission, mutate, to_toml

from auvplan.io.samples import sample_path
from auvplan.mission.preplan import read_terrain

Choose = Callable[[Sequence[Any]], Any]
WINDOW = {"lat": [36.79360, 36.79714], "lon": [-121.81473, -121.80582]}
#: Local coordinates [m] a zone's vertices are drawn from (the window is ~800 m x 390 m).
SPAN = (-50.0, 850.0)
PROJECTION = read_terrain(
    sample_path("monterey"), window_lat=tuple(WINDOW["lat"]), window_lon=tuple(WINDOW["lon"])
).projection
assert PROJECTION is not None
#: GeoJSON files are written here once per run (absolute paths in the missions).
FILES = Path(tempfile.mkdtemp(prefix="auvplan-fuzz-zones-"))
_COUNT = itertools.count()
atexit.register(shutil.rmtree, FILES, ignore_errors=True)


def base_mission() -> dict[str, Any]:
    return {
        "terrain": {"sample": "monterey", "window": WINDOW},
        "fleet": {"horizon_s": 700.0, "safety_radius_m": 5.0},
        "vehicle": [
            {
                "name": "blue",
                "start": {"north": 10.0, "east": 330.0, "speed": 0.5},
                "goal": {"north": 370.0, "east": 380.0},
            }
        ],
        "planner": {"edge_model": "crossed"},
    }


def number(choose: Choose) -> Any:
    """A coordinate [m]: mostly on the map, sometimes off it or not a number at all."""
    if choose([True] * 4 + [False]):
        return choose([*np.linspace(*SPAN, 19).round(1).tolist(), -1e4])
    return choose(EXTREMES)


def ring(choose: Choose, centre: tuple[float, float], radius: float) -> np.ndarray:
    """A star-shaped ring (valid) or, one time in four, its vertices shuffled (often crossing)."""
    n = choose([3, 4, 5, 7])
    angles = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False) + choose([0.0, 0.3, 1.1])
    radii = radius * np.array([choose([0.6, 0.8, 1.0]) for _ in range(n)])
    points = np.column_stack(
        (centre[0] + radii * np.cos(angles), centre[1] + radii * np.sin(angles))
    )
    if choose([False, False, False, True]):
        points = points[[choose(range(n)) for _ in range(n)]]
    return points


def vertices(choose: Choose) -> list[Any]:
    """A polygon's vertices: drawn rings, few or wild numbers, lat/lon tables, mixtures."""
    kind = choose(["ring", "ring", "latlon", "wild", "mixed"])
    centre = (choose([100.0, 200.0, 300.0]), choose([200.0, 350.0, 600.0]))
    points = ring(choose, centre, choose([5.0, 30.0, 120.0]))
    if kind == "ring":
        return [[float(n), float(e)] for n, e in points]
    lat, lon = PROJECTION.to_geographic(points[:, 0], points[:, 1])
    tables = [{"lat": float(a), "lon": float(o)} for a, o in zip(lat, lon, strict=True)]
    if kind == "latlon":
        return list(tables)
    if kind == "mixed":
        return [[float(points[0, 0]), float(points[0, 1])], *tables[1:]]
    return [[number(choose), number(choose)] for _ in range(choose([0, 1, 2, 3, 4, 6]))]


def geojson_file(choose: Choose) -> str:
    """A GeoJSON file (valid, invalid or not JSON) written to FILES; its absolute path."""

    def polygon() -> list[Any]:
        outer = ring(choose, (200.0, 500.0), choose([40.0, 150.0]))
        rings = [outer]
        if choose([False, True]):
            rings.append(ring(choose, (200.0, 500.0), choose([10.0, 200.0])))  # hole, or not
        coordinates = []
        for points in rings:
            lat, lon = PROJECTION.to_geographic(points[:, 0], points[:, 1])
            closed = [[float(o), float(a)] for a, o in zip(lat, lon, strict=True)]
            coordinates.append([*closed, closed[0]])
        return coordinates

    geometry = choose(
        [
            lambda: {"type": "Polygon", "coordinates": polygon()},
            lambda: {"type": "MultiPolygon", "coordinates": [polygon(), polygon()]},
            lambda: {"type": "Point", "coordinates": [-121.81, 36.795]},
            lambda: {"type": "Polygon", "coordinates": choose(EXTREMES)},
            lambda: choose(EXTREMES),
        ]
    )()
    feature: dict[str, Any] = {"type": "Feature", "properties": {}, "geometry": geometry}
    if choose([False, True]):
        feature["id"] = choose(["reef", 7, None])
    document: Any = {"type": "FeatureCollection", "features": [feature]}
    if choose([False] * 5 + [True]):
        document["crs"] = {"type": "name", "properties": {"name": choose(["EPSG:4326", "x", 1])}}
    if choose([False] * 5 + [True]):
        document = choose([feature, geometry, [feature], "text"])
    text = json.dumps(document, allow_nan=True)
    if choose([False] * 9 + [True]):
        text = text[: len(text) // 2]  # not JSON
    path = FILES / f"zones{next(_COUNT)}{choose(['.geojson', '.json'])}"
    path.write_text(text)
    return str(path)


def zone_table(choose: Choose, *, area: bool) -> dict[str, Any]:
    kind = choose(["polygon", "file"] if area else ["polygon", "file", "circle"])
    table: dict[str, Any] = {}
    if kind == "polygon":
        table["polygon"] = vertices(choose)
    elif kind == "file":
        table["file"] = choose([geojson_file, geojson_file, lambda _: "missing.shp"])(choose)
    else:
        table.update(center={"north": number(choose), "east": number(choose)}, radius_m=20.0)
    if choose([False] * 5 + [True]):
        table["layer"] = choose(["reefs", "", 1])
    if not area and choose([False, True]):
        table["name"] = choose(["reef", "blue", "operating area", "a,b"])
    return table


def zone_mission(choose: Choose) -> tuple[str, list[str]]:
    """A mission's TOML text with random zone tables (and maybe mutations), and what it has."""
    document = base_mission()
    if choose([False, True]):
        document["area"] = zone_table(choose, area=True)
    obstacles = [zone_table(choose, area=False) for _ in range(choose([0, 1, 1, 2]))]
    if obstacles:
        document["obstacle"] = obstacles
    done = [json.dumps({k: document.get(k) for k in ("area", "obstacle")})]
    if choose([False, False, True]):
        document, mutations = mutate(document, choose)
        done += mutations
    return to_toml(document), done


def _fuzz(data: st.DataObject) -> None:
    text, done = zone_mission(lambda options: data.draw(st.sampled_from(list(options))))
    note("\n".join(done) + "\n" + text)
    code, problem = check_mission(text)
    assert problem is None, problem
    event(f"exit {code}")


@settings(
    max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow], database=None
)
@given(st.data())
def test_random_zone_tables_never_crash_or_leave_files(data: st.DataObject) -> None:
    _fuzz(data)


@pytest.mark.slow
@settings(
    max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow], database=None
)
@given(st.data())
def test_many_random_zone_tables_never_crash_or_leave_files(data: st.DataObject) -> None:
    _fuzz(data)


def _campaign(n_examples: int, seed: int) -> None:
    import logging

    logging.getLogger().addHandler(logging.NullHandler())  # as under pytest: logs not on stderr
    rng = random.Random(seed)
    failures, codes = 0, {}
    for index in range(n_examples):
        text, done = zone_mission(lambda options: rng.choice(list(options)))
        code, problem = check_mission(text)
        codes[code] = codes.get(code, 0) + 1
        if problem is not None:
            failures += 1
            sys.stdout.write(f"--- #{index}: {problem}\n    " + "; ".join(done) + "\n")
    sys.stdout.write(f"{failures} failures in {n_examples} missions; exit codes {codes}\n")


if __name__ == "__main__":
    _campaign(int(sys.argv[1]), int(sys.argv[2]))
