"""The mission figure draws a polygon's holes open and greys the map outside the area."""

from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from auvplan.terrain import BathymetryGrid, GridGeometry
from auvplan.viz.mission import plot_mission_paths

SQUARE = np.array([[10.0, 10.0], [10.0, 90.0], [90.0, 90.0], [90.0, 10.0]])  # north, east [m]
HOLE = np.array([[40.0, 40.0], [60.0, 40.0], [60.0, 60.0], [40.0, 60.0]])  # other winding


def _pixels(figure: Figure, points: list[tuple[float, float]]) -> list[np.ndarray]:
    """RGB of the rendered figure at ``(north, east)`` [m] points of its map."""
    canvas = FigureCanvasAgg(figure)
    canvas.draw()
    image = np.asarray(canvas.buffer_rgba())[..., :3].astype(int)
    axes = figure.axes[0]
    colours = []
    for north, east in points:
        x, y = axes.transData.transform((east, north))
        colours.append(image[image.shape[0] - round(y), round(x)])
    return colours


def _flat_grid() -> BathymetryGrid:
    """A flat seabed: one colour everywhere, so that any shading shows."""
    return BathymetryGrid(np.full((21, 21), 20.0), GridGeometry(21, 21, 10.0, 10.0))


def test_a_hole_is_left_open_whatever_the_rings_winding() -> None:
    for exterior, hole in ((SQUARE, HOLE), (SQUARE[::-1], HOLE), (SQUARE, HOLE[::-1])):
        figure = plot_mission_paths(
            _flat_grid(), ["a"], [np.array([[150.0, 150.0], [190.0, 190.0]])], None,
            safety_radius=2.0, polygons=[(exterior, hole)],
        )  # fmt: skip
        water, ring, hole_centre = _pixels(figure, [(150.0, 50.0), (20.0, 20.0), (50.0, 50.0)])
        assert np.abs(ring - water).sum() > 60  # the zone is filled
        np.testing.assert_array_equal(hole_centre, water)  # its hole is not


def test_the_area_greys_the_outside_and_fills_its_islands() -> None:
    figure = plot_mission_paths(
        _flat_grid(), ["a"], [np.array([[20.0, 20.0], [30.0, 30.0]])], None, safety_radius=2.0,
        area=(SQUARE * 2.0, HOLE),
    )  # fmt: skip
    inside, outside, island = _pixels(figure, [(100.0, 100.0), (195.0, 100.0), (50.0, 50.0)])
    assert outside.sum() > inside.sum() + 60  # washed out
    assert np.abs(island - inside).sum() > 60
