"""Vehicle files: packaged data, TOML parsing, units, error messages."""

from __future__ import annotations

import re
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from auvplan.errors import DataFormatError, InputError
from auvplan.io.vehicles import (
    load_propeller_table,
    load_vehicle,
    packaged_propeller_tables,
    packaged_vehicle_types,
)

MEDUSA_TEXT = resources.files("auvplan").joinpath("data", "vehicles", "medusa.toml").read_text()


def _write(tmp_path: Path, text: str, name: str = "boat.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_packaged_data_is_importable_resource() -> None:
    root = resources.files("auvplan").joinpath("data")
    assert root.joinpath("vehicles", "medusa.toml").is_file()
    assert root.joinpath("propellers", "wageningen_b4-70_pd1.4.csv").is_file()
    assert packaged_vehicle_types() == ("medusa", "remus100")
    assert packaged_propeller_tables() == ("wageningen_b4-70_pd1.4",)


def test_medusa_matches_reference_parameter_set() -> None:
    vehicle = load_vehicle("medusa")  # reference/vehicle.md §7
    hull = vehicle.hull
    assert (hull.m, hull.I_z, hull.rho) == (30.0, 4.14, 1025.0)
    assert (hull.X_udot, hull.Y_vdot, hull.N_rdot) == (-20.0, -30.0, -0.5)
    assert (hull.X_u, hull.Y_v, hull.N_r) == (0.0, -55.1, -4.14)
    assert (hull.X_uu, hull.Y_vv, hull.N_rr) == (-27.5, -101.0, -6.23)
    assert (hull.m_u, hull.m_v, hull.m_r) == (50.0, 60.0, 4.64)
    assert (vehicle.l, vehicle.n_max, vehicle.w_c, vehicle.hotel_power) == (0.15, 75.0, 150.0, 40.0)
    prop = vehicle.propeller
    assert (prop.diameter, prop.c_T, prop.c_Q, prop.max_order) == (0.057, 1.0, 1.0, 30)
    assert "NSWCCD-50-TR-2006/004" in prop.source
    motor = vehicle.motor
    assert (motor.R_a, motor.K_e, motor.V_bus, motor.current_model) == (0.29, 0.045, 24.0, "torque")


def test_packaged_table_equals_published_figures(shared_data: Path) -> None:
    """The project's own CSV carries the same numbers as the shared transcription."""
    shared = shared_data / "propeller" / "wageningen_B4-70_PD1.4_4q_fourier.csv"
    rows = [line for line in shared.read_text().splitlines() if line and line[0].isdigit()]
    table = np.array([[float(v) for v in row.split(",")] for row in rows])
    prop = load_vehicle("medusa").propeller
    np.testing.assert_array_equal(
        np.column_stack([prop.A_T, prop.B_T, prop.A_Q, prop.B_Q]), table[:, 1:]
    )


def test_vehicle_file_with_relative_propeller_path_and_unit_conversion(tmp_path: Path) -> None:
    table = resources.files("auvplan").joinpath("data", "propellers", "wageningen_b4-70_pd1.4.csv")
    (tmp_path / "props").mkdir()
    (tmp_path / "props" / "mine.csv").write_text(table.read_text())
    text = MEDUSA_TEXT.replace('table    = "wageningen_b4-70_pd1.4"', 'table = "props/mine.csv"')
    text = text.replace('{ value = 75.0,  unit = "rev/s" }', '{ value = 4500, unit = "rpm" }')
    text = text.replace('{ value = 0.057, unit = "m" }', '{ value = 57, unit = "mm" }')
    vehicle = load_vehicle(_write(tmp_path, text))
    assert vehicle.propeller.name == "mine"
    assert vehicle.n_max == pytest.approx(75.0)
    assert vehicle.propeller.diameter == pytest.approx(0.057)


@pytest.mark.parametrize(
    ("old", "new", "error", "message"),
    [
        ('m      = { value = 30.0,   unit = "kg" }', "", DataFormatError, "hull.m is required"),
        (
            'unit = "kg/m^3"',
            'unit = "g/cm^3"',
            DataFormatError,
            "hull.rho: unit 'g/cm^3' is not 'kg/m^3'",
        ),
        (
            "value = 0.29,",
            "value = -0.29,",
            InputError,
            "motor.R_a: Input should be greater than or equal to 0, got -0.29 ohm",
        ),
        (
            "value = -55.1,",
            "value = 55.1,",
            InputError,
            "hull.Y_v: Input should be less than or equal to 0, got 55.1 kg/s",
        ),
        (
            "value = 30.0,",
            'value = "heavy",',
            DataFormatError,
            "hull.m: value must be a number, got 'heavy'",
        ),
        ('current_model = "torque"', 'current_model = "magic"', InputError, "current_model"),
        ('"wageningen_b4-70_pd1.4"', '"nope.csv"', InputError, "propeller table 'nope.csv'"),
        ("[power]", "[powerx]", DataFormatError, "power is required"),
        ("name = ", "name = = ", DataFormatError, "not valid TOML"),
    ],
)
def test_bad_vehicle_files_give_one_line_errors(
    tmp_path: Path, old: str, new: str, error: type[Exception], message: str
) -> None:
    assert old in MEDUSA_TEXT
    path = _write(tmp_path, MEDUSA_TEXT.replace(old, new, 1))
    with pytest.raises(error, match=re.escape(message)) as info:
        load_vehicle(path)
    assert "\n" not in str(info.value)


def test_unknown_type_and_missing_file() -> None:
    with pytest.raises(InputError, match="unknown vehicle type or missing file 'submarine'"):
        load_vehicle("submarine")
    with pytest.raises(InputError, match="missing file"):
        load_vehicle(Path("/nonexistent/boat.toml"))


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("# nothing\n", "header must be"),
        ("k,A_T,B_T,A_Q,B_Q\n0,1,0,1,0\n2,1,1,1,1\n", "without gaps"),
        ("k,A_T,B_T,A_Q,B_Q\n0,1,0,1,0\n1,x,1,1,1\n", "could not convert"),
        ("k,A_T,B_T,A_Q,B_Q\n0,1,0,1,0\n1,nan,1,1,1\n", "non-finite"),
    ],
)
def test_bad_propeller_tables(tmp_path: Path, text: str, message: str) -> None:
    path = _write(tmp_path, text, "prop.csv")
    with pytest.raises(DataFormatError, match=message):
        load_propeller_table(path, diameter=0.1)


def test_propeller_order_from_file(tmp_path: Path) -> None:
    text = MEDUSA_TEXT.replace("[propeller]\n", "[propeller]\norder = 5\n")
    assert load_vehicle(_write(tmp_path, text)).propeller.order == 5
    bad = MEDUSA_TEXT.replace("[propeller]\n", "[propeller]\norder = 99\n")
    with pytest.raises(InputError, match="order must be in"):
        load_vehicle(_write(tmp_path, bad))
