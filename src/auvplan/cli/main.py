"""Entry point of the ``auvplan`` console script.

Each verb lives in its own module under :mod:`auvplan.cli` with two functions:
``register(subparsers)`` adds its parser (argparse only, no heavy imports) and sets
``run=<callable(args) -> int>`` as the parser default. ``-q``/``-v`` are accepted before or
after the verb. A verb's ``-o/--output`` names an output folder; it is checked
(:func:`~auvplan.io.output.check_output_dir`) before the verb runs.

Failures are one line on stderr, never a traceback:

* a usage error (unknown option, bad number), every :class:`~auvplan.errors.AuvplanError` and
  every file-system error: exit code 2;
* SIGINT (Ctrl-C): exit code 130; SIGTERM: exit code 143 (128 + the signal number, as a
  shell reports a process killed by it). Both are stop requests (:mod:`auvplan.interrupts`)
  raised at the next safe point, so the output writers
  (:func:`auvplan.io.output.staged_output_dir`) delete their staging files and leave the
  output folder as it was, and the worker process is stopped with the run. The console
  script (:func:`console`) keeps the handlers until the process ends: a signal after the run
  finished changes nothing.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import signal
import sys
from collections.abc import Sequence
from typing import Any, NoReturn

from auvplan import interrupts
from auvplan._version import __version__
from auvplan.errors import AuvplanError

#: Modules of :mod:`auvplan.cli` that provide a verb, in help order.
COMMAND_MODULES = (
    "maps", "plan", "replan", "export", "evaluate", "sweep", "vehicle", "keys", "scenarios",
)  # fmt: skip

EXIT_USER_ERROR = 2
EXIT_INTERRUPTED = 128 + signal.SIGINT
EXIT_TERMINATED = 128 + signal.SIGTERM
#: What ``str.splitlines`` breaks a line at, escaped in messages (a path given with a newline
#: must not split the one error line).
_LINE_BREAKS = {ord(c): repr(c)[1:-1] for c in "\n\r\v\f\x1c\x1d\x1e\x85\u2028\u2029"}


def _one_line(message: str) -> str:
    r"""``message`` with its line breaks escaped.

    >>> _one_line("no such file: a\nb")
    'no such file: a\\nb'
    """
    return message.translate(_LINE_BREAKS)


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line (``prog: error: ...``), exit 2."""

    def error(self, message: str) -> NoReturn:
        line = _one_line(f"{self.prog}: error: {message} (see {self.prog} --help)")
        self.exit(EXIT_USER_ERROR, line + "\n")


def _add_verbosity(parser: argparse.ArgumentParser, *, default: Any) -> None:
    group = parser.add_mutually_exclusive_group()
    group.add_argument(
        "-q", "--quiet", action="store_true", default=default, help="print nothing but errors"
    )
    group.add_argument(
        "-v", "--verbose", action="store_true", default=default, help="also print debug messages"
    )


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser with every verb registered."""
    parser = _Parser(
        prog="auvplan",
        description="Cooperative, energy-optimal, terrain-aware trajectory planning for "
        "fleets of marine vehicles.",
    )
    parser.add_argument("--version", action="version", version=f"auvplan {__version__}")
    _add_verbosity(parser, default=False)
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMAND_MODULES:
        importlib.import_module(f"auvplan.cli.{name}").register(subparsers)
    # After the verb, -q/-v only override what was given before it (SUPPRESS: no default).
    for verb_parser in {id(p): p for p in subparsers.choices.values()}.values():
        _add_verbosity(verb_parser, default=argparse.SUPPRESS)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Parse ``argv``, run the verb, and turn user errors into one-line messages."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.quiet and args.verbose:
        parser.error("-q/--quiet and -v/--verbose exclude each other")
    logging.basicConfig(level=logging.WARNING, format="%(message)s", stream=sys.stderr)
    logger = logging.getLogger("auvplan")
    level = logger.level
    logger.setLevel(
        logging.WARNING if args.quiet else logging.DEBUG if args.verbose else logging.INFO
    )
    try:
        with interrupts.stop_requests():
            if getattr(args, "output", None) is not None:  # every verb's -o is a folder
                from auvplan.io.output import check_output_dir  # heavy package: only now

                check_output_dir(args.output)  # before any work: fail fast, write nothing
            code: int = args.run(args)
    except AuvplanError as error:
        print(_one_line(f"auvplan: error: {error}"), file=sys.stderr)
        return EXIT_USER_ERROR
    except OSError as error:
        where = f": {error.filename}" if error.filename else ""
        print(_one_line(f"auvplan: error: {error.strerror or error}{where}"), file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("auvplan: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except interrupts.Terminated:
        print("auvplan: terminated", file=sys.stderr)
        return EXIT_TERMINATED
    finally:
        logger.setLevel(level)
    return code


def console() -> int:
    """The ``auvplan`` console script: :func:`main` with stop requests from the first moment.

    Once :func:`main` returned, SIGINT and SIGTERM are blocked: the exit code stands.
    """
    interrupts.install()
    code = main()
    interrupts.finished()
    return code


if __name__ == "__main__":
    sys.exit(console())
