"""Figures of a planned mission: the paper's Fig. 6, time series and pairwise separation.

East is drawn to the right and north up, with equal aspect; on georeferenced terrain the map
also has latitude/longitude axes and a scale bar (:mod:`auvplan.viz.geography`). Each vehicle
has its colour of :func:`auvplan.viz.style.vehicle_colors` in every figure. All functions
return a :class:`matplotlib.figure.Figure` and touch no global pyplot state.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Final

import numpy as np
from matplotlib.colors import Colormap
from matplotlib.figure import Figure
from matplotlib.patches import Circle, PathPatch
from matplotlib.path import Path as MplPath

from auvplan._typing import FloatArray
from auvplan.terrain.grid import BathymetryGrid
from auvplan.vehicle import VehicleModel
from auvplan.viz.figure import NotebookFigure
from auvplan.viz.geography import add_geographic_axes
from auvplan.viz.style import lighter, pair_colors, plain_tick_labels, vehicle_colors

#: Line styles of a vehicle's successive actuators in one panel.
_LINE_STYLES: Final = ("-", "--", ":", "-.")
#: Legend names of MEDUSA's thrusters (others are labelled with their thruster's name).
_ACTUATOR_LABELS: Final = {"n_ps": "port", "n_sb": "starboard"}


def plot_mission_paths(
    bathymetry: BathymetryGrid,
    names: Sequence[str],
    planned: Sequence[FloatArray],
    optimized: Sequence[FloatArray] | None,
    *,
    safety_radius: float,
    circles: FloatArray | None = None,
    polygons: Sequence[FloatArray | tuple[FloatArray, ...]] = (),
    area: Sequence[FloatArray] = (),
    background: FloatArray | None = None,
    background_label: str = "depth [m]",
    cmap: str | Colormap = "viridis_r",
    title: str = "",
) -> Figure:
    """The paper's Fig. 6: pre-planned paths and optimised trajectories over the bathymetry.

    Parameters
    ----------
    bathymetry : BathymetryGrid
        Grid whose depth (or ``background``, same shape) is drawn.
    names : sequence of str
        Vehicle names.
    planned : sequence of ndarray of shape (n_i, 2)
        Pre-planned paths, ``north, east`` [m] (drawn dashed, in a light shade of the
        vehicle's colour, over the trajectories).
    optimized : sequence of ndarray of shape (n_t, 2) or None
        Optimised trajectories (solid, per-vehicle colour), with start/goal markers and safety
        circles of radius ``safety_radius`` at both ends.
    safety_radius : float
        ``r_c`` [m].
    circles : ndarray of shape (n, 3), optional
        Circular obstacles ``north, east, radius`` [m].
    polygons : sequence of ndarray of shape (n_k, 2), or of tuples of them
        Polygon obstacles, vertices ``north, east`` [m]: a ring, or the exterior ring and its
        holes (left open).
    area : sequence of ndarray of shape (n_k, 2)
        The operating area's rings (exterior, then its islands): the map outside it is
        greyed, its islands filled like obstacles. Empty: no area.
    background : ndarray, optional
        Field to draw instead of depth (e.g. the cost map on its own grid is not supported:
        pass a field on the bathymetry grid).
    """
    figure = NotebookFigure(figsize=(9.0, 5.5), layout="constrained")
    axes = figure.add_subplot()
    g = bathymetry.geometry
    field = bathymetry.depth if background is None else background
    # the grid as an image inside vector (SVG/PDF) files: small files, vector lines and text
    mesh = axes.pcolormesh(g.east, g.north, field, cmap=cmap, shading="nearest", rasterized=True)
    figure.colorbar(mesh, ax=axes, label=background_label, shrink=0.85)
    if background is None:
        finite = bathymetry.depth[np.isfinite(bathymetry.depth)]
        if finite.size and np.ptp(finite) > 0:
            axes.contour(g.east, g.north, bathymetry.depth, levels=12, colors="k",
                         linewidths=0.4, alpha=0.5)  # fmt: skip
    colors = vehicle_colors(len(names))
    for k, (name, path) in enumerate(zip(names, planned, strict=True)):
        axes.plot(path[:, 1], path[:, 0], "--", color=lighter(colors[k]), lw=1.5, zorder=3,
                  label=f"{name} pre-planned" if optimized is None else None)  # fmt: skip
    if optimized is not None:
        axes.plot([], [], "--", color="0.6", lw=1.5, label="pre-planned (dashed)")
        for k, (name, track) in enumerate(zip(names, optimized, strict=True)):
            axes.plot(track[:, 1], track[:, 0], "-", color=colors[k], lw=2.0, label=name)
            for point, marker in ((track[0], "o"), (track[-1], "*")):
                axes.plot(point[1], point[0], marker, color=colors[k], ms=9, mec="k")
                axes.add_patch(Circle((point[1], point[0]), safety_radius, fill=False,
                                      ec=colors[k], lw=1.0))  # fmt: skip
    for north, east, radius in np.asarray(circles if circles is not None else []).reshape(-1, 3):
        axes.add_patch(Circle((east, north), radius, fc="0.3", ec="k", alpha=0.7))
    for rings in polygons:
        rings = (rings,) if isinstance(rings, np.ndarray) else rings
        axes.add_patch(PathPatch(_region(*rings), fc="0.3", ec="k", alpha=0.7))
    if len(area):
        (n0, n1), (e0, e1) = g.north_bounds, g.east_bounds
        frame = np.array([[n0, e0], [n1, e0], [n1, e1], [n0, e1]])
        axes.add_patch(PathPatch(_region(frame, area[0]), fc="w", ec="none", alpha=0.5))
        axes.add_patch(PathPatch(_region(area[0]), fill=False, ec="k", ls="--", lw=1.2))
        for island in area[1:]:
            axes.add_patch(PathPatch(_region(island), fc="0.3", ec="k", alpha=0.7))
    axes.set_aspect("equal")
    axes.set_xlabel("east [m]")
    axes.set_ylabel("north [m]")
    axes.set_xlim(*g.east_bounds)
    axes.set_ylim(*g.north_bounds)
    axes.legend(loc="upper left", fontsize="small")
    axes.set_title(title or "Pre-planned paths (dashed) and optimised trajectories")
    if bathymetry.projection is not None:
        add_geographic_axes(axes, bathymetry.projection)
    return plain_tick_labels(figure)


def _region(exterior: FloatArray, *holes: FloatArray) -> MplPath:
    """A polygon ``north, east`` [m] with holes as a matplotlib path in ``(east, north)``.

    The exterior is wound counter-clockwise and the holes clockwise, so that the nonzero fill
    rule leaves the holes open.
    """

    def ring(vertices: FloatArray, counter_clockwise: bool) -> MplPath:
        xy = np.column_stack([vertices[:, 1], vertices[:, 0]])
        area = np.sum(xy[:, 0] * np.roll(xy[:, 1], -1) - np.roll(xy[:, 0], -1) * xy[:, 1])
        if (area > 0.0) != counter_clockwise:
            xy = xy[::-1]
        return MplPath(np.vstack([xy, xy[:1]]), closed=True)

    return MplPath.make_compound_path(ring(exterior, True), *(ring(h, False) for h in holes))


def plot_time_series(
    time: FloatArray,
    names: Sequence[str],
    states: Sequence[FloatArray],
    power: FloatArray,
    *,
    models: Sequence[VehicleModel],
) -> Figure:
    """Surge/sway speed, yaw rate, each vehicle's own actuators and electrical power.

    ``states[i]`` has shape ``(n_t, n_x_i)``, the states of ``models[i]``; ``power``
    ``(n_vehicles, n_t)`` [W]. Each propeller speed ``n_<thruster>`` [rev/s] is drawn and
    labelled with its thruster's name; a fleet with control surfaces gets a panel of
    deflections [deg].
    """
    layouts = [(m.state_names, m.thruster_states, m.surface_states) for m in models]
    has_surfaces = any(surfaces for _, _, surfaces in layouts)
    panels = 5 if has_surfaces else 4
    figure = NotebookFigure(figsize=(9.0, 2.25 * panels), layout="constrained")
    axes = figure.subplots(panels, 1, sharex=True)
    colors = vehicle_colors(len(names))
    for k, (name, (own, thrusters, surfaces)) in enumerate(zip(names, layouts, strict=True)):
        series = dict(zip(own, np.transpose(states[k]), strict=True))
        axes[0].plot(time, series["u"], color=colors[k], label=f"{name} u")
        axes[0].plot(time, series["v"], ":", color=colors[k], label=f"{name} v")
        axes[1].plot(time, series["r"], color=colors[k], label=name)
        for j, state in enumerate(thrusters):
            label = f"{name} {_ACTUATOR_LABELS.get(state, state.removeprefix('n_'))}"
            style = _LINE_STYLES[j % len(_LINE_STYLES)]
            axes[2].plot(time, series[state], style, color=colors[k], label=label)
        for j, state in enumerate(surfaces):
            label = f"{name} {state.removeprefix('delta_')}"
            style = _LINE_STYLES[j % len(_LINE_STYLES)]
            axes[3].plot(time, np.degrees(series[state]), style, color=colors[k], label=label)
        axes[-1].plot(time, power[k], color=colors[k], label=name)
    labels = [
        "speed [m/s]",
        "yaw rate [rad/s]",
        "propeller [rev/s]",
        *(["deflection [deg]"] if has_surfaces else []),
        "electrical power [W]",
    ]
    for ax, label in zip(axes, labels, strict=True):
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small", ncol=2)
    axes[-1].set_xlabel("time [s]")
    return plain_tick_labels(figure)


def plot_separation(
    time: FloatArray, separations: Mapping[str, FloatArray], minimum: float
) -> Figure:
    """Pairwise (and vehicle-obstacle) separation [m] against time with the limit ``minimum``."""
    figure = NotebookFigure(figsize=(9.0, 4.0), layout="constrained")
    axes = figure.add_subplot()
    colors = pair_colors(len(separations))
    for color, (label, distance) in zip(colors, separations.items(), strict=True):
        axes.plot(time, distance, color=color, label=label)
    axes.axhline(minimum, color="r", ls="--", label=f"2 r_c = {minimum:g} m")
    axes.set_xlabel("time [s]")
    axes.set_ylabel("separation [m]")
    axes.set_yscale("log")
    axes.grid(alpha=0.3, which="both")
    axes.legend(fontsize="small")
    return plain_tick_labels(figure)
