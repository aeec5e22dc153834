"""Terrain: bathymetry grids, the local frame, and terrain-information maps (paper Sec. III-A)."""

from __future__ import annotations

from auvplan.terrain.grid import BathymetryGrid, GridGeometry
from auvplan.terrain.maps import (
    MapParameters,
    TerrainMaps,
    compute_cost_map,
    compute_excitation_map,
    compute_gradient_magnitude,
    compute_information_map,
    compute_shifted_cost,
    compute_terrain_maps,
)
from auvplan.terrain.projection import LocalProjection
from auvplan.terrain.synthetic import synthetic_bank

__all__ = [
    "BathymetryGrid",
    "GridGeometry",
    "LocalProjection",
    "MapParameters",
    "TerrainMaps",
    "compute_cost_map",
    "compute_excitation_map",
    "compute_gradient_magnitude",
    "compute_information_map",
    "compute_shifted_cost",
    "compute_terrain_maps",
    "synthetic_bank",
]
