"""Shared fixtures: a seeded RNG and the real bathymetry grids of ../shared/data."""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
# the CLI's second process (auvplan.api.companion) is tested on its own: the many in-process
# `auvplan plan` runs of the suite use one process each, as `--jobs 1`
os.environ.setdefault("AUVPLAN_JOBS", "1")

SHARED_DATA = Path(
    os.environ.get("AUVPLAN_SHARED_DATA", Path(__file__).parents[1] / ".." / "shared" / "data")
)


@pytest.fixture
def rng() -> np.random.Generator:
    """A seeded generator; tests never touch global random state."""
    return np.random.default_rng(20131023)


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """``../shared/data`` (skip the test when the folder is absent)."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"shared data folder not found at {SHARED_DATA}")
    return SHARED_DATA.resolve()


@pytest.fixture(scope="session")
def bathymetry_dir(shared_data: Path) -> Path:
    """``../shared/data/bathymetry`` (skip when absent)."""
    path = shared_data / "bathymetry"
    if not path.is_dir():
        pytest.skip(f"bathymetry folder not found at {path}")
    return path
