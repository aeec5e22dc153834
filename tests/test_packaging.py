"""Packaging: one version, a licence, the metadata a package index shows, ``python -m auvplan``."""

from __future__ import annotations

import subprocess
import sys
import tomllib
from importlib import metadata
from pathlib import Path

import auvplan
from auvplan._version import __version__

ROOT = Path(__file__).parents[1]


def test_the_version_is_written_once() -> None:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert "version" not in project
    assert project["dynamic"] == ["version"]
    assert auvplan.__version__ == __version__ == metadata.version("auvplan")


def test_python_dash_m_runs_the_command_line() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "auvplan", "--version"], capture_output=True, text=True, check=False
    )
    assert (done.returncode, done.stdout, done.stderr) == (0, f"auvplan {__version__}\n", "")


def test_the_licence_and_metadata_ship() -> None:
    assert (ROOT / "LICENSE").read_text().startswith("MIT License")
    fields = metadata.metadata("auvplan")
    assert fields["License-Expression"] == "MIT"
    classifiers = fields.get_all("Classifier") or []
    assert "Typing :: Typed" in classifiers
    assert "Programming Language :: Python :: 3.11" in classifiers
    assert (Path(auvplan.__file__).parent / "py.typed").is_file()
