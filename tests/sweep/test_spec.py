"""``--vary`` / ``--seeds`` parsing and the grid of validated runs."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from auvplan.errors import InputError
from auvplan.sweep import build_runs, mission_file_base, parse_seeds, parse_vary, run_identifier

SAFE_ID = re.compile(r"^[A-Za-z0-9._=-]+$")


def _grid(mission: Path, *options: str, seeds: tuple[int | None, ...] = (None,)) -> tuple:
    base = mission_file_base(mission)
    return build_runs(list(options), seeds, lambda _seed: base)


def test_parse_vary_reads_toml_values() -> None:
    key, values = parse_vary("solver.dt_s=0.5,1,2e0")
    assert key == "solver.dt_s"
    assert values == [0.5, 1, 2.0]
    assert [type(v) for v in values] == [float, int, float]
    assert parse_vary("x.y=true,'a,b',[1, 2],{ a = 1 }")[1] == [True, "a,b", [1, 2], {"a": 1}]
    assert parse_vary("planner.edge_model=paper, crossed")[1] == ["paper", "crossed"]


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("weights.terrain", "expected KEY=VALUE"),
        ("=1,2", "expected KEY=VALUE"),
        ("weights.terrain=1,,2", "empty value"),
        ("weights..terrain=1", "is not a key name"),
        ("weights.terrain[x]=1", "is not a key name"),
    ],
)
def test_parse_vary_errors(text: str, fragment: str) -> None:
    with pytest.raises(InputError, match=re.escape(fragment)):
        parse_vary(text)


def test_parse_seeds() -> None:
    assert parse_seeds("0..3") == (0, 1, 2, 3)
    assert parse_seeds("5, 0..1,9") == (5, 0, 1, 9)
    for bad, fragment in (("3..1", "backwards"), ("-1", "not a seed"), ("1,0..2", "twice")):
        with pytest.raises(InputError, match=fragment):
            parse_seeds(bad)


def test_grid_is_the_product_with_coerced_values(tiny_mission: Path) -> None:
    axes, runs = _grid(
        tiny_mission,
        "weights.terrain=0,0.3,1,3",
        "planner.edge_model=paper,crossed",
        seeds=(0, 1, 2),
    )
    assert len(runs) == 4 * 2 * 3
    assert axes[0].values == (0.0, 0.3, 1.0, 3.0)
    assert all(type(value) is float for value in axes[0].values)  # int 0 -> float, by the schema
    assert axes[1].values == ("paper", "crossed")
    assert [run.seed for run in runs[:4]] == [0, 1, 2, 0]  # seed fastest, then the last axis
    assert runs[3].values == {"weights.terrain": 0.0, "planner.edge_model": "crossed"}
    assert runs[3].document["weights"]["terrain"] == 0.0
    assert runs[3].document["planner"]["edge_model"] == "crossed"
    identifiers = [run.run_id for run in runs]
    assert len(set(identifiers)) == len(runs)
    assert all(SAFE_ID.match(identifier) for identifier in identifiers)
    assert runs[0].run_id == "weights.terrain=0.0__planner.edge_model=paper__seed=0"
    assert len({run.digest for run in runs}) == 4 * 2  # a mission file's seed changes nothing


def test_array_tables_by_index_or_all(tiny_mission: Path) -> None:
    _, runs = _grid(tiny_mission, "vehicle[1].start.speed=0.25", "vehicle.goal.heading_deg=10")
    blue, green = runs[0].document["vehicle"]
    assert "speed" not in blue["start"]
    assert green["start"]["speed"] == 0.25
    assert blue["goal"]["heading_deg"] == green["goal"]["heading_deg"] == 10.0


@pytest.mark.parametrize(
    ("option", "fragment"),
    [
        ("weights.terain=1", "--vary weights.terain=1: unknown key 'weights.terain'"),
        ("weights.terrain=0,-1", "--vary weights.terrain=-1: weights.terrain"),
        ("weights.terrain=heavy", "--vary weights.terrain=heavy: weights.terrain"),
        ("planner.edge_model=paper,quick", "--vary planner.edge_model=quick"),
        ("vehicle[2].start.speed=0.1", "mission.toml has 2 [[vehicle]] tables, no index 2"),
        ("fleet.horizon_s.x=1", "fleet.horizon_s is a value, not a table"),
        ("weights.terrain.x=1", "weights.terrain: Input should be a valid number"),
        ("weights.terrain=1,1.0", "value 1.0 given twice"),
    ],
)
def test_bad_key_or_value_names_it(tiny_mission: Path, option: str, fragment: str) -> None:
    with pytest.raises(InputError, match=re.escape(fragment)):
        _grid(tiny_mission, option)


def test_combinations_are_validated_too(tiny_mission: Path) -> None:
    # each value is valid alone; eps_final above eps_initial is not
    with pytest.raises(InputError, match=r"sweep run solver.eps_initial=0.001__.*eps_final"):
        _grid(tiny_mission, "solver.eps_initial=0.001,1", "solver.eps_final=0.01")


def test_key_given_twice(tiny_mission: Path) -> None:
    with pytest.raises(InputError, match="given twice"):
        _grid(tiny_mission, "weights.terrain=1", "weights.terrain=2")


def test_run_identifier_is_safe_and_unique() -> None:
    assert run_identifier({}, None) == "run"
    assert run_identifier({"maps.block": [2, 2]}, None) == "maps.block=2-2"
    start = {"north": 10.0, "east": 400.0}
    assert run_identifier({"vehicle[0].start": start}, 0) == (
        "vehicle0.start=north-10.0-east-400.0__seed=0"
    )
    odd = [run_identifier({"terrain.file": name}, 1) for name in ("a/b.nc", "a_b.nc", "a b.nc")]
    assert len(set(odd)) == 3
    assert all(SAFE_ID.match(identifier) for identifier in odd)
    long = run_identifier({f"key{i}.value": 1.5 for i in range(20)}, None)
    assert len(long) <= 140
    assert long != run_identifier({f"key{i}.value": 1.5 for i in range(19)}, None)
