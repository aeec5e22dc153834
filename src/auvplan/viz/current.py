"""Current arrows (quiver) on a mission map, drawn into an existing map figure."""

from __future__ import annotations

from typing import Final

import numpy as np
from matplotlib.figure import Figure

from auvplan.ocean import CurrentField
from auvplan.terrain.grid import BathymetryGrid

__all__ = ["add_current_arrows"]

#: Arrows along the longer side of the map.
ARROWS_ALONG: Final = 14


def add_current_arrows(
    figure: Figure, bathymetry: BathymetryGrid, current: CurrentField | None, *, time: float = 0.0
) -> Figure:
    """Draw the current at mission time ``time`` [s] as arrows on the map of ``figure``.

    Parameters
    ----------
    figure : Figure
        A map figure (:func:`auvplan.viz.mission.plot_mission_paths`); its first axes are east
        [m] to the right and north [m] up.
    bathymetry : BathymetryGrid
        The map's grid (its extent places the arrows).
    current : CurrentField or None
        The current; None (still water) draws nothing.
    time : float
        Mission time of the drawn field [s].

    Returns
    -------
    Figure
        ``figure``, with a key arrow labelled with the largest speed [m/s].
    """
    if current is None:
        return figure
    axes = figure.axes[0]
    g = bathymetry.geometry
    (south, north), (west, east) = g.north_bounds, g.east_bounds
    step = max(north - south, east - west) / ARROWS_ALONG
    grid_north, grid_east = (
        axis.ravel()
        for axis in np.meshgrid(
            np.arange(south + step / 2, north, step),
            np.arange(west + step / 2, east, step),
            indexing="ij",
        )
    )
    v_n, v_e = current.velocity(grid_north, grid_east, np.full(grid_north.size, time))
    fastest = float(np.max(np.hypot(v_n, v_e), initial=0.0))
    arrows = axes.quiver(
        grid_east, grid_north, v_e, v_n, color="white", alpha=0.8,
        angles="xy", scale_units="xy", scale=max(fastest, 1e-9) / (0.8 * step), zorder=2,
        width=0.003,
    )  # fmt: skip
    if fastest > 0.0:
        axes.quiverkey(arrows, 0.88, 1.02, fastest, f"current {fastest:.2f} m/s", labelpos="W")
    return figure
