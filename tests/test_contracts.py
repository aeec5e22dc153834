"""The places docs/architecture.md names for a new output file, cost term or constraint.

A newcomer who adds one and misses a place fails here: a file name declared in
``record/files.py`` but never written by a full run (or written but not declared), a running
cost term added to ``vehicle_cost_terms`` but not named in ``RUNNING_TERMS`` (or the reverse),
a constraint block without a label per row or missing from the slack report.
"""

from __future__ import annotations

from pathlib import Path

import casadi as ca
import pytest

from auvplan.cli.main import main
from auvplan.io.vehicles import load_vehicle, packaged_vehicle_types
from auvplan.mission.costs import constraint_slack, cost_breakdown
from auvplan.mission.fleet import COST_TERMS, RUNNING_TERMS, vehicle_cost_terms
from auvplan.record import files
from auvplan.vehicle import build_vehicle_model

GOLDEN = Path(__file__).parent / "regression" / "golden_mission.toml"
#: Declared names a plain ``auvplan plan`` does not write: other verbs write them.
WRITTEN_BY_OTHER_VERBS = {files.NAVIGATION_FILE, files.RUN_RECORD_FILE, files.EXPORT_FOLDER}
#: Declared names written only when the mission names input files to carry (the golden
#: mission's terrain and vehicles are packaged; tests/api/test_portable_folder.py writes it).
WRITTEN_WITH_INPUT_FILES = {files.INPUTS_FOLDER}


def test_every_declared_output_file_is_written_and_every_written_file_declared(
    tmp_path: Path,
) -> None:
    out = tmp_path / "out"
    assert main(["-q", "plan", str(GOLDEN), "-o", str(out), "--no-figures"]) == 0
    written = {path.name for path in out.iterdir()}
    main_plan = files.PLAN_FILES[files.MAIN_PLAN]
    single = {getattr(files, name) for name in files.__all__ if name.endswith(("_FILE", "_FOLDER"))}
    declared = (single - WRITTEN_BY_OTHER_VERBS - WRITTEN_WITH_INPUT_FILES) | {
        main_plan.csv,
        main_plan.netcdf,
    }
    assert written == declared


@pytest.mark.parametrize("vehicle_type", packaged_vehicle_types())
def test_every_running_cost_term_has_a_name(vehicle_type: str) -> None:
    model = build_vehicle_model(load_vehicle(vehicle_type))
    for has_current in (False, True):
        terms = vehicle_cost_terms(model, has_current=has_current)
        assert terms.size1_out(0) == len(RUNNING_TERMS)
    assert COST_TERMS[: len(RUNNING_TERMS)] == RUNNING_TERMS


def test_every_constraint_row_is_labelled_and_reported(golden_solved: tuple) -> None:
    _, result, assembled = golden_solved
    functions = assembled.functions
    for constraint in functions.constraints:
        rows = constraint.function.size1_out(0)
        assert len(constraint.labels) == rows, constraint.name
        assert len(set(constraint.labels)) == rows, constraint.name  # one name per row
    trajectory = result.plan.result.trajectory
    slack = constraint_slack(assembled.problem, functions, trajectory)
    assert set(slack) == {constraint.name for constraint in functions.constraints}
    assert set(cost_breakdown(assembled.problem, functions, trajectory).totals()) == set(COST_TERMS)
    assert isinstance(functions.terminal_cost, ca.Function)
