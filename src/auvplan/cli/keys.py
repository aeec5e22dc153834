"""``auvplan keys``: the reference of every mission-file key (generated from the models)."""

from __future__ import annotations

import argparse
from typing import Any


def register(subparsers: Any) -> None:
    """Add the ``keys`` verb."""
    keys = subparsers.add_parser(
        "keys",
        help="list every mission-file key with its type, default, range and unit",
        description="The mission-file reference, generated from the validating models.",
    )
    keys.set_defaults(run=run_keys)


def run_keys(args: argparse.Namespace) -> int:  # noqa: ARG001  (every verb takes its args)
    """Print the Markdown table."""
    from auvplan.mission.keys import key_reference_markdown

    print(key_reference_markdown(), end="")
    return 0
