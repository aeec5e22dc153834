from __future__ import annotations

import tomllib
from importlib import resources
from pathlib import Path
from typing import Any

import pytest

from auvplan.cli.main import main
from auvplan.mission.keys import key_reference

EXAMPLES = Path(__file__).parents[2] / "examples" / "missions"


def _leaf_keys(table: dict[str, Any], prefix: str = "") -> set[str]:
    keys: set[str] = set()
    for key, value in table.items():
        items = value if isinstance(value, list) and value and isinstance(value[0], dict) else None
        if isinstance(value, dict):
            keys |= _leaf_keys(value, f"{prefix}{key}.")
        elif items is not None:
            for item in items:
                keys |= _leaf_keys(item, f"{prefix}{key}.")
        else:
            keys.add(f"{prefix}{key}")
    return keys


def test_every_key_is_documented_with_a_meaning() -> None:
    undocumented = [
        row.key for row in key_reference() if row.type != "table" and not row.description
    ]
    assert not undocumented


@pytest.mark.parametrize("mission", ["demo", *sorted(p.stem for p in EXAMPLES.glob("*.toml"))])
def test_reference_lists_every_key_the_examples_use(mission: str) -> None:
    if mission == "demo":
        text = resources.files("auvplan").joinpath("data/missions/demo.toml").read_text("utf-8")
    else:
        text = (EXAMPLES / f"{mission}.toml").read_text("utf-8")
    listed = {row.key for row in key_reference()}
    assert _leaf_keys(tomllib.loads(text)) <= listed


def test_keys_verb_prints_a_markdown_table(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["keys"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("| key | type | default | range | unit | meaning |")
    assert "| `solver.dt_s` | number | 0.5 | >= 0.01, <= 10 | s |" in out
