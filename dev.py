#!/usr/bin/env python3
"""Set up auvplan in its own virtual environment and run a task.

Usage::

    python3 dev.py demo        # set up, then run the default mission (`auvplan demo -o out/demo`)
    python3 dev.py test        # set up, then lint (ruff), type-check (mypy) and run the fast tests
    python3 dev.py test-slow   # the slow tests (end-to-end missions)
    python3 dev.py bench       # benchmarks, side by side with the reference tools
    python3 dev.py run ARGS    # any `auvplan` command inside the environment

Needs only Python >= 3.11 with pip and venv. The environment lives in ``.venv`` and is
reinstalled only when ``pyproject.toml`` changes (idempotent).
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import venv
from pathlib import Path

ROOT = Path(__file__).resolve().parent
VENV = ROOT / ".venv"
BIN = VENV / ("Scripts" if os.name == "nt" else "bin")
PYTHON = BIN / ("python.exe" if os.name == "nt" else "python")
STAMP = VENV / ".auvplan-installed"


def _run(*args: str | Path) -> None:
    completed = subprocess.run([str(a) for a in args], cwd=ROOT, check=False)
    if completed.returncode != 0:
        sys.exit(completed.returncode)


def ensure_environment() -> None:
    """Create ``.venv`` and install auvplan with its test, bench and gis extras, unless current."""
    if sys.version_info < (3, 11):  # noqa: UP036  (dev.py may be started by an old python3)
        sys.exit(f"auvplan needs Python >= 3.11, this is {sys.version.split()[0]}")
    key = hashlib.sha256((ROOT / "pyproject.toml").read_bytes()).hexdigest()
    if PYTHON.exists() and STAMP.exists() and STAMP.read_text() == key:
        return
    if not PYTHON.exists():
        print("dev.py: creating .venv", flush=True)
        venv.EnvBuilder(with_pip=True).create(VENV)
    print("dev.py: installing auvplan and its test dependencies into .venv", flush=True)
    _run(PYTHON, "-m", "pip", "install", "--quiet", "--upgrade", "pip")
    _run(PYTHON, "-m", "pip", "install", "--quiet", "-e", ".[test,bench,gis]")
    STAMP.write_text(key)


def main(argv: list[str]) -> None:
    """Dispatch the task named in ``argv``."""
    task = argv[0] if argv else "test"
    ensure_environment()
    if task == "demo":
        _run(BIN / "auvplan", "demo", "-o", "out/demo", *argv[1:])
    elif task == "test":
        _run(PYTHON, "-m", "ruff", "check", "src", "tests", "benchmarks", "examples", "dev.py")
        _run(PYTHON, "-m", "ruff", "format", "--check", "src", "tests", "benchmarks", "examples")
        _run(PYTHON, "-m", "mypy")
        _run(PYTHON, "-m", "pytest", "-n", "2", *argv[1:])
    elif task == "test-slow":
        _run(PYTHON, "-m", "pytest", "-n", "2", "-m", "slow", *argv[1:])
    elif task == "bench":
        _run(PYTHON, "benchmarks/run_all.py", *argv[1:])
    elif task == "run":
        _run(BIN / "auvplan", *argv[1:])
    else:
        sys.exit(f"dev.py: unknown task {task!r}; use demo, test, test-slow, bench or run")


if __name__ == "__main__":
    main(sys.argv[1:])
