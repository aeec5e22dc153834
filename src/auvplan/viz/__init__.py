"""Figures (matplotlib) and the HTML report. Imported only by users, the CLI and :mod:`auvplan.api`.

Every function returns a :class:`matplotlib.figure.Figure` without touching pyplot's global
state; save it with ``figure.savefig(path)`` or :func:`render_figure`. Each vehicle has the
colour :func:`vehicle_colors` gives it in every figure.

The names below are imported from their modules on first use (PEP 562), so that importing
one module of the package, e.g. :mod:`auvplan.viz.html` for a report without figures, does
not import matplotlib.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from auvplan._lazy import lazy_attributes

if TYPE_CHECKING:
    from auvplan._figures import RenderedFigure
    from auvplan.viz.coordination import plot_coordination_space, plot_timed_paths
    from auvplan.viz.geography import add_geographic_axes, add_scale_bar
    from auvplan.viz.html import render_overview, render_report
    from auvplan.viz.maps import plot_terrain_maps
    from auvplan.viz.mission import plot_mission_paths, plot_separation, plot_time_series
    from auvplan.viz.report import (
        mission_figures,
        render_figure,
        render_mission_figures,
        save_mission_figures,
    )
    from auvplan.viz.style import pair_colors, plain_tick_labels, vehicle_colors
    from auvplan.viz.vehicle import plot_vehicle_validation

#: Each public name's module.
_MODULES = {
    "RenderedFigure": "auvplan._figures",
    "add_geographic_axes": "auvplan.viz.geography",
    "add_scale_bar": "auvplan.viz.geography",
    "mission_figures": "auvplan.viz.report",
    "pair_colors": "auvplan.viz.style",
    "plain_tick_labels": "auvplan.viz.style",
    "plot_coordination_space": "auvplan.viz.coordination",
    "plot_mission_paths": "auvplan.viz.mission",
    "plot_separation": "auvplan.viz.mission",
    "plot_terrain_maps": "auvplan.viz.maps",
    "plot_time_series": "auvplan.viz.mission",
    "plot_timed_paths": "auvplan.viz.coordination",
    "plot_vehicle_validation": "auvplan.viz.vehicle",
    "render_figure": "auvplan.viz.report",
    "render_mission_figures": "auvplan.viz.report",
    "render_overview": "auvplan.viz.html",
    "render_report": "auvplan.viz.html",
    "save_mission_figures": "auvplan.viz.report",
    "vehicle_colors": "auvplan.viz.style",
}


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

__getattr__, __dir__ = lazy_attributes(__name__, _MODULES, __all__)
