"""A write that the file system refuses is one WriteError naming the file and the cause."""

from __future__ import annotations

import errno
import os
from pathlib import Path
from types import SimpleNamespace

import pytest

from auvplan.errors import WriteError
from auvplan.io import writing as writing_module
from auvplan.io.writing import FAULTS, shown_path, writing

NETCDF_ERROR = RuntimeError("NetCDF: HDF error")  # what netCDF4 raises for any failed write


@pytest.mark.parametrize("code", sorted(FAULTS))
def test_a_file_system_fault_names_the_file_and_its_cause(tmp_path: Path, code: int) -> None:
    staged = tmp_path / ".run1.ab12_x9z.partial" / "maps.nc"
    with pytest.raises(WriteError) as caught, writing(staged):
        raise OSError(code, os.strerror(code))
    assert str(caught.value) == f"cannot write {tmp_path / 'run1' / 'maps.nc'}: {os.strerror(code)}"


def test_other_errors_pass_unchanged(tmp_path: Path) -> None:
    with pytest.raises(PermissionError), writing(tmp_path / "a.csv"):
        raise PermissionError(errno.EACCES, "Permission denied")
    with pytest.raises(RuntimeError, match="not NetCDF"), writing(tmp_path / "a.nc"):
        raise RuntimeError("not NetCDF")


def _file_system(*, read_only: bool = False, free: int = 1 << 30) -> SimpleNamespace:
    """What ``os.statvfs`` says of a file system (``free`` bytes available)."""
    flags = os.ST_RDONLY if read_only else 0
    return SimpleNamespace(f_flag=flags, f_bavail=free // 4096, f_frsize=4096)


@pytest.mark.parametrize(
    ("file_system", "limit", "cause"),
    [
        (_file_system(free=8192), None, "No space left on device (NetCDF: HDF error)"),
        (_file_system(read_only=True), None, "Read-only file system (NetCDF: HDF error)"),
        (_file_system(), 4096, "File too large (NetCDF: HDF error)"),
        (_file_system(), None, "NetCDF: HDF error"),  # the library says no more
    ],
)
def test_the_netcdf_librarys_error_gets_its_cause_from_the_file_system(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    file_system: SimpleNamespace,
    limit: int | None,
    cause: str,
) -> None:
    monkeypatch.setattr(writing_module.os, "statvfs", lambda path: file_system)
    if limit is not None:
        monkeypatch.setattr(writing_module.resource, "getrlimit", lambda kind: (limit, limit))
    with pytest.raises(WriteError) as caught, writing(tmp_path / "maps.nc"):
        raise NETCDF_ERROR
    assert str(caught.value) == f"cannot write {tmp_path / 'maps.nc'}: {cause}"


def test_staging_names_are_shown_as_the_target() -> None:
    assert shown_path(Path("/a/.out.k_3j9x0q.partial/export/x.kml")) == Path("/a/out/export/x.kml")
    assert shown_path(Path("/a/.paths.k_3j9x0q.partial.svg")) == Path("/a/paths.svg")
    assert shown_path(Path("/a/.hidden/partial.nc")) == Path("/a/.hidden/partial.nc")
