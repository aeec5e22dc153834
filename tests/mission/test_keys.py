from __future__ import annotations

import json
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
    assert "| `solver.dt_s` | number | 0.5 | >= 0.01, <= 10.0 | s |" in out


def test_defaults_and_ranges_are_written_as_toml() -> None:
    """Every default and bound parses as TOML (no Python reprs such as True, (2, 2), 'paper')."""
    rows = [row for row in key_reference() if row.type != "table"]
    for row in rows:
        values = [row.default] if row.default not in ("", "required") else []
        values += [part.split(" ", 1)[1] for part in row.range.split(", ") if part]
        for value in values:
            tomllib.loads(f"v = {value}")  # raises on a Python repr
        assert "``" not in row.description
        assert ":func:" not in row.description


@pytest.mark.parametrize("mission", ["demo", *sorted(p.stem for p in EXAMPLES.glob("*.toml"))])
def test_the_json_schema_accepts_the_examples_and_refuses_a_typo(
    mission: str, capsys: pytest.CaptureFixture[str]
) -> None:
    jsonschema = pytest.importorskip("jsonschema")
    assert main(["keys", "--json-schema"]) == 0
    schema = json.loads(capsys.readouterr().out)
    jsonschema.Draft202012Validator.check_schema(schema)
    if mission == "demo":
        text = resources.files("auvplan").joinpath("data/missions/demo.toml").read_text("utf-8")
    else:
        text = (EXAMPLES / f"{mission}.toml").read_text("utf-8")
    document = tomllib.loads(text)
    jsonschema.validate(document, schema, cls=jsonschema.Draft202012Validator)
    document["fleet"]["safty_radius_m"] = 5.0  # a typo the editor must flag
    with pytest.raises(jsonschema.ValidationError, match="safty_radius_m"):
        jsonschema.validate(document, schema, cls=jsonschema.Draft202012Validator)
