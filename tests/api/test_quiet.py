"""``auvplan -q plan``: one line or nothing on stderr, also with vehicles named in CJK and emoji.

A fresh process (``python -m auvplan``), as a user runs it: its console is the real stderr,
where matplotlib's glyph warnings and every logged warning used to land.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from .conftest import MISSION, NAMES, write_ridge

#: A two-vehicle fleet; one vehicle named in CJK characters and emoji (no font has them here).
CJK_NAMES = ("蓝鲸 🐋", "海豚🐬号")


def test_a_quiet_two_vehicle_run_prints_nothing(tmp_path: Path) -> None:
    mission = MISSION
    for name, new in zip(NAMES, CJK_NAMES, strict=True):
        mission = mission.replace(f'"{name}"', f'"{new}"')
    write_ridge(tmp_path / "ridge.nc")
    (tmp_path / "mission.toml").write_text(mission, encoding="utf-8")
    out = tmp_path / "out"
    command = [sys.executable, "-m", "auvplan", "-q", "plan", "mission.toml", "-o", str(out)]
    completed = subprocess.run(
        [*command, "--stage", "deconflict", "--dpi", "40"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "PYTHONWARNINGS": "default"},  # what a user's Python shows
        check=False,
    )
    assert completed.returncode == 0, completed.stderr
    assert completed.stderr == ""
    assert completed.stdout == ""
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert [vehicle["name"] for vehicle in summary["vehicles"]] == list(CJK_NAMES)
    assert {"paths.png", "coordination.png"} <= {path.name for path in out.iterdir()}
