"""Fixtures of the export tests: a synthetic plan (no planning) and a planned folder."""

from __future__ import annotations

from pathlib import Path

import pytest

from auvplan.cli.main import main
from auvplan.export.plan import ExportPlan

from ._plans import MISSION, synthetic_plan, write_geographic_grid


@pytest.fixture
def export_plan() -> ExportPlan:
    """Two vehicles (one with characters XML must escape), a circle and a polygon obstacle."""
    return synthetic_plan()


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
