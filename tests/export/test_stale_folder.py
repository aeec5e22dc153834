"""A ``--stage preplan`` rerun into a full folder leaves stale trajectories: refused.

The rerun replaces ``summary.json`` and ``maps.nc`` and keeps the old ``trajectories*``
(the output folder keeps the files a run does not write); ``summary.json``'s digest does not
list them, so ``evaluate``, ``export`` and :func:`auvplan.load` refuse the folder instead of
flying the old trajectories over the new maps.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import auvplan
from auvplan.cli.main import main
from auvplan.errors import DataFormatError


def test_trajectories_of_an_earlier_run_are_refused(
    planned_folder: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "out"
    shutil.copytree(planned_folder, folder, ignore=shutil.ignore_patterns("export"))
    mission = folder / "mission.toml"  # its grid is the folder's maps.nc
    assert main(["-q", "plan", str(mission), "--stage", "preplan", "--no-figures", "-o",
                 str(folder)]) == 0  # fmt: skip
    assert (folder / "trajectories.csv").is_file()  # kept by the rerun
    capsys.readouterr()
    for arguments in (
        ["evaluate", str(folder), "--runs", "2", "--particles", "100", "--no-figure"],
        ["export", str(folder), "--format", "gpx"],
    ):
        assert main(arguments) == 2
        lines = capsys.readouterr().err.strip().splitlines()
        assert len(lines) == 1, lines
        assert "trajectories.csv is stale" in lines[0], lines[0]
    assert not (folder / "navigation.json").exists()
    assert not (folder / "export").exists()
    with pytest.raises(DataFormatError, match="stale"):
        auvplan.load(folder)
    for stale in folder.glob("trajectories*"):
        stale.unlink()
    assert auvplan.load(folder).status is None  # a pre-planned folder, as written
    assert main(["evaluate", str(folder), "--runs", "2"]) == 2
    assert "run the plan to the full stage first" in capsys.readouterr().err
