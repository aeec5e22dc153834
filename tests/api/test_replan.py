"""``MissionPlan.replan`` on a plan read from its folder, with a state given in lat/lon."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import auvplan

from .conftest import NAMES


def test_a_loaded_plan_replans_from_a_lat_lon_state(saved_folder: Path) -> None:
    loaded = auvplan.load(saved_folder)
    frame = loaded.to_dataframe()
    row = frame[(frame["vehicle"] == NAMES[0]) & np.isclose(frame["t"], 20.0)].iloc[0]
    state = {"lat": row["lat"], "lon": row["lon"], "heading_deg": row["heading"], "speed": row["u"]}
    rest = loaded.replan(20.0, {NAMES[0]: {k: float(v) for k, v in state.items()}}, progress=False)
    assert rest.status == "CONVERGED"
    assert rest.summary["replan"]["parent"] == saved_folder.name
    assert rest.summary["replan"]["at_s"] == 20.0
    first = rest.to_dataframe().groupby("vehicle").first()
    assert (
        np.hypot(
            first.loc[NAMES[0], "north"] - row["north"], first.loc[NAMES[0], "east"] - row["east"]
        )
        < 0.01
    )
    assert (
        first.loc[NAMES[1], "north"]
        == frame[(frame["vehicle"] == NAMES[1]) & np.isclose(frame["t"], 20.0)]["north"].iloc[0]
    )
