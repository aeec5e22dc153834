"""Terrain: bathymetry grids, the local frame, and terrain-information maps (paper Sec. III-A)."""

from __future__ import annotations

from auvplan.terrain.grid import BathymetryGrid, GridGeometry
from auvplan.terrain.projection import LocalProjection

__all__ = ["BathymetryGrid", "GridGeometry", "LocalProjection"]
