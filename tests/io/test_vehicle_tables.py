"""Vehicle files validated by the pydantic models of :mod:`auvplan.io.vehicle_tables`."""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from auvplan.io.vehicles import load_vehicle
from auvplan.vehicle.actuators import ActuatedVehicleParams
from auvplan.vehicle.params import (
    DEFAULT_EPS_ABS_RATE,
    DEFAULT_EPS_INFLOW,
    DEFAULT_EPS_SIGN_N,
    LinearPropellerParams,
)

TESTS = Path(__file__).parents[1]
VEHICLES = resources.files("auvplan").joinpath("data", "vehicles")
MEDUSA_TEXT = VEHICLES.joinpath("medusa.toml").read_text()
REMUS_TEXT = VEHICLES.joinpath("remus100.toml").read_text()

#: Edits of the packaged files exercising unit conversions and optional keys.
VARIANTS = {
    "medusa_rpm_mm": MEDUSA_TEXT.replace(
        '{ value = 75.0,  unit = "rev/s" }', '{ value = 4500, unit = "rpm" }'
    ).replace('{ value = 0.057, unit = "m" }', '{ value = 57, unit = "mm" }'),
    "medusa_order_measured_unsmoothed": MEDUSA_TEXT.split("\n[smoothing]")[0]
    .replace("[propeller]\n", "[propeller]\norder = 5\n")
    .replace('current_model = "torque"', 'current_model = "measured"'),
    "remus_cm_mm_spellings": REMUS_TEXT.replace(
        '{ value = 1.6,   unit = "m" }', '{ value = 160, unit = "cm" }'
    )
    .replace('{ value = 0.14,   unit = "m" }', '{ value = 140, unit = "mm" }')
    .replace('{ value = 0.0133,  unit = "m^2" }', '{ value = 133, unit = "cm^2" }')
    .replace('unit = "kg m^2/s"', 'unit = "kg*m^2/s"')
    .replace('unit = "kg m^2"', 'unit = "kg  m2"'),
}


def _load(tmp_path: Path, variant: str) -> Any:
    path = tmp_path / f"{variant}.toml"
    path.write_text(VARIANTS[variant], encoding="utf-8")
    return load_vehicle(path)


def test_every_packaged_test_and_example_vehicle_file_loads() -> None:
    files = [
        path
        for folder in (TESTS, TESTS.parent / "examples")
        for path in folder.rglob("*.toml")
        if "[hull]" in path.read_text(encoding="utf-8")
    ]
    assert files
    vehicles: list[str | Path] = ["medusa", "remus100", *files]
    for vehicle in vehicles:
        assert load_vehicle(vehicle).hull.m > 0


def test_numbers_are_those_of_the_hand_written_schema(tmp_path: Path) -> None:
    """Bit for bit the parameters the hand-written schema gave (compared on every file when
    the models replaced it): conversions multiply by the same factors, defaults are the same."""
    remus = load_vehicle("remus100")
    assert isinstance(remus, ActuatedVehicleParams)
    thruster, rudder = remus.thrusters[0], remus.surfaces[0]
    assert (thruster.n_max, thruster.axis) == (25.416666666666668, 0.0)  # 1525 rpm, 0 deg
    assert (rudder.delta_max, rudder.rate_max) == (0.2617993877991494, 2.6179938779914944)
    assert remus.hull.crossflow is not None
    assert remus.hull.crossflow.strips == 20
    assert isinstance(thruster.propeller, LinearPropellerParams)
    assert (thruster.propeller.K_Q0, thruster.propeller.name) == (0.07, "remus100_wageningen_b3-72")
    spelled = _load(tmp_path, "remus_cm_mm_spellings")
    assert spelled.hull.crossflow.length == 1.6  # 160 cm
    assert spelled.thrusters[0].propeller.diameter == 0.14  # 140 mm
    assert spelled.surfaces[0].area == 0.013300000000000001  # 133 cm^2
    assert spelled.hull.N_r == -7.454  # kg*m^2/s
    rpm = _load(tmp_path, "medusa_rpm_mm")
    assert (rpm.n_max, rpm.propeller.diameter) == (75.0, 0.057)  # 4500 rpm, 57 mm
    measured = _load(tmp_path, "medusa_order_measured_unsmoothed")
    assert (measured.propeller.order, measured.motor.current_model) == (5, "measured")
    assert measured.motor.current_curve_amps.dtype == np.float64
    assert (measured.eps_inflow, measured.eps_abs_rate, measured.eps_sign_n) == (
        DEFAULT_EPS_INFLOW,
        DEFAULT_EPS_ABS_RATE,
        DEFAULT_EPS_SIGN_N,
    )
