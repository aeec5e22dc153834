"""End to end: a MEDUSA and a REMUS 100 planned together through ``auvplan plan`` (slow).

Every output and figure is written; the plan is checked independently
(:func:`auvplan.scenarios.check`: separation on a 10x finer spline, each vehicle's own
dynamics and actuator limits at every sample); each vehicle's energy is the integral of its own
model's power along its own states; the deconflicted time laws keep each vehicle within its own
speed range.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from auvplan.cli.main import main
from auvplan.io.results import read_trajectories_csv
from auvplan.io.trajectories_file import read_trajectories_netcdf
from auvplan.io.vehicles import load_vehicle
from auvplan.mission.pipeline import vehicle_model
from auvplan.mission.timing import SPEED_MARGIN
from auvplan.scenarios import check
from auvplan.vehicle import build_vehicle_model, electrical_power, top_speed

pytestmark = pytest.mark.slow

MISSION = Path(__file__).parent / "missions" / "mixed_pair.toml"
TYPES = {"blue": "medusa", "red": "remus100"}


@pytest.fixture(scope="module")
def output(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("mixed") / "out"
    assert main(["-q", "plan", str(MISSION), "-o", str(folder)]) == 0  # CONVERGED
    return folder


def test_every_output_and_figure_is_written(output: Path) -> None:
    for name in (
        "summary.json", "mission.toml", "maps.nc", "paths.geojson", "desired.csv",
        "trajectories.csv", "trajectories.nc", "report.html", "maps.png", "paths.png",
        "paths_cost.png", "coordination.png", "time_series.png", "separation.png",
    ):  # fmt: skip
        assert (output / name).is_file(), name


def test_columns_are_the_documented_union(output: Path) -> None:
    header = (output / "trajectories.csv").read_text(encoding="utf-8").splitlines()[0]
    assert header == (
        "vehicle,t,north,east,psi,u,v,r,n_ps,n_sb,n_prop,delta_rudder,"
        "c_ps,c_sb,c_prop,c_rudder,power"
    )
    columns = read_trajectories_csv(output / "trajectories.csv")
    assert np.isnan(columns["red"]["n_ps"]).all()
    assert np.isnan(columns["blue"]["delta_rudder"]).all()
    dataset = read_trajectories_netcdf(output / "trajectories.nc")
    assert [str(t) for t in dataset["vehicle_type"].values] == list(TYPES.values())
    np.testing.assert_allclose(dataset["delta_rudder"].values[1], columns["red"]["delta_rudder"])
    assert np.isnan(dataset["n_prop"].values[0]).all()


def test_independent_check_passes_with_limits_at_every_sample(output: Path) -> None:
    report = check(output, mission=MISSION)
    assert not report.failures, report.failures
    assert report.min_separation_m["blue / red"] >= report.separation_limit_m
    assert set(report.max_limit_fraction["red"]) == {"n_prop", "delta_rudder"}
    assert set(report.max_limit_fraction["blue"]) == {"n_ps", "n_sb"}
    columns = read_trajectories_csv(output / "trajectories.csv")
    for name, vehicle_type in TYPES.items():
        model = build_vehicle_model(load_vehicle(vehicle_type))
        for state, limit in model.state_limits:  # the final node included
            assert np.max(np.abs(columns[name][state])) <= limit * (1 + 1e-9), state


def test_energy_is_each_vehicle_s_own_power_integrated(output: Path) -> None:
    summary = json.loads((output / "summary.json").read_text(encoding="utf-8"))
    columns = read_trajectories_csv(output / "trajectories.csv")
    energies = summary["optimization"]["vehicles"]
    order = summary["solver"]["propeller_order"]
    for name, vehicle_type in TYPES.items():
        model = vehicle_model(vehicle_type, order)  # the optimiser's propeller order
        own = columns[name]
        states = np.column_stack([own[state] for state in model.state_names])
        inputs = np.column_stack([own[column] for column in model.input_names])
        power = electrical_power(states, inputs, model)
        np.testing.assert_allclose(own["power"], power, rtol=1e-9)
        energy = float(np.trapezoid(power, own["t"]))
        assert energies[name]["energy_J"] == pytest.approx(energy, rel=1e-9)


def test_time_laws_keep_each_vehicle_s_own_speed_range(output: Path) -> None:
    import csv

    with (output / "desired.csv").open(newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    for name, vehicle_type in TYPES.items():
        own = [row for row in rows if row["vehicle"] == name]
        time = np.array([float(row["t"]) for row in own])
        track = np.array([[float(row["north"]), float(row["east"])] for row in own])
        speed = np.hypot(*np.gradient(track, time, axis=0).T)
        limit = SPEED_MARGIN * top_speed(build_vehicle_model(load_vehicle(vehicle_type)))
        assert float(np.max(speed)) <= limit * 1.01, name
