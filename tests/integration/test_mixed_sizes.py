"""End to end: an 8-state and a 9-state vehicle type in one fleet (slow).

A MEDUSA (8 states: two propellers) and a REMUS 100 whose rudder is split into two fins
(``missions/remus100_two_fins.toml``, 9 states) are planned together on a georeferenced
grid, written, loaded back, exported and evaluated: no step assumes a common state size.
(A 6-state vehicle type cannot be written as a vehicle file: every type has at least one
actuator state. ``tests/record`` covers a 6-state vehicle in a record.)
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import auvplan
from auvplan.cli.main import main
from export._plans import MISSION, write_geographic_grid

pytestmark = pytest.mark.slow

TWO_FINS = Path(__file__).parent / "missions" / "remus100_two_fins.toml"


def test_an_8_and_a_9_state_vehicle_plan_write_load_export_and_evaluate(tmp_path: Path) -> None:
    write_geographic_grid(tmp_path / "grid.nc")
    mission = tmp_path / "mission.toml"
    typed = MISSION.replace('name = "green"\n', f'name = "green"\ntype = "{TWO_FINS}"\n')
    assert typed != MISSION
    mission.write_text(typed)
    out = tmp_path / "out"
    assert main(["-q", "plan", str(mission), "-o", str(out), "--no-figures"]) == 0
    header = (out / "trajectories.csv").read_text().splitlines()[0].split(",")
    assert {"n_ps", "n_prop", "delta_upper", "delta_lower", "c_upper", "c_lower"} <= set(header)
    plan = auvplan.load(out)
    blue, green = plan.record.plans["terrain_aware"]
    assert blue.states.shape[1] == 8
    assert green.states.shape[1] == 9
    assert green.state_names[-2:] == ("delta_upper", "delta_lower")
    dataset = plan.to_xarray()
    assert list(dataset["vehicle_type"].values) == ["medusa", "remus100_two_fins"]
    np.testing.assert_array_equal(dataset["delta_lower"].values[1], green.state("delta_lower"))
    assert np.isnan(dataset["delta_lower"].values[0]).all()
    assert main(["-q", "export", str(out), "--format", "gpx,moos"]) == 0
    assert (out / "export" / "trajectories.gpx").is_file()
    arguments = ["-q", "evaluate", str(out), "--runs", "2", "--particles", "200", "--no-figure"]
    assert main(arguments) == 0
    assert (out / "navigation.json").is_file()
