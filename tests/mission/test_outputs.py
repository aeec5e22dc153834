"""Trajectory files of mixed fleets: union columns, empty cells / NaN fill, MEDUSA unchanged."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import xarray as xr
from _fleet_outputs import EXPECTATION, output_digest, stand_in_result, write_files

from auvplan.io.results import TRAJECTORY_COLUMNS, read_trajectories_csv
from auvplan.io.trajectories_file import read_trajectories_netcdf
from auvplan.io.vehicles import load_vehicle
from auvplan.vehicle import build_vehicle_model

N_T = 21


def test_all_medusa_outputs_are_unchanged(tmp_path: Path) -> None:
    expected = json.loads(EXPECTATION.read_text(encoding="utf-8"))
    assert output_digest(tmp_path) == expected


def _mixed(rng: np.random.Generator) -> tuple[object, object, tuple[np.ndarray, ...]]:
    medusa = build_vehicle_model(load_vehicle("medusa"))
    remus = build_vehicle_model(load_vehicle("remus100"))
    models = (medusa, remus, medusa)
    states = tuple(rng.normal(size=(N_T, model.n_x)) for model in models)
    inputs = tuple(rng.normal(size=(N_T - 1, model.n_u)) for model in models)
    power = rng.uniform(20.0, 80.0, size=(len(models), N_T))
    result, plan = stand_in_result(("blue", "red", "green"), models, states, inputs, power)
    return result, plan, states


def test_mixed_fleet_csv_has_union_columns_and_empty_cells(tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    result, plan, states = _mixed(rng)
    csv_path, _ = write_files(result, plan, tmp_path)
    lines = csv_path.read_text(encoding="utf-8").splitlines()
    header = tuple(lines[0].split(","))
    assert header == (
        *TRAJECTORY_COLUMNS[:10], "n_prop", "delta_rudder", "c_ps", "c_sb", "c_prop", "c_rudder",
        "power",
    )  # fmt: skip
    red_row = dict(zip(header, lines[1 + N_T].split(","), strict=True))
    blue_row = dict(zip(header, lines[1].split(","), strict=True))
    assert red_row["vehicle"] == "red"
    assert red_row["n_ps"] == red_row["c_sb"] == blue_row["n_prop"] == blue_row["c_rudder"] == ""
    columns = read_trajectories_csv(csv_path)
    np.testing.assert_array_equal(columns["red"]["delta_rudder"], states[1][:, 7])
    np.testing.assert_array_equal(columns["green"]["n_sb"], states[2][:, 7])
    assert np.isnan(columns["red"]["n_ps"]).all()
    assert np.isnan(columns["green"]["c_prop"]).all()


def test_mixed_fleet_netcdf_is_nan_filled_with_vehicle_types(tmp_path: Path) -> None:
    rng = np.random.default_rng(4)
    result, plan, states = _mixed(rng)
    _, netcdf_path = write_files(result, plan, tmp_path)
    dataset = read_trajectories_netcdf(netcdf_path)
    assert [str(t) for t in dataset["vehicle_type"].values] == ["medusa", "remus100", "medusa"]
    np.testing.assert_array_equal(dataset["n_prop"].values[1], states[1][:, 6])
    np.testing.assert_array_equal(dataset["delta_rudder"].values[1], states[1][:, 7])
    assert np.isnan(dataset["n_prop"].values[[0, 2]]).all()
    assert np.isnan(dataset["n_ps"].values[1]).all()
    np.testing.assert_array_equal(dataset["n_ps"].values[2], states[2][:, 6])
    assert dataset["delta_rudder"].attrs["units"] == "rad"
    assert np.isnan(dataset["n_ps"].encoding["_FillValue"])
    assert "_FillValue" not in dataset["north"].encoding
    in_memory = xr.open_dataset(netcdf_path).load()
    xr.testing.assert_identical(dataset, in_memory)
