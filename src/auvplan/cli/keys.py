"""``auvplan keys``: the reference of every mission-file key (generated from the models)."""

from __future__ import annotations

import argparse
import json
from typing import Any


def register(subparsers: Any) -> None:
    """Add the ``keys`` verb."""
    keys = subparsers.add_parser(
        "keys",
        help="list every mission-file key with its type, default, range and unit",
        description="The mission-file reference, generated from the validating models: a "
        "Markdown table with TOML values, or (--json-schema) the JSON Schema that TOML editors "
        "(Even Better TOML, taplo) use to check and complete mission files.",
    )
    keys.add_argument(
        "--json-schema",
        action="store_true",
        help="print the mission file's JSON Schema instead of the table",
    )
    keys.set_defaults(run=run_keys)


def run_keys(args: argparse.Namespace) -> int:
    """Print the Markdown table, or the JSON Schema."""
    from auvplan.mission.keys import key_reference_markdown, mission_json_schema

    if args.json_schema:
        print(json.dumps(mission_json_schema(), indent=2))
    else:
        print(key_reference_markdown(), end="")
    return 0
