"""Fixtures of the export tests: a synthetic plan (no planning) and a planned folder."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from auvplan.cli.main import main
from auvplan.export import FORMATS
from auvplan.export.plan import ExportPlan
from auvplan.record import export_plan as record_export_plan
from auvplan.record import read_record

from ._plans import MISSION, synthetic_plan, write_geographic_grid


@pytest.fixture(params=["synthetic", pytest.param("monterey", marks=pytest.mark.slow)])
def export_plan(request: pytest.FixtureRequest) -> ExportPlan:
    """The synthetic plan (two vehicles, one named with characters XML escapes, a circle and
    a polygon obstacle) and, in the slow suite, the Monterey example's plan read back."""
    if request.param == "synthetic":
        return synthetic_plan()
    return record_export_plan(read_record(request.getfixturevalue("monterey_folder")))


@pytest.fixture(scope="session")
def planned_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A full plan of two vehicles on a georeferenced grid, with every export (read only)."""
    root = tmp_path_factory.mktemp("planned")
    write_geographic_grid(root / "grid.nc")
    (root / "mission.toml").write_text(MISSION)
    out = root / "out"
    code = main(
        [
            "-q",
            "plan",
            str(root / "mission.toml"),
            "-o",
            str(out),
            "--no-figures",
            "--export",
            "moos,qgc,imc,gpx,kml,geojson",
        ]
    )
    assert code == 0
    return out


@pytest.fixture(scope="session")
def monterey_folder(tmp_path_factory: pytest.TempPathFactory, bathymetry_dir: Path) -> Path:
    """examples/missions/monterey.toml planned with every export (slow; needs shared data)."""
    example = Path(__file__).parents[2] / "examples" / "missions" / "monterey.toml"
    grid = bathymetry_dir / "monterey_canyon_head_ncei_13arcsec.nc"
    text = re.sub(r'(?m)^file = ".*"$', f"file = {str(grid)!r}", example.read_text())
    root = tmp_path_factory.mktemp("monterey")
    (root / "monterey.toml").write_text(text)
    out = root / "out"
    arguments = ["-q", "plan", str(root / "monterey.toml"), "-o", str(out), "--no-figures"]
    assert main([*arguments, "--export", ",".join(FORMATS)]) == 0
    return out
