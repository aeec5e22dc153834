"""Issue 28: the waypoint tolerance is bounded (0 to half the Earth's circumference) everywhere.

``auvplan export`` and ``plan --export`` refuse a tolerance out of range as a one-line usage
error (exit 2, nothing written, before any planning); the library refuses it too.
"""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from auvplan.cli.main import main
from auvplan.errors import InputError
from auvplan.export import MAX_TOLERANCE_M, render_exports
from auvplan.export.plan import ExportPlan

OUT_OF_RANGE = ["1e300", "3e7", "nan", "-inf", "-1"]


def _usage_error(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """The one stderr line of ``auvplan argv``, which must end with exit code 2."""
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    (line,) = captured.err.strip().splitlines()
    return line


@pytest.mark.parametrize("tolerance", OUT_OF_RANGE)
def test_export_refuses_a_tolerance_out_of_range(
    planned_folder: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], tolerance: str
) -> None:
    out = tmp_path / "export"
    line = _usage_error(
        ["export", str(planned_folder), "--format", "gpx", "-o", str(out),
         f"--tolerance-m={tolerance}"],
        capsys,
    )  # fmt: skip
    assert line.startswith("auvplan export: error: argument --tolerance-m: waypoint tolerance")
    assert f"<= {MAX_TOLERANCE_M:g} m" in line
    assert not out.exists()


def test_plan_export_refuses_it_before_planning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    started = time.perf_counter()
    line = _usage_error(
        ["plan", str(tmp_path / "mission.toml"), "-o", str(out), "--export", "gpx",
         "--tolerance-m", "1e300"],
        capsys,
    )  # fmt: skip
    assert "argument --tolerance-m: waypoint tolerance must be >= 0 and <= 2e+07 m" in line
    assert time.perf_counter() - started < 10.0
    assert not out.exists()


@pytest.mark.parametrize("tolerance", [float(text) for text in OUT_OF_RANGE])
def test_render_exports_refuses_it(export_plan: ExportPlan, tolerance: float) -> None:
    with pytest.raises(InputError, match="waypoint tolerance must be >= 0"):
        render_exports(export_plan, ["gpx"], tolerance=tolerance)
