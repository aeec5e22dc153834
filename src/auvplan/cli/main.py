"""Entry point of the ``auvplan`` console script.

Each verb lives in its own module under :mod:`auvplan.cli` with two functions:
``register(subparsers)`` adds its parser (argparse only, no heavy imports) and sets
``run=<callable(args) -> int>`` as the parser default. Every :class:`~auvplan.errors.AuvplanError`
and every file-system error is reported as one line on stderr with exit code 2; nothing else
is printed on failure.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from collections.abc import Sequence

from auvplan import __version__
from auvplan.errors import AuvplanError

#: Modules of :mod:`auvplan.cli` that provide a verb, in help order.
COMMAND_MODULES = ("maps", "plan", "vehicle", "scenarios")

EXIT_USER_ERROR = 2


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser with every verb registered."""
    parser = argparse.ArgumentParser(
        prog="auvplan",
        description="Cooperative, energy-optimal, terrain-aware trajectory planning for "
        "fleets of marine vehicles.",
    )
    parser.add_argument("--version", action="version", version=f"auvplan {__version__}")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMAND_MODULES:
        importlib.import_module(f"auvplan.cli.{name}").register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Parse ``argv``, run the verb, and turn user errors into one-line messages."""
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.WARNING if args.quiet else logging.INFO,
        format="%(message)s",
        stream=sys.stderr,
    )
    try:
        code: int = args.run(args)
    except AuvplanError as error:
        print(f"auvplan: error: {error}", file=sys.stderr)
        return EXIT_USER_ERROR
    except OSError as error:
        where = f": {error.filename}" if error.filename else ""
        print(f"auvplan: error: {error.strerror or error}{where}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("auvplan: interrupted", file=sys.stderr)
        return 130
    return code


if __name__ == "__main__":
    sys.exit(main())
