"""Fixtures of the navigation tests: a strongly featured and a flat synthetic seabed."""

from __future__ import annotations

import numpy as np
import pytest
from _navigation_synthetic import featured_depth, make_grid

from auvplan.terrain import BathymetryGrid


@pytest.fixture(scope="session")
def featured_grid() -> BathymetryGrid:
    """1 km x 1 km of strong relief on a 5 m grid."""
    return make_grid(featured_depth)


@pytest.fixture(scope="session")
def flat_grid() -> BathymetryGrid:
    """1 km x 1 km of flat seabed at 45 m."""
    return make_grid(lambda north, east: np.full_like(north, 45.0))
