"""The inputs an output folder carries (:mod:`auvplan.mission.carry`), without planning."""

from __future__ import annotations

import tomllib
from dataclasses import asdict
from importlib import resources
from pathlib import Path

import numpy as np
import tomli_w

from auvplan.io.vehicles import load_vehicle
from auvplan.mission.carry import carried_mission
from auvplan.mission.config import load_mission

PACKAGED = resources.files("auvplan").joinpath("data")
MEDUSA = PACKAGED.joinpath("vehicles", "medusa.toml").read_text(encoding="utf-8")
TABLE = PACKAGED.joinpath("propellers", "wageningen_b4-70_pd1.4.csv").read_bytes()


def _vehicle_file(path: Path, table: str, *, hotel_w: float = 0.0) -> Path:
    """MEDUSA's file naming propeller ``table`` (and another hotel load, to tell files apart)."""
    text = MEDUSA.replace('"wageningen_b4-70_pd1.4"', f'"{table}"', 1)
    assert text != MEDUSA
    document = tomllib.loads(text)
    document["power"]["hotel"]["value"] = hotel_w
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(tomli_w.dumps(document), encoding="utf-8")
    return path


def _mission(folder: Path, types: list[str], extra: str = "") -> Path:
    vehicles = "".join(
        f'[[vehicle]]\ntype = "{kind}"\nstart = {{ north = 10.0, east = {100.0 + 50 * i} }}\n'
        f"goal = {{ north = 60.0, east = {100.0 + 50 * i} }}\n"
        for i, kind in enumerate(types)
    )
    path = folder / "mission.toml"
    path.write_text(
        "[terrain]\nsynthetic = true\n[fleet]\nhorizon_s = 60.0\nsafety_radius_m = 5.0\n"
        + vehicles
        + extra,
        encoding="utf-8",
    )
    return path


def _write(files: dict[str, bytes], folder: Path, document: dict[str, object]) -> Path:
    """The carried files and the mission as an output folder would hold them."""
    for name, content in files.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(content)
    (folder / "mission.toml").write_text(tomli_w.dumps(document), encoding="utf-8")
    return folder / "mission.toml"


def test_vehicle_files_and_tables_are_carried_and_reload_alike(tmp_path: Path) -> None:
    source = tmp_path / "source"
    (source / "tables").mkdir(parents=True)
    (source / "tables" / "b4.csv").write_bytes(TABLE)
    kept = _vehicle_file(source / "boats" / "boat.toml", "props/mine.csv", hotel_w=1.0)
    (source / "boats" / "props").mkdir()
    (source / "boats" / "props" / "mine.csv").write_bytes(TABLE)
    outside = _vehicle_file(source / "far" / "boat.toml", "../tables/b4.csv", hotel_w=2.0)
    absolute = _vehicle_file(
        source / "abs" / "boat.cfg", str(source / "tables" / "b4.csv"), hotel_w=3.0
    )
    mission = _mission(
        source,
        ["boats/boat.toml", "far/boat.toml", str(absolute), "boats/boat.toml", "medusa"],
    )
    carried = carried_mission(load_mission(mission))

    types = [table["type"] for table in carried.document["vehicle"]]
    # the same file once; a different file of the same name in the next free folder
    assert types == [
        "inputs/boat.toml",
        "inputs/2/boat.toml",
        "inputs/3/boat.toml",
        "inputs/boat.toml",
        "medusa",
    ]
    files = carried.files
    assert files["inputs/boat.toml"] == kept.read_bytes()  # byte for byte
    assert files["inputs/props/mine.csv"] == TABLE  # at its place relative to the file
    for folder, original in (("inputs/2", outside), ("inputs/3", absolute)):
        copy = tomllib.loads(files[f"{folder}/boat.toml"].decode())
        assert copy["propeller"]["table"] == "b4.csv"  # moved beside the copy
        assert files[f"{folder}/b4.csv"] == TABLE
        expected = tomllib.loads(original.read_text(encoding="utf-8"))
        expected["propeller"]["table"] = "b4.csv"
        assert copy == expected  # nothing else changed
    assert all(not Path(name).is_absolute() and ".." not in name for name in files)

    elsewhere = _write(files, tmp_path / "elsewhere", carried.document)
    moved = load_mission(elsewhere)
    for before, after in zip(load_mission(mission).vehicles, moved.vehicles, strict=True):
        np.testing.assert_equal(asdict(load_vehicle(after.type)), asdict(load_vehicle(before.type)))
        if before.type != "medusa":
            assert Path(after.type).is_relative_to(tmp_path / "elsewhere")


def test_bathymetry_becomes_the_folders_maps_and_a_current_file_is_copied(
    tmp_path: Path,
) -> None:
    source = tmp_path / "source"
    source.mkdir()
    (source / "grid.nc").write_bytes(b"not read")
    (source / "flow.nc").write_bytes(b"current bytes")
    mission = _mission(source, ["medusa"], '[current]\nfile = "flow.nc"\n')
    text = mission.read_text().replace(
        "synthetic = true",
        'file = "grid.nc"\nwindow = { lat = [36.79, 36.80], lon = [-121.82, -121.80] }',
    )
    mission.write_text(text)
    carried = carried_mission(load_mission(mission))
    assert carried.document["terrain"]["file"] == "maps.nc"
    assert carried.document["terrain"]["window"] == {}
    assert carried.document["current"]["file"] == "inputs/flow.nc"
    assert carried.files == {"inputs/flow.nc": b"current bytes"}


def test_packaged_inputs_are_not_copied(tmp_path: Path) -> None:
    mission = _mission(tmp_path, ["medusa", "remus100"])
    text = mission.read_text().replace("synthetic = true", 'sample = "monterey"')
    mission.write_text(text)
    carried = carried_mission(load_mission(mission))
    assert carried.files == {}
    assert carried.document["terrain"]["sample"] == "monterey"
    assert [table["type"] for table in carried.document["vehicle"]] == ["medusa", "remus100"]


def test_gis_files_are_carried_a_shapefile_with_its_parts(tmp_path: Path) -> None:
    source = tmp_path / "source"
    (source / "gis").mkdir(parents=True)
    parts = {suffix: f"{suffix} bytes".encode() for suffix in (".shp", ".shx", ".dbf", ".prj")}
    for suffix, content in parts.items():
        (source / "gis" / f"reefs{suffix}").write_bytes(content)
    (source / "gis" / "reefs_old.shp").write_bytes(b"another layer")  # not a part
    (source / "area.geojson").write_bytes(b"{}")
    extra = '[[obstacle]]\nfile = "gis/reefs.shp"\n[area]\nfile = "area.geojson"\n'
    carried = carried_mission(load_mission(_mission(source, ["medusa"], extra)))
    assert carried.document["obstacle"][0]["file"] == "inputs/reefs.shp"
    assert carried.document["area"]["file"] == "inputs/area.geojson"
    expected = {f"inputs/reefs{suffix}": content for suffix, content in parts.items()}
    assert carried.files == {**expected, "inputs/area.geojson": b"{}"}
