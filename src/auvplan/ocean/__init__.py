"""Ocean currents: fields in the local frame and speeds along a path in a current."""

from __future__ import annotations

from auvplan.ocean.current import CurrentField, GriddedCurrent, UniformCurrent
from auvplan.ocean.speed import ground_speed, through_water

__all__ = ["CurrentField", "GriddedCurrent", "UniformCurrent", "ground_speed", "through_water"]
