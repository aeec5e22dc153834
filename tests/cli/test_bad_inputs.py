"""Every bad input found by the user-fuzzing pass: exit 2, one stderr line, nothing left behind.

Each case builds its input files in ``tmp_path``, runs the command line in-process, and checks
the exact contract: exit code 2, exactly one line on stderr naming the cause, nothing on
stdout, no traceback, and ``tmp_path`` (inputs, an earlier output folder) byte-for-byte as it
was, with no new file or folder. SIGTERM is sent to a real ``auvplan`` process.
"""

from __future__ import annotations

import json
import logging
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import Literal

import numpy as np
import pytest
import xarray as xr
from _cli import run_cli

from auvplan.cli.main import EXIT_TERMINATED

#: The ``write_plan_folder`` fixture of ``tests/conftest.py``.
PlanFolderWriter = Callable[..., Path]

MEDUSA = resources.files("auvplan").joinpath("data", "vehicles", "medusa.toml").read_text()
DEMO = resources.files("auvplan").joinpath("data", "missions", "demo.toml").read_text()


def _tree(root: Path) -> dict[str, bytes | None]:
    """Every entry below ``root``: relative path -> file content (None for folders)."""
    return {
        str(path.relative_to(root)): path.read_bytes() if path.is_file() else None
        for path in sorted(root.rglob("*"))
    }


def _write(path: Path, content: str | bytes) -> str:
    if isinstance(content, str):
        content = content.encode()
    path.write_bytes(content)
    return str(path)


def _maps_on_netcdf(
    name: str,
    lat: tuple[float, float],
    lon: tuple[float, float],
    elevation: float | np.ndarray,
    netcdf_format: Literal["NETCDF4", "NETCDF3_CLASSIC"] = "NETCDF4",
) -> Callable[[Path], list[str]]:
    """Arguments of ``auvplan maps`` on a 12 x 12 lat/lon NetCDF of ``elevation`` [m], the
    coordinates stored first as in GEBCO's and NCEI's files."""

    def build(tmp: Path) -> list[str]:
        dataset = xr.Dataset(coords={"lat": np.linspace(*lat, 12), "lon": np.linspace(*lon, 12)})
        dataset["elevation"] = ("lat", "lon"), np.broadcast_to(elevation, (12, 12))
        dataset.to_netcdf(tmp / name, format=netcdf_format)
        return ["maps", str(tmp / name), "-o", str(tmp / "out")]

    return build


def _maps_on_raster(name: str, driver: str) -> Callable[[Path], list[str]]:
    """Arguments of ``auvplan maps`` on a 60 x 60 metric GeoTIFF or ESRI ASCII grid (a slope)."""

    def build(tmp: Path) -> list[str]:
        import rasterio
        from affine import Affine

        depth = 40.0 + 0.1 * np.add.outer(np.arange(60.0), np.arange(60.0))
        profile = {"height": 60, "width": 60, "count": 1, "dtype": "float32"}
        with rasterio.open(
            tmp / name,
            "w",
            driver=driver,
            transform=Affine(10.0, 0.0, 0.0, 0.0, -10.0, 600.0),
            **profile,
        ) as raster:
            raster.write(depth.astype(np.float32), 1)
        return ["maps", str(tmp / name), "-o", str(tmp / "out")]

    return build


def _cut_to_a_third(build: Callable[[Path], list[str]]) -> Callable[[Path], list[str]]:
    """The same arguments, the input file (``argv[1]``) cut to its first third of bytes, as an
    interrupted download leaves it."""

    def cut(tmp: Path) -> list[str]:
        argv = build(tmp)
        data = Path(argv[1]).read_bytes()
        Path(argv[1]).write_bytes(data[: len(data) // 3])
        return argv

    return cut


def _maps_on_xyz(name: str, table: np.ndarray) -> Callable[[Path], list[str]]:
    """Arguments of ``auvplan maps`` on an XYZ file of ``table``."""

    def build(tmp: Path) -> list[str]:
        np.savetxt(tmp / name, table, fmt="%.3f")
        return ["maps", str(tmp / name), "-o", str(tmp / "out")]

    return build


def _survey(n: int = 300, offset: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    rng = np.random.default_rng(5)
    east, north = rng.uniform(0.0, 300.0, n), rng.uniform(0.0, 200.0, n)
    return np.column_stack(
        [500_000.0 + offset[0] + east, 4_100_000.0 + offset[1] + north, 30.0 + 0.05 * north]
    )


def _previous_output(tmp: Path) -> Path:
    """An earlier run's output folder that a failed run must leave untouched."""
    out = tmp / "out"
    out.mkdir()
    (out / "maps.nc").write_bytes(b"earlier maps")
    (out / "notes.txt").write_text("mine")
    return out


def _propeller_not_utf8(tmp: Path) -> list[str]:
    _write(
        tmp / "prop.csv",
        "# Wageningen, transcribed by Jürgen\nk,A_T,B_T,A_Q,B_Q\n".encode("latin-1"),
    )
    boat = MEDUSA.replace('"wageningen_b4-70_pd1.4"', '"prop.csv"')
    return ["vehicle", _write(tmp / "boat.toml", boat)]


def _clash(tmp: Path) -> list[str]:
    (_previous_output(tmp) / "maps.png").mkdir()  # a folder where the run writes a file
    return ["maps", "synthetic", "-o", str(tmp / "out")]


def _plan_demo(edit: Callable[[str], str]) -> Callable[[Path], list[str]]:
    """Arguments of ``auvplan plan --stage preplan`` on the demo mission as ``edit`` changes it."""

    def build(tmp: Path) -> list[str]:
        mission = _write(tmp / "m.toml", edit(DEMO))
        return ["plan", mission, "-o", str(tmp / "out"), "--stage", "preplan", "--no-figures"]

    return build


#: A polygon over blue's start (10, 400) m in the demo mission.
REEF = """
[[obstacle]]
name = "reef"
polygon = [[0.0, 390.0], [0.0, 410.0], [20.0, 410.0], [20.0, 390.0]]
"""


def _current_file(path: Path, nan_rows: slice, nan_cols: slice) -> None:
    """A still current on local north/east axes [m] around the demo's map (0 … 400 m north,
    0 … 800 m east, nodes every 50 m), NaN at the nodes ``[nan_rows, nan_cols]``."""
    north, east = np.arange(-100.0, 501.0, 50.0), np.arange(-100.0, 901.0, 50.0)
    velocity = np.full((north.size, east.size), 0.1)
    velocity[nan_rows, nan_cols] = np.nan
    attrs = {"units": "m s-1"}
    xr.Dataset(
        {"u": (("north", "east"), velocity, attrs), "v": (("north", "east"), velocity, attrs)},
        coords={"north": north, "east": east},
    ).to_netcdf(path)


def _plan_in_current(nan_rows: slice, nan_cols: slice) -> Callable[[Path], list[str]]:
    """The demo mission (preplan) in a current file with NaN at the nodes given."""

    def build(tmp: Path) -> list[str]:
        _current_file(tmp / "cur.nc", nan_rows, nan_cols)
        return _plan_demo(lambda mission: mission + '\n[current]\nfile = "cur.nc"\n')(tmp)

    return build


#: case -> (argv builder, text the one stderr line must contain)
CASES: dict[str, tuple[Callable[[Path], list[str]], str]] = {
    # 1. text files that are not UTF-8 or not parseable
    "vehicle toml not utf-8": (
        lambda tmp: ["vehicle", _write(tmp / "boat.toml", MEDUSA.encode("utf-16"))],
        "boat.toml: not UTF-8 text (byte 0xff at offset 0)",
    ),
    "propeller csv not utf-8": (_propeller_not_utf8, "prop.csv: not UTF-8 text (byte 0xfc"),
    "5000-deep toml array": (
        lambda tmp: ["vehicle", _write(tmp / "deep.toml", "a = " + "[" * 5000 + "]" * 5000)],
        "deep.toml: not valid TOML (arrays or tables nested too deeply)",
    ),
    # 2. XYZ surveys: degenerate geometry, absurd grid size
    "collinear soundings": (
        _maps_on_xyz("line.xyz", _survey()[:, [0, 0, 2]]),
        "line.xyz: the 300 soundings lie on one line",
    ),
    "xyz over two far areas": (
        _maps_on_xyz("two.xyz", np.vstack([_survey(), _survey(offset=(2e6, 3e6))])),
        "two.xyz: the grid would need",
    ),
    # 3. NetCDF off the Earth or without a valid value
    "netcdf latitude > 90": (
        _maps_on_netcdf("pole.nc", (89.5, 95.0), (10.0, 10.1), -50.0),
        "pole.nc: latitudes 89.5 … 95 deg are outside [-90, 90] deg",
    ),
    "netcdf longitude 400": (
        _maps_on_netcdf("lon.nc", (40.0, 40.1), (400.0, 400.1), -50.0),
        "lon.nc: longitudes 400 … 400.1 deg are outside [-180, 360] deg",
    ),
    "netcdf all -1e308": (
        _maps_on_netcdf("huge.nc", (40.0, 40.1), (10.0, 10.1), -1e308),
        "huge.nc: no valid value: all 144 values are no data or beyond ±12000 m",
    ),
    # 3b. bathymetry cut short (an interrupted download): refused, naming what is missing
    "netcdf-3 cut to a third": (
        _cut_to_a_third(
            _maps_on_netcdf("cut3.nc", (40.0, 40.1), (10.0, 10.1), -50.0, "NETCDF3_CLASSIC")
        ),
        "cut3.nc: truncated NetCDF: the file has",
    ),
    "netcdf-4 cut to a third": (
        _cut_to_a_third(_maps_on_netcdf("cut4.nc", (40.0, 40.1), (10.0, 10.1), -50.0)),
        "cut4.nc: truncated NetCDF-4: the file has",
    ),
    "geotiff cut to a third": (
        _cut_to_a_third(_maps_on_raster("cut.tif", "GTiff")),
        "cut.tif: truncated GeoTIFF: the file has",
    ),
    "esri ascii cut to a third": (
        _cut_to_a_third(_maps_on_raster("cut.asc", "AAIGrid")),
        "cut.asc: ESRI ASCII grid cut short: the header declares 60 x 60 = 3600 values",
    ),
    "xyz cut to a third": (
        _cut_to_a_third(_maps_on_xyz("cut.xyz", _survey(301))),  # 30-byte lines: cut in line 101
        "cut.xyz: line 101 has 1 column, need 3",
    ),
    # 3c. starts and goals
    "polygon over a start": (
        _plan_demo(lambda mission: mission + REEF),
        "auvplan: error: blue: start (10, 400) m is inside obstacle 'reef'",
    ),
    "goal == start": (
        _plan_demo(
            lambda mission: mission.replace(
                "goal = { north = 380.0, east = 450.0", "goal = { north = 10.0, east = 440.0"
            )
        ),
        "green: goal (10, 440) m is 0 m from the start (10, 440) m; give a goal at least 1 mm",
    ),
    # 3d. mission values the seabed or physics rule out
    "depth_m below the seabed": (
        _plan_demo(lambda mission: mission + "\n[mission]\ndepth_m = 5000.0\n"),
        (
            "auvplan: error: mission.depth_m = 5000 m is not above the seabed along blue's path "
            "(seabed 22.5 m deep at north 325 m, east 402 m; the deepest seabed is 43.5 m along "
            "the paths and 60.0 m over the map): give depth_m < 22.5 m"
        ),
    ),
    "safety_radius_m = 1e-15": (
        _plan_demo(
            lambda mission: mission.replace("safety_radius_m = 5.0", "safety_radius_m = 1e-15")
        ),
        "fleet.safety_radius_m: Input should be greater than or equal to 0.01, got 1e-15",
    ),
    "current file with a NaN block over the map's water": (
        _plan_in_current(slice(4, 7), slice(6, 10)),  # north 100 … 200 m, east 200 … 350 m
        (
            "current file cur.nc: v is NaN over the map's water: at 1900 of its 20301 water "
            "cells, first north 76 m, east 176 m (NaN is read as still water only over land"
        ),
    ),
    # 4. vehicle numbers outside their physical range
    "vehicle n_max = 1e-9": (
        lambda tmp: [
            "vehicle",
            _write(tmp / "boat.toml", MEDUSA.replace("value = 75.0,", "value = 1e-9,")),
        ],
        "propulsion.n_max: Input should be greater than or equal to 0.5, got 1e-09 rev/s",
    ),
    # 5. command-line values
    "maps --seed -1": (
        lambda tmp: ["maps", "synthetic", "--seed", "-1", "-o", str(tmp / "out")],
        "seed must be an integer >= 0, got -1",
    ),
    "maps --omega 1.7e308": (
        lambda tmp: ["maps", "synthetic", "--omega", "1.7e308", "-o", str(tmp / "out")],
        "omega must be in (0, 1e+06], got 1.7e+308",
    ),
    "maps --seed not a number": (
        lambda tmp: ["maps", "synthetic", "--seed", "x", "-o", str(tmp / "out")],
        "auvplan maps: error: argument --seed: invalid int value: 'x'",
    ),
    "vehicle --figure fig.xyz": (
        lambda tmp: ["vehicle", "--figure", str(tmp / "fig.xyz")],
        "unsupported extension '.xyz' (supported: .avif, .eps,",
    ),
    "vehicle --figure .": (
        lambda tmp: ["vehicle", "--figure", str(tmp) + "/."],
        "is a folder, not a file name",
    ),
    "vehicle --figure in a missing folder": (
        lambda tmp: ["vehicle", "--figure", str(tmp / "nowhere" / "fig.png")],
        "nowhere does not exist",
    ),
    # 6. -q and -v together
    "-q before and -v after the verb": (
        lambda tmp: ["-q", "maps", "synthetic", "-v", "-o", str(tmp / "out")],
        "-q/--quiet and -v/--verbose exclude each other",
    ),
    # 7. output folders
    "-o an existing file": (
        lambda tmp: ["maps", "synthetic", "-o", _write(tmp / "maps.png", b"a file")],
        "maps.png exists and is not a folder",
    ),
    "-o the mission file itself": (
        lambda tmp: [
            "plan",
            _write(tmp / "m.toml", DEMO),
            "-o",
            str(tmp / "m.toml"),
            "--stage",
            "preplan",
        ],
        "m.toml exists and is not a folder",
    ),
    "-o below a file": (
        lambda tmp: ["maps", "synthetic", "-o", _write(tmp / "f", b"x") + "/out"],
        "f is not a folder",
    ),
    "-o an unwritable place": (
        lambda tmp: ["maps", "synthetic", "-o", "/proc/auvplan-test/out"],
        "/proc/auvplan-test",
    ),
    "-o holding a folder named like an output file": (
        _clash,
        "maps.png is a folder but the run writes a file",
    ),
}


@pytest.mark.parametrize("case", list(CASES))
def test_bad_input_exits_2_with_one_line_and_leaves_nothing(
    case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    build, expected = CASES[case]
    _assert_refused(build(tmp_path), tmp_path, expected, capsys)
    assert not Path("/proc/auvplan-test").exists()


def _assert_refused(
    argv: list[str], tmp: Path, expected: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """``argv`` exits 2 with one stderr line holding ``expected``, and ``tmp`` is unchanged."""
    before = _tree(tmp)
    code, out, err = run_cli(argv, capsys)
    assert code == 2, err
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("auvplan"), err
    assert expected in lines[0]
    assert "Traceback" not in err
    assert out == ""
    assert _tree(tmp) == before


def test_real_netcdf_cut_to_a_third_is_refused(
    bathymetry_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """NCEI's Monterey grid (NetCDF-3) cut to its first third: read before as two thirds of
    no data plus garbage rows, and mapped with exit 0."""
    data = (bathymetry_dir / "monterey_canyon_head_ncei_13arcsec.nc").read_bytes()
    cut = _write(tmp_path / "monterey.nc", data[: len(data) // 3])
    expected = (
        "monterey.nc: truncated NetCDF: the file has 70848 bytes but its header places data "
        "past them; 69 % of the values of elevation are missing"
    )
    _assert_refused(["maps", cut, "-o", str(tmp_path / "out")], tmp_path, expected, capsys)


def test_current_folder_as_output_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    code, _, err = run_cli(["maps", "synthetic", "-o", "."], capsys)
    assert code == 2
    assert err == "auvplan: error: output folder . is the current folder or contains it: " + (
        "choose a new or dedicated folder\n"
    )
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "argv",
    [
        ["-q", "maps", "synthetic", "--block", "8", "8"],
        ["maps", "-q", "synthetic", "--block", "8", "8"],
        ["maps", "synthetic", "--block", "8", "8", "-q"],
    ],
)
def test_quiet_before_or_after_the_verb(
    argv: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    previous = _previous_output(tmp_path)
    code, out, err = run_cli([*argv, "-o", str(previous)], capsys)
    assert (code, out, err) == (0, "", "")
    assert sorted(p.name for p in previous.iterdir()) == ["maps.nc", "maps.png", "notes.txt"]
    assert (previous / "notes.txt").read_text() == "mine"  # other files are kept
    assert (previous / "maps.nc").read_bytes() != b"earlier maps"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_verbose_after_the_verb_enables_debug(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run_cli(["vehicle", "--json", "-v"], capsys)
    assert code == 0
    assert '"characteristics"' in out
    assert logging.getLogger("auvplan").level == logging.NOTSET  # restored after the run


def test_plan_accepts_quiet_after_the_verb(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mission = _write(tmp_path / "demo.toml", DEMO)
    out = tmp_path / "out"
    argv = ["plan", "-q", mission, "-o", str(out), "--stage", "preplan", "--no-figures"]
    code, stdout, _ = run_cli(argv, capsys)
    assert (code, stdout) == (0, "")
    assert (out / "paths.geojson").is_file()


def test_stray_fix_and_absurd_values_are_warnings_not_errors(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    """One (0, 0) fix among a survey, and -1e308 in a NetCDF: mapped, with a counted warning."""
    survey = _survey()
    survey[7] = (0.0, 0.0, 31.0)
    elevation = -50.0 - 0.5 * np.add.outer(np.arange(12.0), np.arange(12.0))
    elevation[4, 4] = -1e308
    builds = [
        _maps_on_xyz("stray.xyz", survey),
        _maps_on_netcdf("absurd.nc", (40.0, 40.01), (10.0, 10.01), elevation),
    ]
    with caplog.at_level(logging.WARNING):
        for build in builds:
            code, _, err = run_cli([*build(tmp_path), "-q"], capsys)
            assert (code, err) == (0, "")
            assert (tmp_path / "out" / "maps.png").is_file()
    assert "stray.xyz: dropped 1 of 300 soundings" in caplog.text
    assert "absurd.nc: 1 of 144 values beyond ±12000 m treated as no data" in caplog.text


def test_current_nan_off_the_maps_water_is_still_water(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """NaN at nodes nearest no water cell of the map (as ocean models leave land) plans."""
    argv = _plan_in_current(slice(0, 2), slice(None))(tmp_path)  # the rows south of the map
    code, _, err = run_cli([*argv, "-q"], capsys)
    assert (code, err) == (0, "")


@pytest.mark.parametrize(("key", "value"), [("lat", float("nan")), ("lat", 95.0), ("lon", 1e400)])
def test_export_refuses_an_origin_off_the_earth(
    key: str,
    value: float,
    tmp_path: Path,
    write_plan_folder: PlanFolderWriter,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """summary.json's terrain.origin with a NaN lat was exported (``LatOrigin = nan``)."""
    from auvplan.record import VehicleTrajectory
    from auvplan.terrain import BathymetryGrid, GridGeometry, LocalProjection, compute_terrain_maps

    time = np.arange(0.0, 60.5, 0.5)
    states = np.zeros((time.size, 6))
    states[:, 0], states[:, 1], states[:, 3] = 20.0 + time, 100.0, 1.0
    track = VehicleTrajectory(
        "blue", ("north", "east", "psi", "u", "v", "r"), ("tau_u", "tau_r"), time, states,
        np.zeros((time.size - 1, 2)), np.full(time.size, 40.0),
    )  # fmt: skip
    depth = np.full((40, 60), 40.0) + 0.01 * np.arange(60.0)
    maps = compute_terrain_maps(
        BathymetryGrid(depth, GridGeometry(40, 60, 4.0, 4.0), LocalProjection(36.8, -121.81))
    )
    origin = {"north": 0.0, "east": 0.0, "lat": 36.8, "lon": -121.81}
    folder = write_plan_folder(
        tmp_path / "out", maps, {"terrain_aware": (track,)},
        extra={"terrain": {"name": "test", "origin": origin}},
    )  # fmt: skip
    summary = json.loads((folder / "summary.json").read_text())
    summary["terrain"]["origin"][key] = value
    (folder / "summary.json").write_text(json.dumps(summary))
    _assert_refused(
        ["export", str(folder), "--format", "moos"],
        tmp_path,
        f"summary.json: entry terrain.origin.{key}: input should be",
        capsys,
    )


# --- SIGTERM on a real process ---------------------------------------------------------------


def _start_maps(out: Path) -> subprocess.Popen[str]:
    source = Path(__file__).parents[2] / "src"
    env = {**os.environ, "PYTHONPATH": f"{source}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    command = [sys.executable, "-m", "auvplan.cli.main", "-q", "maps", "synthetic", "-o", str(out)]
    return subprocess.Popen(command, env=env, stderr=subprocess.PIPE, text=True)


def _wait_for(condition: Callable[[], bool], process: subprocess.Popen[str]) -> bool:
    deadline = time.monotonic() + 60.0
    while time.monotonic() < deadline and process.poll() is None:
        if condition():
            return True
        time.sleep(0.005)
    return False


def test_sigterm_while_writing_leaves_the_old_folder_intact(tmp_path: Path) -> None:
    """SIGTERM once the staging folder exists: exit 143, one line, old output untouched.

    If the signal lands during the final swap it is held until the swap ends, so the folder
    is then completely new; either way it is never half-updated and nothing is left over.
    """
    for attempt in range(3):
        root = tmp_path / f"attempt{attempt}"
        root.mkdir()
        previous = _previous_output(root)
        before = _tree(root)
        process = _start_maps(previous)
        staged = _wait_for(lambda root=root: any(root.glob(".out.*.partial")), process)
        assert staged, "the run never staged its output"
        process.send_signal(signal.SIGTERM)
        _, err = process.communicate(timeout=60)
        assert process.returncode == EXIT_TERMINATED, err
        assert err == "auvplan: terminated\n"
        after = _tree(root)
        if after == before:
            return
        assert sorted(after) == ["out", "out/maps.nc", "out/maps.png", "out/notes.txt"]
    pytest.fail("SIGTERM never landed before the swap in 3 attempts")


def _catches_sigterm(process: subprocess.Popen[str]) -> bool:
    """True once the process has a SIGTERM handler installed (Linux: SigCgt in /proc)."""
    status = Path(f"/proc/{process.pid}/status").read_text()
    caught = next(line.split()[1] for line in status.splitlines() if line.startswith("SigCgt:"))
    return bool(int(caught, 16) & (1 << (signal.SIGTERM - 1)))


@pytest.mark.skipif(not Path("/proc/self/status").is_file(), reason="needs Linux /proc")
def test_sigterm_before_writing_creates_nothing(tmp_path: Path) -> None:
    out = tmp_path / "new" / "out"
    process = _start_maps(out)
    assert _wait_for(lambda: _catches_sigterm(process), process)
    process.send_signal(signal.SIGTERM)  # while importing and computing: nothing written yet
    _, err = process.communicate(timeout=60)
    assert (process.returncode, err) == (EXIT_TERMINATED, "auvplan: terminated\n")
    assert list(tmp_path.iterdir()) == []
