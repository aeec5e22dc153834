"""Figures (matplotlib) and the HTML report. Imported only by users, the CLI and :mod:`auvplan.api`.

Every function returns a :class:`matplotlib.figure.Figure` without touching pyplot's global
state; save it with ``figure.savefig(path)`` or :func:`render_figure`. Each vehicle has the
colour :func:`vehicle_colors` gives it in every figure.
"""

from __future__ import annotations

from auvplan.viz.coordination import plot_coordination_space, plot_timed_paths
from auvplan.viz.geography import add_geographic_axes, add_scale_bar
from auvplan.viz.html import render_overview, render_report
from auvplan.viz.maps import plot_terrain_maps
from auvplan.viz.mission import plot_mission_paths, plot_separation, plot_time_series
from auvplan.viz.report import (
    RenderedFigure,
    mission_figures,
    render_figure,
    render_mission_figures,
    save_mission_figures,
)
from auvplan.viz.style import pair_colors, plain_tick_labels, vehicle_colors
from auvplan.viz.vehicle import plot_vehicle_validation

__all__ = [
    "RenderedFigure",
    "add_geographic_axes",
    "add_scale_bar",
    "mission_figures",
    "pair_colors",
    "plain_tick_labels",
    "plot_coordination_space",
    "plot_mission_paths",
    "plot_separation",
    "plot_terrain_maps",
    "plot_time_series",
    "plot_timed_paths",
    "plot_vehicle_validation",
    "render_figure",
    "render_mission_figures",
    "render_overview",
    "render_report",
    "save_mission_figures",
    "vehicle_colors",
]
