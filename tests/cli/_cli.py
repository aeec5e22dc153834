"""Running the command line in-process in tests: exit code, stdout and stderr."""

from __future__ import annotations

import subprocess
import sys

import pytest

from auvplan.cli.main import main


def run_cli(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """``auvplan argv`` in this process: ``(exit code, stdout, stderr)``."""
    try:
        code = main(argv)
    except SystemExit as exit_:  # usage errors leave through argparse
        code = int(exit_.code or 0)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def run_cli_process(argv: list[str], *, timeout: float) -> tuple[int, str]:
    """``auvplan argv`` as a process killed after ``timeout`` [s]: ``(exit code, stderr)``.

    For what might hang: ``subprocess.TimeoutExpired`` fails the test in bounded time.
    """
    process = subprocess.run(
        [sys.executable, "-m", "auvplan.cli.main", *argv],
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )
    return process.returncode, process.stderr


def one_error_line(err: str) -> str:
    """The single line of ``err``, asserted to be ``auvplan: error: ...``."""
    lines = err.strip().splitlines()
    assert len(lines) == 1, lines
    assert lines[0].startswith("auvplan: error: "), lines[0]
    return lines[0]
