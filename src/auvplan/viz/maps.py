"""The paper's Fig. 5: bathymetry, information, excitation and cost maps side by side."""

from __future__ import annotations

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from auvplan._typing import FloatArray
from auvplan.terrain.grid import GridGeometry
from auvplan.terrain.maps import TerrainMaps
from auvplan.viz.figure import NotebookFigure
from auvplan.viz.geography import add_geographic_axes
from auvplan.viz.style import plain_tick_labels

#: Colour of NaN (land / no-data / no-go) cells.
LAND_COLOR = "#c8b58a"


def plot_terrain_maps(maps: TerrainMaps, *, width_inches: float = 11.0) -> Figure:
    """Four panels (bathymetry, information, excitation, cost) on shared north/east axes.

    Parameters
    ----------
    maps : TerrainMaps
        The maps to draw.
    width_inches : float
        Figure width [in]; the height follows from the map's aspect ratio.

    Returns
    -------
    matplotlib.figure.Figure
        A 2 x 2 grid of panels with east to the right, north up, equal aspect, a colour bar
        with units on each panel, and NaN (no-go) cells in a land colour; on georeferenced
        terrain, longitude on top of the upper panels and a scale bar on the bathymetry.
        Created without pyplot, so it never touches global state; save it with
        ``fig.savefig(path)``.
    """
    fine, coarse = maps.bathymetry.geometry, maps.cost_geometry
    south, north = fine.north_bounds
    west, east = fine.east_bounds
    aspect = (north - south) / max(east - west, 1e-9)
    panel_width = 0.5 * width_inches
    height = 2.0 * panel_width * aspect * 0.85 + 1.2
    figure = NotebookFigure(figsize=(width_inches, float(np.clip(height, 3.0, 3.0 * width_inches))))
    figure.set_layout_engine("constrained")
    axes = figure.subplots(2, 2, sharex=True, sharey=True)
    parameters = maps.parameters
    r_north, r_east = parameters.block
    panels = [
        (maps.bathymetry.depth, fine, "viridis_r", "depth [m]", "Bathymetry $M_B$"),
        (
            maps.information,
            fine,
            "magma",
            "information [-]",
            f"Information $M_I$ (s = {parameters.exponent:g})",
        ),
        (
            maps.excitation,
            coarse,
            "magma",
            "excitation [-]",
            f"Excitation $M_E$ ({r_north} x {r_east} blocks)",
        ),
        (maps.cost, coarse, "cividis", "cost [-]", r"Cost $M_C = \cos(\pi/2\,M_E)$"),
    ]
    for ax, (values, geometry, cmap, unit, title) in zip(axes.flat, panels, strict=True):
        _draw(figure, ax, values, geometry, cmap, unit, title)
    for ax in axes[1]:
        ax.set_xlabel("east [m]")
    for ax in axes[:, 0]:
        ax.set_ylabel("north [m]")
    figure.suptitle(
        f"Terrain maps of {maps.bathymetry.name or 'the bathymetry'}: "
        f"shifted cost = {parameters.omega:g} + {parameters.weight:g} $M_C$"
    )
    projection = maps.bathymetry.projection
    if projection is not None:
        for column, ax in enumerate(axes[0]):
            add_geographic_axes(ax, projection, latitude=False, scale_bar=column == 0)
    return plain_tick_labels(figure)


def _draw(
    figure: Figure,
    ax: Axes,
    values: FloatArray,
    geometry: GridGeometry,
    cmap_name: str,
    unit: str,
    title: str,
) -> None:
    cmap = colormaps[cmap_name].with_extremes(bad=LAND_COLOR)
    south, north = geometry.north_bounds
    west, east = geometry.east_bounds
    finite = values[np.isfinite(values)]
    low, high = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    image = ax.imshow(
        np.ma.masked_invalid(values),
        origin="lower",
        extent=(west, east, south, north),
        cmap=cmap,
        vmin=low,
        vmax=high if high > low else low + 1.0,
        interpolation="nearest",
    )
    ax.set_aspect("equal")
    ax.set_title(title, fontsize="medium")
    colorbar = figure.colorbar(image, ax=ax, shrink=0.9)
    colorbar.set_label(unit)
