"""A full disk, a too-large file or a read-only file system while the output folder is written.

Every file of the folder fails in turn, as the system reports it: a plain file's write raises
``OSError(code)`` (no file name), a NetCDF file's write raises the library's
``RuntimeError("NetCDF: HDF error")`` and the file system shows the cause. The run stops with
one WriteError naming the file in the folder asked for and the cause, and leaves nothing.
"""

from __future__ import annotations

import builtins
import errno
import io
import os
import re
import resource
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any, Self

import pytest
from xarray.backends.netCDF4_ import NetCDF4DataStore

import auvplan
from auvplan.cli.main import main
from auvplan.errors import WriteError
from auvplan.io import writing as writing_module
from auvplan.io.writing import shown_path

CODES = (errno.ENOSPC, errno.EFBIG, errno.EROFS)
DATA_FILES = (
    "summary.json",
    "mission.toml",
    "maps.nc",
    "paths.geojson",
    "desired.csv",
    "trajectories.csv",
    "trajectories.nc",
    "export/trajectories.gpx",
)
FIGURE_FILES = ("paths.png", "report.html")
#: Written by ``api/folder.py`` (another owner), which does not use ``io.writing`` yet.


class _RefusedFile:
    """A file opened for writing whose every write fails with ``OSError(code)``."""

    def __init__(self, handle: Any, code: int) -> None:
        self._handle, self._code = handle, code

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self._handle.close()

    def write(self, data: object) -> int:
        raise OSError(self._code, os.strerror(self._code))

    def __getattr__(self, name: str) -> Any:
        return getattr(self._handle, name)


def _refuse(monkeypatch: pytest.MonkeyPatch, name: str, code: int) -> None:
    """Make every write of the file ``name`` (a path's last parts) fail as ``code`` would."""

    def is_refused(path: object) -> bool:  # (a staged file by the name the user gave)
        return shown_path(Path(str(path))).as_posix().endswith("/" + name)

    if name.endswith(".nc"):
        close = NetCDF4DataStore.close

        def failing_close(store: NetCDF4DataStore, **kwargs: Any) -> None:
            close(store, **kwargs)
            if is_refused(store._filename):
                raise RuntimeError("NetCDF: HDF error")

        monkeypatch.setattr(NetCDF4DataStore, "close", failing_close)
        full = SimpleNamespace(f_flag=os.ST_RDONLY if code == errno.EROFS else 0, f_frsize=4096)
        full.f_bavail = 0 if code == errno.ENOSPC else 1 << 20
        monkeypatch.setattr(writing_module.os, "statvfs", lambda path: full)
        if code == errno.EFBIG:
            monkeypatch.setattr(writing_module.resource, "getrlimit", lambda kind: (1, 1))
        return
    real_open = io.open

    def refusing_open(file: Any, mode: str = "r", *args: Any, **kwargs: Any) -> Any:
        handle = real_open(file, mode, *args, **kwargs)
        return _RefusedFile(handle, code) if "w" in mode and is_refused(file) else handle

    monkeypatch.setattr(io, "open", refusing_open)  # pathlib's
    monkeypatch.setattr(builtins, "open", refusing_open)  # matplotlib's


def _expected(folder: Path, name: str, code: int) -> str:
    cause = os.strerror(code) + (" (NetCDF: HDF error)" if name.endswith(".nc") else "")
    return f"cannot write {folder.resolve() / name}: {cause}"


def _assert_nothing_left(folder: Path) -> None:
    assert not folder.exists()
    assert not [path for path in folder.parent.iterdir() if path.name.startswith(".out.")]


@pytest.mark.parametrize("code", CODES, ids=errno.errorcode.get)
@pytest.mark.parametrize("name", DATA_FILES)
def test_a_refused_data_file_stops_the_save_naming_it(
    mission_plan: auvplan.MissionPlan,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    name: str,
    code: int,
) -> None:
    out = tmp_path / "out"
    _refuse(monkeypatch, name, code)
    exports = ["gpx"] if name.startswith("export/") else []  # (the exports alone import pyproj)
    with pytest.raises(WriteError) as caught:
        mission_plan.save(out, figures=False, exports=exports)
    assert str(caught.value) == _expected(out, name, code)
    _assert_nothing_left(out)


@pytest.mark.parametrize("name", FIGURE_FILES)
def test_a_refused_figure_or_report_stops_the_save_naming_it(
    mission_plan: auvplan.MissionPlan, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, name: str
) -> None:
    out = tmp_path / "out"
    _refuse(monkeypatch, name, errno.ENOSPC)
    with pytest.raises(WriteError) as caught:
        mission_plan.save(out, dpi=30)
    assert str(caught.value) == _expected(out, name, errno.ENOSPC)
    _assert_nothing_left(out)


def test_a_full_disk_while_plan_writes_maps_nc_is_one_line(
    mission_file: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    out = tmp_path / "out"
    _refuse(monkeypatch, "maps.nc", errno.ENOSPC)
    code = main(["-q", "plan", str(mission_file), "-o", str(out), "--stage", "preplan"])
    captured = capsys.readouterr()
    assert code == 2
    assert captured.err.splitlines() == [
        f"auvplan: error: {_expected(out, 'maps.nc', errno.ENOSPC)}"
    ]
    _assert_nothing_left(out)


def _file_size_limit(limit: int) -> Callable[[], None]:
    """A child process's start: writes past ``limit`` bytes fail with EFBIG (no signal)."""

    def limit_writes() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return limit_writes


def test_a_real_file_size_limit_is_one_line_naming_the_file(
    mission_file: Path, tmp_path: Path
) -> None:
    out = tmp_path / "out"
    command = [sys.executable, "-m", "auvplan", "-q", "plan", str(mission_file), "-o", str(out)]
    completed = subprocess.run(
        [*command, "--stage", "preplan", "--no-figures"],
        capture_output=True,
        text=True,
        timeout=600,
        preexec_fn=_file_size_limit(32 * 1024),  # maps.nc is larger; the kernels are cached
        check=False,
    )
    assert completed.returncode == 2
    lines = completed.stderr.splitlines()
    assert len(lines) == 1, completed.stderr
    assert re.fullmatch(
        rf"auvplan: error: cannot write {re.escape(str(out.resolve()))}/\S+: File too large.*",
        lines[0],
    )
    _assert_nothing_left(out)


@pytest.mark.parametrize("name", ["maps.nc", "maps.png"])
def test_a_refused_file_of_auvplan_maps_is_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], name: str
) -> None:
    out = tmp_path / "out"
    _refuse(monkeypatch, name, errno.ENOSPC)
    assert main(["-q", "maps", "synthetic", "--seed", "3", "-o", str(out)]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"auvplan: error: {_expected(out, name, errno.ENOSPC)}"
    ]
    _assert_nothing_left(out)


def test_a_refused_vehicle_figure_is_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    figure = tmp_path / "vehicle.png"
    _refuse(monkeypatch, "vehicle.png", errno.EROFS)
    assert main(["-q", "vehicle", "--figure", str(figure)]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"auvplan: error: cannot write {figure.resolve()}: Read-only file system"
    ]
    assert list(tmp_path.iterdir()) == []
