from __future__ import annotations

import math
import tomllib
from importlib import resources
from pathlib import Path
from typing import Any

import pytest

from auvplan.errors import DataFormatError, InputError
from auvplan.mission.config import load_mission, parse_mission
from auvplan.optimization import ProntoOptions

MINIMAL = """
[terrain]
synthetic = true
[fleet]
horizon_s = 600.0
safety_radius_m = 5.0
[[vehicle]]
name = "blue"
start = { north = 10.0, east = 400.0, heading_deg = 90.0, speed = 0.5 }
goal = { north = 380.0, east = 420.0 }
"""


def _mission(extra: str = "", base: str = MINIMAL) -> dict[str, Any]:
    return tomllib.loads(base + extra)


def test_minimal_mission_defaults_and_units() -> None:
    mission = parse_mission(_mission())
    assert mission.terrain.synthetic
    assert mission.terrain.seed == 7
    assert mission.maps.omega == 10.0
    assert mission.maps.weight == 10.0
    assert mission.maps.block == (2, 2)
    (blue,) = mission.vehicles
    assert blue.type == "medusa"
    assert blue.start.psi == pytest.approx(math.pi / 2)  # degrees in the file, radians inside
    assert blue.start.speed == 0.5
    assert blue.goal.north == 380.0
    assert mission.planner.edge_model == "navigation"
    assert mission.solver.dt == 0.5
    # the solver's defaults have one home: ProntoOptions
    assert mission.solver.pronto_options() == ProntoOptions(
        eps_initial=1.0, compile_c=False, max_iter=ProntoOptions().max_iter
    )


def test_packaged_demo_mission_is_valid() -> None:
    text = resources.files("auvplan").joinpath("data/missions/demo.toml").read_text()
    mission = parse_mission(tomllib.loads(text))
    assert [v.name for v in mission.vehicles] == ["blue", "green"]
    assert mission.fleet.horizon == 600.0


def test_file_relative_to_mission(tmp_path: Path) -> None:
    text = MINIMAL.replace("synthetic = true", 'file = "grids/bank.nc"')
    (tmp_path / "m.toml").write_text(text)
    mission = load_mission(tmp_path / "m.toml")
    assert mission.terrain.file == tmp_path / "grids" / "bank.nc"
    assert not mission.terrain.synthetic


def test_geographic_poses_and_window() -> None:
    text = MINIMAL.replace("north = 10.0, east = 400.0", "lat = 36.794, lon = -121.81")
    text = text.replace(
        "synthetic = true",
        "synthetic = true\nwindow = { lat = [36.79, 36.80], lon = [-121.82, -121.80] }",
    )
    mission = parse_mission(tomllib.loads(text))
    assert mission.vehicles[0].start.is_geographic
    assert mission.terrain.window.lat == (36.79, 36.80)


@pytest.mark.parametrize(
    ("extra", "base_edit", "fragment"),
    [
        ("[planer]\nedge_model = 'paper'\n", None, "unknown key 'planer' (allowed here: terrain"),
        ("[solver]\ndt = 1.0\n", None, "unknown key 'solver.dt' (allowed here: dt_s, tol"),
        ("[planner]\nedge_model = 'fast'\n", None, "planner.edge_model"),
        ("[maps]\nblock = [0, 2]\n", None, "maps.block"),
        ("[maps]\nomega = -1.0\n", None, "maps.omega"),
        ("[solver]\ndt_s = 'half'\n", None, "solver.dt_s"),
        ("", ("horizon_s = 600.0", "horizon_s = 600.0\ncruise_speed = 0.5"), "exactly one"),
        ("", ("horizon_s = 600.0", "horizon_s = 1e20"), "fleet.horizon_s"),
        ("[solver]\ndt_s = 1e-300\n", None, "solver.dt_s"),
        ("", ("horizon_s = 600.0", "cruise_speed = 1e-17"), "fleet.cruise_speed"),
        ("", ("heading_deg = 90.0", "heading_deg = 1e300"), "vehicle[0].start.heading_deg"),
        ("", ("speed = 0.5", "speed = 1e9"), "vehicle[0].start.speed"),
        ("[maps]\nomega = 1.7e308\n", None, "maps.omega"),
        ("", ("synthetic = true", "seed = 3"), "terrain"),
        (
            "[[obstacle]]\npolygon = [[0.0, 0.0], [10.0, 10.0], [0.0, 10.0], [10.0, 0.0]]\n",
            None,
            "not a simple polygon",
        ),
        (
            "[[obstacle]]\nname = 'blue'\ncenter = { north = 1.0, east = 2.0 }\nradius_m = 3.0\n",
            None,
            "unique",
        ),
        ("[solver]\nmax_iter = 2.5\n", None, "solver.max_iter"),
        ("[solver]\npropeller_order = 'half'\n", None, "solver.propeller_order"),
        ("", ("safety_radius_m = 5.0", ""), "safety_radius_m is required"),
        ("", ("heading_deg = 90.0", "heading = 90.0"), "vehicle[0].start.heading"),
        ("", ("goal = { north = 380.0, east = 420.0 }", "goal = { north = 380.0 }"), "goal"),
        (
            (
                '[[vehicle]]\nname = "blue"\nstart = { north = 0.0, east = 0.0 }\n'
                "goal = { north = 1.0, east = 1.0 }\n"
            ),
            None,
            "unique",
        ),
        ('[[comm]]\npair = ["blue", "red"]\nmax_range_m = 100.0\n', None, "'red'"),
        ("[[obstacle]]\ncenter = { north = 1.0, east = 2.0 }\n", None, "radius_m"),
        ("[[obstacle]]\npolygon = [[0.0, 0.0], [1.0, 1.0]]\n", None, "at least 3"),
        ("[terrain.window]\nnorth = [5.0, 1.0]\n", None, "low must be < high"),
    ],
)
def test_bad_missions_name_the_key(
    extra: str, base_edit: tuple[str, str] | None, fragment: str
) -> None:
    base = MINIMAL if base_edit is None else MINIMAL.replace(*base_edit)
    with pytest.raises(InputError, match=None) as info:
        parse_mission(_mission(extra, base))
    message = str(info.value)
    assert fragment in message
    assert "\n" not in message


def test_missing_and_malformed_files(tmp_path: Path) -> None:
    with pytest.raises(DataFormatError, match="not found"):
        load_mission(tmp_path / "nope.toml")
    (tmp_path / "bad.toml").write_text("[fleet\nhorizon_s = 1")
    with pytest.raises(DataFormatError, match="not valid TOML"):
        load_mission(tmp_path / "bad.toml")


def test_small_horizon_over_dt_refused_before_allocation() -> None:
    text = MINIMAL.replace("horizon_s = 600.0", "horizon_s = 172800.0") + "[solver]\ndt_s = 0.01\n"
    with pytest.raises(InputError, match=r"use a larger solver\.dt_s"):
        parse_mission(tomllib.loads(text))


def test_headings_are_reduced() -> None:
    text = MINIMAL.replace("heading_deg = 90.0", "heading_deg = -270.0")
    (blue,) = parse_mission(tomllib.loads(text)).vehicles
    assert blue.start.psi == pytest.approx(math.pi / 2)


def test_obstacle_labels_default_and_named() -> None:
    extra = (
        "[[obstacle]]\ncenter = { north = 1.0, east = 2.0 }\nradius_m = 3.0\n"
        "[[obstacle]]\nname = 'wreck'\ncenter = { north = 9.0, east = 2.0 }\nradius_m = 3.0\n"
    )
    assert parse_mission(_mission(extra)).obstacle_names == ("obstacle 0", "wreck")


def test_non_utf8_and_deeply_nested_mission_files(tmp_path: Path) -> None:
    (tmp_path / "latin1.toml").write_bytes("# caf\xe9\n".encode("latin-1") + MINIMAL.encode())
    with pytest.raises(DataFormatError, match="not UTF-8"):
        load_mission(tmp_path / "latin1.toml")
    (tmp_path / "deep.toml").write_text("x = " + "[" * 5000 + "]" * 5000 + "\n")
    with pytest.raises(DataFormatError, match="not valid TOML"):
        load_mission(tmp_path / "deep.toml")


def test_metadata_table_defaults_the_publisher_to_the_creator() -> None:
    assert parse_mission(_mission()).metadata.attributes() == {}
    metadata = parse_mission(
        _mission('[metadata]\ncreator_name = "Ada"\ncreator_email = "a@b.org"\npublisher_url = "u"')
    ).metadata
    assert metadata.attributes() == {
        "creator_name": "Ada",
        "creator_email": "a@b.org",
        "publisher_name": "Ada",
        "publisher_email": "a@b.org",
        "publisher_url": "u",
    }
    for extra, key in (
        ('[metadata]\ncreator_type = "robot"\n', "metadata.creator_type"),
        ('[metadata]\nproject = "two\\nlines"\n', "metadata.project"),
        ("[metadata]\nlicense = 4\n", "metadata.license"),
        ('[metadata]\nauthor = "Ada"\n', "metadata.author"),
    ):
        with pytest.raises(InputError) as info:
            parse_mission(_mission(extra))
        assert key in str(info.value)
        assert "\n" not in str(info.value)
