"""Independent readers of the export formats that have no Python reader package."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import jsonschema
from compliance_checker.runner import CheckSuite, ComplianceChecker

SCHEMAS = Path(__file__).parent / "schemas"


def validate_json(text: str, schema: str) -> Any:
    """Parse ``text`` and validate it against ``schemas/<schema>.schema.json``; the document."""
    document = json.loads(text)
    schema_document = json.loads((SCHEMAS / f"{schema}.schema.json").read_text())
    jsonschema.Draft202012Validator.check_schema(schema_document)
    jsonschema.validate(document, schema_document, cls=jsonschema.Draft202012Validator)
    return document


def parse_moos(text: str) -> tuple[dict[str, str], list[dict[str, str]]]:
    """Top-level ``key = value`` lines and ``Behavior = NAME { key = value ... }`` blocks.

    MOOS-IvP syntax: ``//`` starts a comment; the first ``=`` of a line separates key and value
    (a value may hold more ``=``, as in ``condition = DEPLOY = true``); a behaviour's
    parameters sit between ``{`` and ``}`` lines.
    """
    settings: dict[str, str] = {}
    blocks: list[dict[str, str]] = []
    current: dict[str, str] | None = None
    pending: str | None = None
    for raw in text.splitlines():
        line = raw.split("//", 1)[0].strip()
        if not line:
            continue
        if line == "{":
            assert pending is not None, "a '{' without a Behavior line"
            current = {"Behavior": pending}
            pending = None
            continue
        if line == "}":
            assert current is not None, "a '}' without a block"
            blocks.append(current)
            current = None
            continue
        match = re.fullmatch(r"([A-Za-z_]\w*)\s*=\s*(.*)", line)
        assert match, f"not a MOOS line: {raw!r}"
        key, value = match.groups()
        if current is not None:
            assert key not in current, f"repeated parameter {key}"
            current[key] = value
        elif key == "Behavior":
            pending = value
        else:
            settings[key] = value
    assert current is None, "unterminated block"
    assert pending is None, "a Behavior line without its block"
    return settings, blocks


def moos_points(value: str) -> list[tuple[float, float]]:
    """``x,y : x,y : ...`` (or ``pts={...}``) as floats."""
    value = value.removeprefix("pts={").removesuffix("}")
    pairs = [item.split(",") for item in value.split(":")]
    return [(float(x), float(y)) for x, y in pairs]


def cf_findings(path: Path, report: Path) -> dict[str, list[str]]:
    """Names of the failed checks of the IOOS compliance checker's CF-1.8 test, by priority.

    ``report`` is where the checker writes its JSON report.
    """
    CheckSuite.load_all_available_checkers()
    ComplianceChecker.run_checker(
        str(path), ["cf:1.8"], 0, "normal", output_filename=str(report), output_format="json"
    )
    results = json.loads(report.read_text())["cf:1.8"]
    return {
        priority: [item["name"] for item in results[f"{priority}_priorities"] if item["msgs"]]
        for priority in ("high", "medium", "low")
    }
