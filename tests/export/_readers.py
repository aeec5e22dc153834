"""Independent readers of the export formats that have no Python reader package."""

from __future__ import annotations

import json
import math
import re
import warnings
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


#: Behaviour parameters that may appear more than once (MOOS-IvP: conditions are conjunctive,
#: every endflag is posted).
REPEATABLE = ("condition", "endflag")


def parse_moos(text: str) -> tuple[dict[str, str], list[dict[str, str]]]:
    """Top-level ``key = value`` lines and ``Behavior = NAME { key = value ... }`` blocks.

    MOOS-IvP syntax: ``//`` starts a comment; the first ``=`` of a line separates key and value
    (a value may hold more ``=``, as in ``condition = DEPLOY = true``); a behaviour's
    parameters sit between ``{`` and ``}`` lines; ``initialize VAR = value`` lines set the
    helm's variables (returned as ``initialize VAR``). Repeated :data:`REPEATABLE` parameters
    are joined with ``" & "``.
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
        initial = re.fullmatch(r"initialize\s+([A-Za-z_]\w*)\s*=\s*(\S+)", line)
        if initial and current is None:
            settings[f"initialize {initial[1]}"] = initial[2]
            continue
        match = re.fullmatch(r"([A-Za-z_]\w*)\s*=\s*(.*)", line)
        assert match, f"not a MOOS line: {raw!r}"
        key, value = match.groups()
        if current is not None:
            if key in REPEATABLE and key in current:
                current[key] += f" & {value}"
                continue
            assert key not in current, f"repeated parameter {key}"
            current[key] = value
        elif key == "Behavior":
            pending = value
        else:
            settings[key] = value
    assert current is None, "unterminated block"
    assert pending is None, "a Behavior line without its block"
    return settings, blocks


def fly_moos(
    settings: dict[str, str], blocks: list[dict[str, str]], start: tuple[float, float]
) -> list[tuple[float, float, float]]:
    """A minimal pHelmIvP: run the behaviours as their conditions and endflags say.

    Sets ``DEPLOY = true``, then repeatedly runs the one waypoint or timer behaviour whose
    conditions all hold: a waypoint behaviour flies straight to its point at its speed, a timer
    waits its duration; either then posts its endflags. Returns ``(t, x, y)`` after each
    behaviour, until no behaviour can run; a behaviour that would run twice is an error.
    """
    variables = {
        key.removeprefix("initialize "): value
        for key, value in settings.items()
        if key.startswith("initialize ")
    }
    variables["DEPLOY"] = "true"

    def holds(block: dict[str, str]) -> bool:
        conditions = block.get("condition", "").split(" & ")
        pairs = [condition.split("=") for condition in conditions if condition]
        return all(variables.get(name.strip()) == value.strip() for name, value in pairs)

    steps = [block for block in blocks if block["Behavior"] in ("BHV_Waypoint", "BHV_Timer")]
    done: set[str] = set()
    time, (x, y) = 0.0, start
    visited = [(time, x, y)]
    while running := [block for block in steps if holds(block) and block["name"] not in done]:
        assert len(running) == 1, f"{len(running)} leg behaviours at once"
        (block,) = running
        if block["Behavior"] == "BHV_Waypoint":
            ((x_next, y_next),) = moos_points(block["points"])
            time += math.hypot(x_next - x, y_next - y) / float(block["speed"])
            x, y = x_next, y_next
        else:
            time += float(block["duration"])
        done.add(block["name"])
        for flag in block["endflag"].split(" & "):
            name, value = flag.split("=")
            variables[name.strip()] = value.strip()
        visited.append((time, x, y))
    assert variables.get("PLAN_DONE") == "true", "the plan never finished"
    return visited


def moos_points(value: str) -> list[tuple[float, float]]:
    """``x,y : x,y : ...`` (or ``pts={...}``) as floats."""
    value = value.removeprefix("pts={").removesuffix("}")
    pairs = [item.split(",") for item in value.split(":")]
    return [(float(x), float(y)) for x, y in pairs]


def checker_passes(path: Path, report: Path, test: str) -> bool:
    """Whether ``compliance-checker --test TEST PATH`` exits 0: no failed check of high or
    medium priority (its default ``--criteria normal``); the JSON report goes to ``report``."""
    CheckSuite.load_all_available_checkers()
    with warnings.catch_warnings():  # the NCEI plugin calls a deprecated checker interface
        warnings.simplefilter("ignore", DeprecationWarning)
        passed, _ = ComplianceChecker.run_checker(
            str(path), [test], 0, "normal", output_filename=str(report), output_format="json"
        )
    return bool(passed)


def checker_report(path: Path, report: Path, test: str) -> dict[str, Any]:
    """The IOOS compliance checker's JSON report of ``test`` (``"cf:1.8"``, ``"acdd:1.3"``,
    ``"ncei-trajectory:2.0"`` with the NCEI plugin) on ``path``, written to ``report``."""
    checker_passes(path, report, test)
    results: dict[str, Any] = json.loads(report.read_text())[test]
    return results


def cf_findings(path: Path, report: Path, test: str = "cf:1.8") -> dict[str, list[str]]:
    """Names of the failed checks of a compliance-checker ``test``, by priority."""
    results = checker_report(path, report, test)
    return {
        priority: [item["name"] for item in results[f"{priority}_priorities"] if item["msgs"]]
        for priority in ("high", "medium", "low")
    }
