"""``auvplan vehicle``: table, JSON, figure, and one-line errors."""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path

import pytest

from auvplan.cli.main import main
from auvplan.io.vehicles import load_vehicle
from auvplan.vehicle import build_vehicle_model
from auvplan.vehicle.trim import bollard, top_speed, trim_surge


def test_json_report_matches_library(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["vehicle", "medusa", "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    table = document["characteristics"]
    model = build_vehicle_model(load_vehicle("medusa"))
    assert table["bollard_thrust"] == pytest.approx(bollard(model).thrust)
    assert table["bollard_thrust"] == pytest.approx(36.1, rel=0.01)
    assert table["bollard_torque"] == pytest.approx(0.442, rel=0.01)
    assert table["top_speed"] == pytest.approx(top_speed(model))
    assert table["power_at_0_5"] == pytest.approx(trim_surge(model, 0.5).power)
    assert table["power_at_1_0"] == pytest.approx(trim_surge(model, 1.0).power)
    assert 0.3 < table["cruise_speed"] < 1.0
    assert table["cruise_energy_per_metre"] > 0
    assert 0.5 < table["max_yaw_rate"] < 1.1
    assert document["units"]["cruise_energy_per_metre"] == "J/m"
    assert set(document["units"]) <= set(table)


def test_order_option_changes_the_model(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["vehicle", "--json", "--order", "3"]) == 0
    low = json.loads(capsys.readouterr().out)["characteristics"]
    assert low["propeller_order"] == 3
    assert low["bollard_thrust"] == pytest.approx(36.1 * 1.037, rel=0.005)  # +3.7 % at order 3


def test_text_report_and_figure(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    figure = tmp_path / "vehicle.png"
    assert main(["vehicle", "--figure", str(figure)]) == 0
    out = capsys.readouterr().out
    for label in ("bollard", "top speed", "energy-optimal cruise", "0.5 m/s", "1.0 m/s", "yaw"):
        assert label in out
    assert figure.stat().st_size > 10_000
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_vehicle_file_path(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = resources.files("auvplan").joinpath("data", "vehicles", "medusa.toml").read_text()
    path = tmp_path / "heavy.toml"
    path.write_text(text.replace('name = "medusa"', 'name = "heavy"').replace("40.0", "80.0"))
    assert main(["vehicle", str(path), "--json"]) == 0
    table = json.loads(capsys.readouterr().out)["characteristics"]
    assert table["name"] == "heavy"
    assert table["hotel_power"] == 80.0


def test_battery_and_its_range_at_the_cruise(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Range = capacity / energy per metre at the energy-optimal cruise; none without one."""
    text = resources.files("auvplan").joinpath("data", "vehicles", "medusa.toml").read_text()
    hotel = next(line for line in text.splitlines() if line.startswith("hotel "))
    path = tmp_path / "boat.toml"
    path.write_text(
        text.replace(hotel, f'{hotel}\nbattery_capacity = {{ value = 0.5, unit = "kWh" }}')
    )
    assert main(["vehicle", str(path), "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    table = document["characteristics"]
    assert table["battery_capacity"] == pytest.approx(1.8e6)
    assert table["cruise_range"] == pytest.approx(1.8e6 / table["cruise_energy_per_metre"])
    assert document["units"]["cruise_range"] == "m"
    assert main(["vehicle", str(path)]) == 0
    line = next(row for row in capsys.readouterr().out.splitlines() if row.startswith("battery"))
    assert f"500.0 Wh; {table['cruise_range'] / 1e3:.2f} km" in line
    assert main(["vehicle", "medusa", "--json"]) == 0
    medusa = json.loads(capsys.readouterr().out)["characteristics"]
    assert medusa["battery_capacity"] is None
    assert medusa["cruise_range"] is None


def test_vertical_limits_are_reported(capsys: pytest.CaptureFixture[str]) -> None:
    """The [vertical] table of the packaged REMUS 100: climb, dive and minimum altitude."""
    assert main(["vehicle", "remus100", "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    table = document["characteristics"]
    assert (table["climb_rate"], table["dive_rate"], table["min_altitude"]) == (0.35, 0.35, 3.0)
    assert document["units"]["min_altitude"] == "m"
    assert main(["vehicle", "remus100"]) == 0
    line = next(row for row in capsys.readouterr().out.splitlines() if row.startswith("depth"))
    assert "climb 0.35 m/s, dive 0.35 m/s, at least 3 m above the seabed" in line


@pytest.mark.parametrize(
    ("argument", "message"),
    [
        ("submarine", "unknown vehicle type or missing file 'submarine'"),
        ("missing/boat.toml", "missing file 'missing/boat.toml'"),
    ],
)
def test_bad_vehicle_is_one_line_exit_2(
    argument: str, message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["vehicle", argument]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert message in captured.err
    assert captured.err.count("\n") == 1


def test_bad_order_is_one_line_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["vehicle", "--order", "99"]) == 2
    assert "order must be in [0, 30]" in capsys.readouterr().err


def test_malformed_file_is_one_line_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "bad.toml"
    path.write_text('name = "x"\n[hull]\nm = 3\n')
    assert main(["vehicle", str(path)]) == 2
    err = capsys.readouterr().err
    assert 'hull.m: must be a table { value = ..., unit = "kg" }, got 3' in err
    assert err.count("\n") == 1
