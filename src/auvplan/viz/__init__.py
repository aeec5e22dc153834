"""Figures (matplotlib). Imported only by users and the CLI, never by the core packages.

Every function returns a :class:`matplotlib.figure.Figure` without touching pyplot's global
state; save it with ``figure.savefig(path)``.
"""

from __future__ import annotations

from auvplan.viz.coordination import plot_coordination_space, plot_timed_paths
from auvplan.viz.maps import plot_terrain_maps
from auvplan.viz.mission import plot_mission_paths, plot_separation, plot_time_series
from auvplan.viz.report import mission_figures, save_mission_figures
from auvplan.viz.vehicle import plot_vehicle_validation

__all__ = [
    "mission_figures",
    "plot_coordination_space",
    "plot_mission_paths",
    "plot_separation",
    "plot_terrain_maps",
    "plot_time_series",
    "plot_timed_paths",
    "plot_vehicle_validation",
    "save_mission_figures",
]
