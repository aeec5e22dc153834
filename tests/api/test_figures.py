"""Figures: formats and resolution, one colour per vehicle everywhere, lat/lon axes, plain ticks."""

from __future__ import annotations

import struct

import numpy as np
import pytest
from matplotlib.figure import Figure
from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar

import auvplan
from auvplan.terrain import BathymetryGrid, GridGeometry
from auvplan.viz.mission import plot_mission_paths, plot_separation
from auvplan.viz.report import mission_figures, render_figure
from auvplan.viz.style import pair_colors, vehicle_colors

from .conftest import LAT, LON, NAMES, SHAPE


def png_size(data: bytes) -> tuple[int, int]:
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", data[16:24])
    return width, height


@pytest.mark.parametrize("dpi", [40, 90])
def test_png_resolution_follows_dpi(dpi: int) -> None:
    figure = Figure(figsize=(4.0, 2.5))
    figure.add_subplot().plot([0, 1], [0, 1])
    rendered = render_figure(figure, figure_format="png", dpi=dpi)
    assert png_size(rendered.data) == (4 * dpi, round(2.5 * dpi))
    assert rendered.preview == rendered.data


def test_vector_formats_and_their_previews() -> None:
    figure = Figure(figsize=(3.0, 2.0))
    figure.add_subplot().plot([0, 1], [0, 1])
    svg = render_figure(figure, figure_format="svg", dpi=50)
    assert b"<svg" in svg.data[:400]
    assert svg.preview_type == "image/svg+xml"
    pdf = render_figure(figure, figure_format="pdf", dpi=50)
    assert pdf.data.startswith(b"%PDF-")
    assert pdf.preview_type == "image/png"
    assert png_size(pdf.preview) == (150, 100)
    with pytest.raises(auvplan.InputError, match="'jpg' is not one of png, svg, pdf"):
        render_figure(figure, figure_format="jpg")


def _line_colors(figure: Figure, labels: list[str], axes_index: int = 0) -> list[str]:
    lines = {line.get_label(): line.get_color() for line in figure.axes[axes_index].lines}
    return [lines[label] for label in labels]


def test_each_vehicle_has_one_colour_in_every_figure(mission_plan: auvplan.MissionPlan) -> None:
    assert mission_plan.result is not None
    figures = mission_figures(mission_plan.result)
    expected = list(vehicle_colors(len(NAMES)))
    assert len(set(expected)) == len(NAMES)
    assert _line_colors(figures["paths"], list(NAMES)) == expected
    assert _line_colors(figures["paths_cost"], list(NAMES)) == expected
    assert _line_colors(mission_plan.plot(), list(NAMES)) == expected
    assert _line_colors(figures["time_series"], [f"{n} u" for n in NAMES]) == expected
    assert _line_colors(figures["time_series"], list(NAMES), axes_index=3) == expected
    pairs = [line.get_color() for line in figures["separation"].axes[0].lines[:-1]]
    assert pairs
    assert not set(pairs) & set(expected)


def test_palette_is_distinct_for_any_fleet() -> None:
    for n in (1, 2, 10, 11, 20, 21, 64):
        assert len(set(vehicle_colors(n))) == n
    assert vehicle_colors(4)[:2] == vehicle_colors(2)  # a fleet's colours do not shuffle
    assert not set(pair_colors(8)) & set(vehicle_colors(10))


def test_geographic_terrain_gets_lat_lon_axes_and_a_scale_bar(
    mission_plan: auvplan.MissionPlan,
) -> None:
    figure = mission_plan.plot()
    figure.draw_without_rendering()  # secondary axes take their limits when drawn
    axes = figure.axes[0]
    top, right = axes.child_axes
    # oracle: the grid file's latitudes and longitudes (cell centres), out to the cell edges
    for secondary, (low, high), n in ((top, LON, SHAPE[1]), (right, LAT, SHAPE[0])):
        half_cell = 0.5 * (high - low) / (n - 1)
        limits = secondary.get_xlim() if secondary is top else secondary.get_ylim()
        np.testing.assert_allclose(limits, [low - half_cell, high + half_cell], atol=1e-6)
    assert (top.get_xlabel(), right.get_ylabel()) == ("longitude [deg]", "latitude [deg]")
    bars = [artist for artist in axes.artists if isinstance(artist, AnchoredSizeBar)]
    assert len(bars) == 1
    assert bars[0].txt_label.get_text() == "50 m"  # a fifth of 490 m, rounded down to 1-2-5


def test_local_terrain_has_no_geographic_axes() -> None:
    grid = BathymetryGrid(np.full((20, 30), 30.0), GridGeometry(20, 30, 5.0, 5.0))
    path = np.array([[10.0, 10.0], [80.0, 120.0]])
    figure = plot_mission_paths(grid, ["a"], [path], [path], safety_radius=2.0)
    assert figure.axes[0].child_axes == []


def test_tick_labels_are_plain_numbers() -> None:
    time = np.linspace(0.0, 100.0, 50)
    figure = plot_separation(time, {"a / b": 30.0 + 30.0 * time / 100.0}, 10.0)
    figure.draw_without_rendering()
    axis = figure.axes[0].yaxis
    labels = [t.get_text() for t in axis.get_ticklabels() + axis.get_ticklabels(minor=True)]
    labels = [label for label in labels if label]
    assert "40" in labels
    assert not any("times" in label or "^" in label or "e+" in label for label in labels)


def test_current_arrows_show_the_field_over_the_whole_map() -> None:
    from auvplan.ocean import UniformCurrent
    from auvplan.viz.current import ARROWS_ALONG, add_current_arrows

    grid = BathymetryGrid(np.full((20, 30), 30.0), GridGeometry(20, 30, 5.0, 5.0))
    path = np.array([[10.0, 10.0], [80.0, 120.0]])
    figure = plot_mission_paths(grid, ["a"], [path], [path], safety_radius=2.0)
    add_current_arrows(figure, grid, UniformCurrent(0.15, -0.26))
    (arrows,) = figure.axes[0].collections[-1:]
    assert len(arrows.U) == ARROWS_ALONG * round(ARROWS_ALONG * 20 / 30)
    np.testing.assert_allclose(arrows.U, -0.26)
    np.testing.assert_allclose(arrows.V, 0.15)
    offsets = arrows.get_offsets()
    assert offsets[:, 0].min() > 0.0
    assert offsets[:, 0].max() < 150.0
    assert offsets[:, 1].min() > 0.0
    assert offsets[:, 1].max() < 100.0
