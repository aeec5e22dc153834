"""Synthetic seabeds and tracks shared by the navigation tests."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from auvplan.navigation import Track
from auvplan.terrain import BathymetryGrid, GridGeometry

SPACING = 5.0
N_ROWS, N_COLS = 200, 200  # 1 km x 1 km


def featured_depth(north: np.ndarray, east: np.ndarray) -> np.ndarray:
    """Strong, non-repeating relief (tens of metres over ~100 m): a TAN-friendly seabed."""
    return (
        60.0
        + 12.0 * np.sin(north / 37.0) * np.cos(east / 53.0)
        + 7.0 * np.sin((north + 2.0 * east) / 29.0)
        + 5.0 * np.cos((3.0 * north - east) / 41.0)
    )


def make_grid(depth_function: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> BathymetryGrid:
    """A 1 km x 1 km grid of 5 m cells whose node depths are ``depth_function(north, east)``."""
    geometry = GridGeometry(N_ROWS, N_COLS, SPACING, SPACING)
    north, east = np.meshgrid(geometry.north, geometry.east, indexing="ij")
    return BathymetryGrid(depth_function(north, east), geometry)


def straight_track(
    start: tuple[float, float], heading: float, speed: float, duration: float, dt: float = 1.0
) -> Track:
    """A straight track at constant speed [m/s] and heading [rad] from ``start`` [m]."""
    time = np.arange(0.0, duration + 0.5 * dt, dt)
    direction = np.array([np.cos(heading), np.sin(heading)])
    positions = np.asarray(start)[None, :] + speed * time[:, None] * direction[None, :]
    return Track(time, positions, np.full(time.size, heading))
