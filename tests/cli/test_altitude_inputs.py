"""Bad inputs of a constant-altitude plan: exit 2, one stderr line naming the cause, no folder."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import pytest
from _cli import one_error_line, run_cli

DEMO = resources.files("auvplan").joinpath("data", "missions", "demo.toml").read_text()
MEDUSA = resources.files("auvplan").joinpath("data", "vehicles", "medusa.toml").read_text()
#: The packaged MEDUSA's [vertical] lines, as a vehicle file would edit them.
CLIMB = 'climb_rate   = { value = 0.2, unit = "m/s" }'
MIN_ALTITUDE = 'min_altitude = { value = 2.0, unit = "m" }'


def _vehicle(tmp: Path, old: str, new: str) -> None:
    """A MEDUSA vehicle file ``boat.toml`` with ``old`` replaced by ``new``; the demo uses it."""
    assert old in MEDUSA
    (tmp / "boat.toml").write_text(MEDUSA.replace(old, new))


@pytest.mark.parametrize(
    ("mission", "vehicle", "expected"),
    [
        (
            "[mission]\naltitude_m = 10.0\ndepth_m = 3.0\n",
            None,
            "mission: give depth_m (constant depth) or altitude_m (above the seabed), not both",
        ),
        (
            "[mission]\naltitude_m = -5.0\n",
            None,
            "mission.altitude_m: Input should be greater than 0, got -5.0",
        ),
        (
            "[mission]\naltitude_m = 10.0\n",
            (CLIMB, CLIMB.replace("0.2", "0.0")),
            "boat.toml: vertical.climb_rate: Input should be greater than or equal to 0.001",
        ),
        (
            "[mission]\naltitude_m = 10.0\n",
            (CLIMB, CLIMB.replace("0.2", "-0.3")),
            "vertical.climb_rate: Input should be greater than or equal to 0.001",
        ),
        (
            "[mission]\naltitude_m = 10.0\n",
            (MIN_ALTITUDE, MIN_ALTITUDE.replace("2.0", "80.0")),
            "shallower than its vehicle's [vertical] min_altitude = 80 m: move its start",
        ),
    ],
    ids=["with depth_m", "negative altitude", "zero climb rate", "negative rate", "shoal"],
)
def test_bad_altitude_input_exits_2_with_one_line(
    mission: str,
    vehicle: tuple[str, str] | None,
    expected: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    text = DEMO + "\n" + mission
    if vehicle is not None:
        _vehicle(tmp_path, *vehicle)
        text = text.replace('type = "medusa"', 'type = "boat.toml"')
    (tmp_path / "m.toml").write_text(text)
    argv = ["plan", str(tmp_path / "m.toml"), "-o", str(tmp_path / "out"), "--no-figures"]
    code, out, err = run_cli([*argv, "--stage", "preplan"], capsys)
    assert code == 2, err
    assert expected in one_error_line(err)
    assert out == ""
    assert not (tmp_path / "out").exists()
