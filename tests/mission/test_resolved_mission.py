"""``[mission]`` (start time, depth) and the resolved mission written as ``mission.toml``."""

from __future__ import annotations

import tomllib
from datetime import UTC, datetime, timedelta
from importlib import resources
from pathlib import Path
from typing import Any

import pytest
import tomli_w

from auvplan.errors import InputError
from auvplan.mission.config import load_mission, parse_mission, resolved_document

MINIMAL = """
[terrain]
synthetic = true
[fleet]
horizon_s = 60.0
safety_radius_m = 5.0
[[vehicle]]
start = { north = 10.0, east = 400.0 }
goal = { north = 40.0, east = 400.0 }
"""
ROOT = Path(__file__).parents[2]
MISSIONS = [
    *sorted((ROOT / "examples" / "missions").glob("*.toml")),
    ROOT / "tests" / "integration" / "missions" / "ring_crossing.toml",
    ROOT / "tests" / "regression" / "golden_mission.toml",
]


def _parse(extra: str) -> Any:
    return parse_mission(tomllib.loads(MINIMAL + extra))


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("2026-05-01T08:00:00Z", datetime(2026, 5, 1, 8, tzinfo=UTC)),
        ('"2026-05-01T10:30:00+02:00"', datetime(2026, 5, 1, 8, 30, tzinfo=UTC)),
        ('"2026-05-01T08:00:00.25Z"', datetime(2026, 5, 1, 8, 0, 0, 250000, tzinfo=UTC)),
        ("2026-05-01 03:00:00-05:00", datetime(2026, 5, 1, 8, tzinfo=UTC)),
    ],
)
def test_start_time_is_kept_in_utc(text: str, expected: datetime) -> None:
    start = _parse(f"[mission]\nstart_time = {text}\n").mission.start_time
    assert start == expected
    assert start.utcoffset() == timedelta(0)


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("2026-05-01T08:00:00", "give a time zone"),  # a TOML local date-time
        ('"2026-05-01T08:00:00"', "give a time zone"),
        ('"first of May"', "not an ISO 8601 time"),
        ("1777622400", "ISO 8601"),  # no Unix seconds
        ("2026-05-01", "ISO 8601"),  # a date alone
        ("9999-12-31T23:59:59-05:00", "outside 1900-2200"),
    ],
)
def test_bad_start_times_name_the_key(text: str, fragment: str) -> None:
    with pytest.raises(InputError, match=r"mission\.start_time") as info:
        _parse(f"[mission]\nstart_time = {text}\n")
    assert fragment in str(info.value)


def test_start_time_defaults_to_now_in_whole_seconds() -> None:
    before = datetime.now(UTC).replace(microsecond=0)
    start = _parse("").mission.start_time
    assert before <= start <= datetime.now(UTC)
    assert start.microsecond == 0
    assert start.tzinfo is UTC


def test_depth_is_checked() -> None:
    assert _parse("").mission.depth == 0.0
    with pytest.raises(InputError, match=r"mission\.depth_m"):
        _parse("[mission]\ndepth_m = -2.0\n")


@pytest.mark.parametrize("path", [*MISSIONS, "demo"], ids=lambda p: getattr(p, "stem", p))
def test_resolved_document_round_trips_through_toml(path: Path | str, tmp_path: Path) -> None:
    if path == "demo":
        with resources.as_file(resources.files("auvplan") / "data/missions/demo.toml") as demo:
            config = load_mission(demo)
    else:
        config = load_mission(path)
    document = resolved_document(config)
    text = tomli_w.dumps(document)
    (tmp_path / "elsewhere").mkdir()
    again = parse_mission(tomllib.loads(text), base_dir=tmp_path / "elsewhere")  # paths absolute
    expected = config.model_dump()
    if config.terrain.file is not None:
        expected["terrain"]["file"] = config.terrain.file.resolve()  # the same file
    assert again.model_dump() == expected
    # every default is written out
    assert set(document) >= {"maps", "weights", "planner", "deconfliction", "solver", "mission"}
    assert "start_time" in document["mission"]
    assert "name" in document["vehicle"][0]


def test_vehicle_files_are_made_absolute(tmp_path: Path) -> None:
    boat = tmp_path / "boats" / "mine.toml"
    boat.parent.mkdir()
    boat.write_text((resources.files("auvplan") / "data/vehicles/medusa.toml").read_text())
    mission = tmp_path / "mission.toml"
    mission.write_text(MINIMAL.replace("[[vehicle]]", '[[vehicle]]\ntype = "boats/mine.toml"'))
    document = resolved_document(load_mission(mission))
    assert document["vehicle"][0]["type"] == str(boat.resolve())


def test_keys_reference_lists_the_mission_table() -> None:
    from auvplan.mission.keys import key_reference

    rows = {row.key: row for row in key_reference()}
    assert rows["mission.start_time"].type == "datetime"
    assert "ISO 8601" in rows["mission.start_time"].description
    assert (rows["mission.depth_m"].unit, rows["mission.depth_m"].default) == ("m", "0.0")
