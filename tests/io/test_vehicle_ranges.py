"""Vehicle files: every number has a physical range; encoding errors name the file."""

from __future__ import annotations

import re
from importlib import resources
from pathlib import Path

import pytest

from auvplan.errors import DataFormatError, InputError
from auvplan.io.vehicles import load_vehicle

MEDUSA_TEXT = resources.files("auvplan").joinpath("data", "vehicles", "medusa.toml").read_text()
PROPELLER_TEXT = (
    resources.files("auvplan").joinpath("data", "propellers", "wageningen_b4-70_pd1.4.csv")
).read_text()


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "boat.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            "value = 75.0,",
            "value = 1e-9,",
            "propulsion.n_max: Input should be greater than or equal to 0.5, got 1e-09 rev/s",
        ),
        (
            "value = 75.0,",
            "value = 1e6,",
            "propulsion.n_max: Input should be less than or equal to 1000, got 1000000.0 rev/s",
        ),
        (
            "value = 1025.0,",
            "value = 1.025,",
            "hull.rho: Input should be greater than or equal to 950, got 1.025 kg/m^3",
        ),
        (
            "value = 30.0,",
            "value = 1e300,",
            "hull.m: Input should be less than or equal to 10000000, got 1e+300 kg",
        ),
        ("value = 30.0,", "value = nan,", "hull.m: Input should be a finite number, got nan kg"),
        (
            "value = 0.057,",
            "value = 1e-300,",
            "propeller.diameter: Input should be greater than or equal to 0.005, got 1e-300 m",
        ),
        (
            "value = 0.15,",
            "value = -inf,",
            "propulsion.l: Input should be a finite number, got -inf m",
        ),
        (
            "value = 40.0,",
            "value = 1e9,",
            "power.hotel: Input should be less than or equal to 10000000, got 1000000000.0 W",
        ),
        (
            "value = 0.02,",
            "value = 0.0,",
            "smoothing.inflow: Input should be greater than or equal to 0.000001, got 0.0 m/s",
        ),
        (
            "value = 24.0,",
            "value = 0.0,",
            "motor.V_bus: Input should be greater than or equal to 0.5, got 0.0 V",
        ),
        (
            "0.393,",
            "-0.393,",
            (
                "motor.current_curve.current[1]: Input should be greater than or equal to 0, "
                "got -0.393 A"
            ),
        ),
    ],
)
def test_out_of_range_numbers_are_refused_naming_key_and_range(
    tmp_path: Path, old: str, new: str, message: str
) -> None:
    assert old in MEDUSA_TEXT
    path = _write(tmp_path, MEDUSA_TEXT.replace(old, new, 1))
    with pytest.raises(InputError, match=re.escape(message)) as info:
        load_vehicle(path)
    assert str(info.value) == f"{path}: {message}"
    assert "\n" not in str(info.value)


def test_range_applies_after_unit_conversion(tmp_path: Path) -> None:
    """4500 rpm is 75 rev/s (inside the range); 4500 rev/s is not."""
    rpm = MEDUSA_TEXT.replace('{ value = 75.0,  unit = "rev/s" }', '{ value = 4500, unit = "rpm" }')
    assert load_vehicle(_write(tmp_path, rpm)).n_max == pytest.approx(75.0)
    rev_s = MEDUSA_TEXT.replace("value = 75.0,", "value = 4500.0,")
    with pytest.raises(
        InputError,
        match=re.escape("n_max: Input should be less than or equal to 1000, got 4500.0 rev/s"),
    ):
        load_vehicle(_write(tmp_path, rev_s))


def test_non_utf8_vehicle_file_names_the_file(tmp_path: Path) -> None:
    path = tmp_path / "latin.toml"
    path.write_bytes(MEDUSA_TEXT.replace("MEDUSA-class", "MEDUSA-clåss").encode("latin-1"))
    with pytest.raises(DataFormatError, match=r"vehicle file .*latin.toml: not UTF-8 text"):
        load_vehicle(path)


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (PROPELLER_TEXT.encode("utf-16"), "not UTF-8 text (byte 0xff at offset 0)"),
        (PROPELLER_TEXT.replace("\n1,", "\n1,1e3*", 1).encode(), "could not convert"),
        (PROPELLER_TEXT.replace("\n1,0.28033", "\n1,250.0", 1).encode(), "coefficient 250 beyond"),
    ],
    ids=["utf-16", "garbage", "absurd-coefficient"],
)
def test_bad_propeller_csv_names_the_table(tmp_path: Path, content: bytes, message: str) -> None:
    (tmp_path / "mine.csv").write_bytes(content)
    text = MEDUSA_TEXT.replace('"wageningen_b4-70_pd1.4"', '"mine.csv"')
    with pytest.raises(DataFormatError, match=re.escape(message)) as info:
        load_vehicle(_write(tmp_path, text))
    assert "mine" in str(info.value)
    assert "\n" not in str(info.value)
