"""End to end on a small georeferenced plan: trajectories.nc, mission.toml, ``auvplan export``."""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import os
import shutil
import subprocess
import sys
from datetime import datetime
from pathlib import Path
from typing import Any

import gpxpy
import numpy as np
import pandas as pd
import pytest
import xarray as xr

from auvplan.cli.main import main
from auvplan.export import FORMATS
from auvplan.io.maps_file import read_maps_netcdf, write_maps_netcdf
from auvplan.io.vehicles import vehicle_file
from auvplan.mission.config import load_mission, parse_mission
from auvplan.record import read_record
from auvplan.record.dataset import trajectories_dataset_of
from auvplan.record.files import MAIN_PLAN
from auvplan.terrain import LocalProjection

from ._plans import MISSION
from ._readers import cf_findings, checker_passes, checker_report, moos_points, parse_moos

ALL = ",".join(FORMATS)


def test_maps_netcdf_passes_the_cf_checker(planned_folder: Path, tmp_path: Path) -> None:
    """Issue 25: ``compliance-checker --test cf:1.8 maps.nc`` exits 0 (no error, no warning)
    for a plan on a georeferenced grid and for one on the synthetic bank (no grid mapping)."""
    (tmp_path / "mission.toml").write_text(MISSION.replace('file = "grid.nc"', "synthetic = true"))
    local = tmp_path / "local"
    arguments = ["-q", "plan", str(tmp_path / "mission.toml"), "-o", str(local), "--no-figures"]
    assert main([*arguments, "--stage", "preplan"]) == 0
    for folder, georeferenced in ((planned_folder, True), (local, False)):
        path = folder / "maps.nc"
        assert checker_passes(path, tmp_path / "cf.json", "cf:1.8"), folder.name
        assert cf_findings(path, tmp_path / "cf.json") == {"high": [], "medium": [], "low": []}
        with xr.open_dataset(path) as dataset:
            assert ("crs" in dataset.variables) == georeferenced


def test_trajectories_netcdf_is_a_cf_trajectory_file(planned_folder: Path, tmp_path: Path) -> None:
    path = planned_folder / "trajectories.nc"
    # `compliance-checker --test cf:1.8` exits 0: no error and no warning
    assert checker_passes(path, tmp_path / "cf.json", "cf:1.8")
    findings = cf_findings(path, tmp_path / "cf.json")
    assert findings["high"] == findings["medium"] == [], findings
    table = pd.read_csv(planned_folder / "trajectories.csv")
    summary = json.loads((planned_folder / "summary.json").read_text())
    with xr.open_dataset(path) as dataset:
        assert dataset.attrs["featureType"] == "trajectory"
        assert dataset["trajectory"].attrs["cf_role"] == "trajectory_id"
        assert list(dataset["trajectory"].values) == ["blue", "green"]
        # 10:00 at +02:00 in the mission file is 08:00 UTC
        assert dataset["time"].values[0, 0] == np.datetime64("2026-05-01T08:00:00")
        assert summary["start_time"] == "2026-05-01T08:00:00+00:00"
        np.testing.assert_array_equal(dataset["depth"].values, 3.0)
        origin = LocalProjection(
            summary["terrain"]["origin"]["lat"], summary["terrain"]["origin"]["lon"]
        )
        for i, name in enumerate(["blue", "green"]):
            rows = table[table["vehicle"] == name]
            seconds = (dataset["time"].values[i] - dataset["time"].values[i, 0]) / np.timedelta64(
                1, "s"
            )
            np.testing.assert_allclose(seconds, rows["t"], atol=1e-9)
            for column in ("north", "east", "u", "v", "r", "n_ps", "n_sb", "power"):
                np.testing.assert_array_equal(dataset[column].values[i], rows[column])
            # lat/lon place the local north/east (a tangent plane at the origin agrees to cm)
            north, east = origin.to_local(dataset["lat"].values[i], dataset["lon"].values[i])
            assert np.max(np.hypot(north - rows["north"], east - rows["east"])) < 0.05
            # a true heading differs from ψ by the meridian convergence only (< 0.01 deg here)
            turn = (
                dataset["heading"].values[i] - np.degrees(rows["psi"].to_numpy()) + 180.0
            ) % 360.0 - 180.0
            assert np.max(np.abs(turn)) < 0.01


def test_trajectories_netcdf_follows_the_ncei_template_and_acdd(
    planned_folder: Path, tmp_path: Path
) -> None:
    """NCEI trajectory template v2.0: no required failure; ACDD-1.3 discovery attributes, the
    operator's from the mission's [metadata] (publisher defaulting to the creator)."""
    path = planned_folder / "trajectories.nc"
    assert cf_findings(path, tmp_path / "ncei.json", "ncei-trajectory:2.0")["high"] == []
    acdd = checker_report(path, tmp_path / "acdd.json", "acdd:1.3")
    assert acdd["scored_points"] / acdd["possible_points"] >= 0.9  # 80 of 85 measured
    summary = json.loads((planned_folder / "summary.json").read_text())
    with xr.open_dataset(path) as dataset:
        attrs = dataset.attrs
        assert attrs["ncei_template_version"] == "NCEI_NetCDF_Trajectory_Template_v2.0"
        assert {"CF-1.6", "CF-1.8", "ACDD-1.3"} <= set(attrs["Conventions"].split(", "))
        assert (attrs["creator_name"], attrs["institution"]) == (
            "Ada Operator", "Example Marine Robotics Lab",
        )  # fmt: skip
        assert (attrs["publisher_name"], attrs["publisher_email"]) == (
            "Ada Operator", "ada@example.org",
        )  # fmt: skip
        assert (attrs["license"], attrs["naming_authority"]) == ("CC-BY-4.0", "org.example")
        assert attrs["platform"] == "medusa"
        # the run's time, as summary.json records it, in ISO 8601 UTC
        created = datetime.fromisoformat(summary["created"])
        assert attrs["date_created"] == created.strftime("%Y-%m-%dT%H:%M:%SZ")
        assert attrs["date_issued"] == attrs["date_modified"] == attrs["date_created"]
        assert attrs["time_coverage_duration"] == "PT80S"  # horizon_s
        assert dataset.attrs["geospatial_lat_min"] == pytest.approx(float(dataset["lat"].min()))
        assert dataset["u"].attrs["coverage_content_type"] == "modelResult"
        assert dataset["u"].attrs["valid_max"] == pytest.approx(float(dataset["u"].max()))


#: The ACDD-1.3 recommended attributes that say who made and distributes a file: the
#: operator's to give in [metadata], never made up.
WHO: frozenset[str] = frozenset(
    {
        "creator_name", "creator_url", "creator_email", "institution", "project", "license",
        "naming_authority", "publisher_name", "publisher_url", "publisher_email",
    }
)  # fmt: skip


def _acdd_missing(report: dict[str, Any]) -> tuple[set[str], set[str]]:
    """The missing global attributes and the variables without a standard name of an ACDD
    report (``compliance-checker --test acdd:1.3``)."""
    attributes, unnamed = set(), set()
    for result in [*report["high_priorities"], *report["medium_priorities"]]:
        for message in result["msgs"]:
            if message.endswith(" not present"):
                attributes.add(message.removesuffix(" not present"))
            elif message == "standard_name":
                unnamed.add(result["name"].split('"')[1])
    return attributes, unnamed


def test_without_metadata_acdd_scores_what_the_plan_itself_tells(
    planned_folder: Path, tmp_path: Path
) -> None:
    """Issue 25: without [metadata] the files carry every ACDD attribute the plan and the run
    determine; what is missing is who made them (never invented) and the CF standard names
    that do not exist (propeller speed, electrical power, map values, local north/east).
    Measured: trajectories.nc 70/85 (80/85 with [metadata]), maps.nc 46/66 (56/66)."""
    record = read_record(planned_folder)
    anonymous = dataclasses.replace(
        record, mission={k: v for k, v in record.mission.items() if k != "metadata"}
    )
    trajectories, maps = tmp_path / "trajectories.nc", tmp_path / "maps.nc"
    trajectories_dataset_of(anonymous, MAIN_PLAN).to_netcdf(trajectories)
    write_maps_netcdf(record.maps, maps, created=record.summary.created_at)
    expected = {
        trajectories: (70 / 85, {"north", "east", "n_ps", "n_sb", "power"}, set()),
        maps: (
            46 / 66,
            {"information", "excitation", "cost", "shifted_cost"},
            # maps have no time; the depth's vertical datum is the source's
            {
                "time_coverage_start",
                "time_coverage_end",
                "time_coverage_duration",
                "time_coverage_resolution",
                "geospatial_bounds_vertical_crs",
            },
        ),
    }
    for path, (score, unnamed, undetermined) in expected.items():
        assert checker_passes(path, tmp_path / "cf.json", "cf:1.8"), path.name
        report = checker_report(path, tmp_path / "acdd.json", "acdd:1.3")
        assert report["scored_points"] / report["possible_points"] >= score, path.name
        assert _acdd_missing(report) == (set(WHO | undetermined), unnamed), path.name
        with xr.open_dataset(path) as dataset:
            assert not WHO & set(dataset.attrs), path.name
            assert dataset.attrs["date_metadata_modified"] == dataset.attrs["date_created"]
    assert cf_findings(trajectories, tmp_path / "ncei.json", "ncei-trajectory:2.0")["high"] == []
    # with [metadata], maps.nc names who made it as trajectories.nc does
    with xr.open_dataset(planned_folder / "maps.nc") as dataset:
        assert (dataset.attrs["creator_name"], dataset.attrs["license"]) == (
            "Ada Operator", "CC-BY-4.0",
        )  # fmt: skip
        assert dataset.attrs["geospatial_lat_min"] == pytest.approx(float(dataset["lat"].min()))
        assert dataset.attrs["geospatial_vertical_max"] == pytest.approx(
            float(dataset["depth"].max())
        )
        assert dataset["depth"].attrs["coverage_content_type"] == "physicalMeasurement"
    report = checker_report(planned_folder / "maps.nc", tmp_path / "acdd.json", "acdd:1.3")
    assert report["scored_points"] / report["possible_points"] >= 56 / 66


def test_summary_records_version_inputs_and_start_time(planned_folder: Path) -> None:
    summary = json.loads((planned_folder / "summary.json").read_text())
    assert summary["auvplan_version"]
    inputs = summary["inputs"]
    read = {  # each file the run read, by the name summary.json records (no folder)
        "mission.toml": planned_folder.parent / "mission.toml",
        "grid.nc": planned_folder.parent / "grid.nc",
        "medusa.toml": vehicle_file("medusa"),
    }
    for entry in [inputs["mission"], inputs["bathymetry"], *inputs["vehicles"].values()]:
        digest = hashlib.sha256(read[entry["path"]].read_bytes()).hexdigest()
        assert entry["sha256"] == digest
    assert inputs["bathymetry"]["path"] == "grid.nc"
    assert [obstacle["name"] for obstacle in summary["obstacles"]] == ["rock", "wreck"]
    assert set(summary["obstacles"][0]["center"]) == {"north", "east", "lat", "lon"}


def test_mission_toml_is_the_resolved_mission_and_reruns_the_plan(
    planned_folder: Path, tmp_path: Path
) -> None:
    import tomllib

    resolved = load_mission(planned_folder / "mission.toml")
    original = parse_mission(tomllib.loads(MISSION), base_dir=planned_folder.parent)
    # the same mission, on the folder's own copy of the grid (maps.nc: cropped, projected)
    assert resolved.model_dump(exclude={"terrain"}) == original.model_dump(exclude={"terrain"})
    assert resolved.terrain.file == planned_folder / "maps.nc"
    again = tmp_path / "again"
    assert (
        main(["-q", "plan", str(planned_folder / "mission.toml"), "-o", str(again), "--no-figures"])
        == 0
    )
    first, second = (pd.read_csv(folder / "trajectories.csv") for folder in (planned_folder, again))
    assert list(first["vehicle"]) == list(second["vehicle"])
    numbers = first.columns[1:]
    np.testing.assert_allclose(second[numbers], first[numbers], rtol=0.0, atol=1e-9)
    with (
        xr.open_dataset(planned_folder / "trajectories.nc") as a,
        xr.open_dataset(again / "trajectories.nc") as b,
    ):
        xr.testing.assert_allclose(a, b, rtol=0.0, atol=1e-9)


def _tree(root: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()
    }


def test_export_later_gives_the_files_of_plan_export(planned_folder: Path, tmp_path: Path) -> None:
    target = tmp_path / "exports"
    assert main(["-q", "export", str(planned_folder), "--format", ALL, "-o", str(target)]) == 0
    assert _tree(target) == _tree(planned_folder / "export")
    gpx = gpxpy.parse((target / "trajectories.gpx").read_text())
    assert [track.name for track in gpx.tracks] == ["blue", "green"]
    for track in gpx.tracks:
        times = [point.time for point in track.segments[0].points]
        assert times[0] is not None
        assert times[0].isoformat() == "2026-05-01T08:00:00+00:00"
        assert all(b > a for a, b in itertools.pairwise(times))


def test_export_from_csv_when_the_netcdf_is_gone(planned_folder: Path, tmp_path: Path) -> None:
    folder = tmp_path / "copy"
    shutil.copytree(planned_folder, folder)
    (folder / "trajectories.nc").unlink()
    shutil.rmtree(folder / "export")
    assert main(["-q", "export", str(folder), "--format", "gpx,qgc"]) == 0
    for name in ("trajectories.gpx", "blue.plan", "green.plan"):
        from_csv = (folder / "export" / name).read_text()
        from_netcdf = (planned_folder / "export" / name).read_text()
        if name.endswith(".plan"):
            a, b = json.loads(from_csv), json.loads(from_netcdf)
            np.testing.assert_allclose(
                [p for item in a["mission"]["items"] for p in item["params"] if p is not None],
                [p for item in b["mission"]["items"] for p in item["params"] if p is not None],
                rtol=1e-12,
                atol=1e-12,
            )
        else:
            assert from_csv == from_netcdf


def test_export_from_a_csv_with_a_nan_cell_ends_with_exit_2(
    planned_folder: Path, tmp_path: Path
) -> None:
    """A NaN in trajectories.csv (no trajectories.nc) made `auvplan export` loop forever."""
    folder = tmp_path / "copy"
    shutil.copytree(planned_folder, folder, ignore=shutil.ignore_patterns("export"))
    (folder / "trajectories.nc").unlink()
    table = pd.read_csv(folder / "trajectories.csv")
    table.loc[5, "north"] = np.nan
    table.to_csv(folder / "trajectories.csv", index=False)
    before = sorted(p.name for p in folder.iterdir())
    source = Path(__file__).parents[2] / "src"
    env = {**os.environ, "PYTHONPATH": f"{source}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    command = [sys.executable, "-m", "auvplan.cli.main", "export", str(folder), "--format", "gpx"]
    done = subprocess.run(
        command, env=env, capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == 2, done.stderr
    (line,) = done.stderr.splitlines()
    assert line.startswith("auvplan: error: ")
    assert "north" in line
    assert sorted(p.name for p in folder.iterdir()) == before


def _fails_cleanly(args: list[str], where: Path, capsys: pytest.CaptureFixture[str]) -> str:
    before = sorted(p.name for p in where.iterdir())
    assert main(args) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith("auvplan")
    assert sorted(p.name for p in where.iterdir()) == before  # nothing written, no staging left
    return line


def test_export_user_errors(
    planned_folder: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    missing = tmp_path / "nothing"
    assert "not found" in _fails_cleanly(
        ["export", str(missing), "--format", "gpx"], tmp_path, capsys
    )
    folder = tmp_path / "copy"
    shutil.copytree(
        planned_folder, folder, ignore=shutil.ignore_patterns("export", "trajectories*")
    )
    message = _fails_cleanly(["export", str(folder), "--format", "gpx,dxf"], folder, capsys)
    assert "unknown export format 'dxf'" in message
    message = _fails_cleanly(["export", str(folder), "--format", "gpx"], folder, capsys)
    assert "trajectories.csv is missing: the run of" in message
    assert _fails_cleanly(["export", str(tmp_path), "--format", "gpx"], tmp_path, capsys).endswith(
        "(no summary.json)"
    )


def _without_georeference(planned_folder: Path, folder: Path) -> None:
    """``planned_folder`` as on the synthetic bank: maps.nc without CRS, origin without lat/lon
    (the maps' arrays, which summary.json's digest covers, unchanged)."""
    shutil.copytree(planned_folder, folder, ignore=shutil.ignore_patterns("export"))
    maps = read_maps_netcdf(folder / "maps.nc")
    local = dataclasses.replace(maps.bathymetry, projection=None)
    write_maps_netcdf(dataclasses.replace(maps, bathymetry=local), folder / "maps.nc")
    summary = json.loads((folder / "summary.json").read_text())
    summary["terrain"]["origin"] = {"north": 0.0, "east": 0.0}
    (folder / "summary.json").write_text(json.dumps(summary))


def test_export_without_georeference_is_moos_in_the_local_frame_only(
    planned_folder: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every format that needs lat/lon is refused in one line naming it, exit 2, nothing
    written; MOOS-IvP's local frame is the plan's own north/east."""
    local = tmp_path / "local"
    _without_georeference(planned_folder, local)
    for formats in ("geojson", "kml", "gpx", "qgc", "imc", "moos", "moos,gpx"):
        arguments = ["export", str(local), "--format", formats, "--moos-frame"]
        frame = "local" if "," in formats else "utm"  # moos in the local frame is written
        message = _fails_cleanly([*arguments, frame], local, capsys)
        name = formats.split(",")[-1]
        assert message.startswith(f"auvplan: error: {name} export needs lat/lon"), message
        assert "has no geographic reference" in message
        assert ("--moos-frame local" in message) == (name == "moos")
    out = tmp_path / "moos"
    arguments = ["-q", "export", str(local), "--format", "moos", "--moos-frame", "local"]
    assert main([*arguments, "-o", str(out), "--tolerance-m", "0"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["blue.bhv", "green.bhv", "origin.moos"]
    origin = (out / "origin.moos").read_text()
    assert "LatOrigin  =" not in origin
    assert "set LatOrigin and LongOrigin" in origin
    table = pd.read_csv(planned_folder / "trajectories.csv")
    blue = table[table["vehicle"] == "blue"]
    _, legs = parse_moos((out / "blue.bhv").read_text())
    points = [moos_points(leg["points"])[0] for leg in legs if "points" in leg]
    assert len(points) > 2
    # each waypoint is a sample of the plan, as x = east, y = north of the plan's own frame
    samples = np.column_stack([blue["east"], blue["north"]])
    for x, y in points:
        assert np.min(np.hypot(*(samples - [x, y]).T)) < 0.01


@pytest.mark.slow
def test_plan_on_the_synthetic_bank_exports_moos_in_the_local_frame(tmp_path: Path) -> None:
    """plan --export moos --moos-frame local works without georeference (a plan: ~10 s)."""
    mission = tmp_path / "mission.toml"
    mission.write_text(MISSION.replace('file = "grid.nc"', "synthetic = true"))
    out = tmp_path / "out"
    arguments = ["-q", "plan", str(mission), "-o", str(out), "--no-figures"]
    assert main([*arguments, "--export", "moos", "--moos-frame", "local"]) == 0
    assert sorted(p.name for p in (out / "export").iterdir()) == [
        "blue.bhv", "green.bhv", "origin.moos",
    ]  # fmt: skip
    table = pd.read_csv(out / "trajectories.csv")
    green = table[table["vehicle"] == "green"]
    _, legs = parse_moos((out / "export" / "green.bhv").read_text())
    (x, y) = moos_points([leg["points"] for leg in legs if "points" in leg][-1])[0]
    # the last waypoint is the last sample, as x = east, y = north of the plan's frame
    assert (x, y) == pytest.approx((green["east"].iloc[-1], green["north"].iloc[-1]), abs=0.01)


def test_plan_export_refuses_before_planning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mission = tmp_path / "mission.toml"
    mission.write_text(MISSION.replace('file = "grid.nc"', "synthetic = true"))
    message = _fails_cleanly(
        ["plan", str(mission), "-o", str(tmp_path / "out"), "--export", "gpx"], tmp_path, capsys
    )
    assert "gpx export needs lat/lon, but the synthetic bank has no geographic" in message
    message = _fails_cleanly(
        ["plan", str(mission), "-o", str(tmp_path / "out"), "--export", "moos"], tmp_path, capsys
    )
    assert "(or export moos with --moos-frame local)" in message
    message = _fails_cleanly(
        [
            "plan",
            str(mission),
            "-o",
            str(tmp_path / "out"),
            "--stage",
            "preplan",
            "--export",
            "gpx",
        ],
        tmp_path,
        capsys,
    )
    assert "--stage preplan" in message


@pytest.mark.slow
def test_monterey_example_exports_everything(monterey_folder: Path, tmp_path: Path) -> None:
    """The issue's acceptance: the Monterey example's trajectories.nc is CF and every export is
    written (each is read back by its reader in test_formats' slow variant)."""
    findings = cf_findings(monterey_folder / "trajectories.nc", tmp_path / "cf.json")
    assert findings["high"] == [], findings
    names = {path.name for path in (monterey_folder / "export").iterdir()}
    for vehicle in ("blue", "green"):
        assert {f"{vehicle}.bhv", f"{vehicle}.plan", f"{vehicle}.imc.json"} <= names
    assert {"origin.moos", "trajectories.gpx", "trajectories.kml", "trajectories.geojson"} <= names


def test_export_writes_moos_in_the_frame_asked(planned_folder: Path, tmp_path: Path) -> None:
    """``--moos-frame local`` for LatLong2LocalGrid builds; UTM by default; anything else exit 2."""
    points = {}
    for frame in ("utm", "local"):
        out = tmp_path / frame
        extra = [] if frame == "utm" else ["--moos-frame", frame]
        arguments = ["-q", "export", str(planned_folder), "--format", "moos", "-o", str(out)]
        assert main([*arguments, *extra]) == 0
        text = (out / "blue.bhv").read_text()
        assert ("LatLong2LocalUTM" in text) == (frame == "utm")
        points[frame] = [line for line in text.splitlines() if "points" in line]
    assert points["utm"] != points["local"]
    # plan --export takes the same flag (the session's folder was planned with the default)
    assert "LatLong2LocalUTM" in (planned_folder / "export" / "blue.bhv").read_text()
    with pytest.raises(SystemExit) as stopped:
        main(["-q", "export", str(planned_folder), "--format", "moos", "--moos-frame", "grid"])
    assert stopped.value.code == 2
