"""``navigation.png``: terrain-aided navigation along each plan, plans side by side.

One column per plan (terrain-aware, energy-only). Top: the tracks over the bathymetry, zoomed
on the vehicles (true track solid, one run's dead-reckoned track dotted and TAN estimate
dashed). Below, one panel per vehicle: the TAN position error (RMS over the runs) against
time, the filter's own standard deviation as a band, the dead-reckoning error and the
posterior Cramér-Rao bound. Rows share their axes, so plans compare at a glance.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from auvplan.navigation.evaluation import PlanNavigation, time_series
from auvplan.navigation.prediction import ErrorPrediction
from auvplan.terrain import BathymetryGrid
from auvplan.viz.figure import NotebookFigure
from auvplan.viz.geography import add_geographic_axes
from auvplan.viz.style import plain_tick_labels, vehicle_colors

#: Margin [m] around the tracks in the map panels, and their least width / height.
MAP_MARGIN_M = 40.0
MAP_MIN_ASPECT = 0.8
PLAN_TITLES = {
    "terrain_aware": "mission's plan",
    "energy_only": "energy-only plan",
    "paper": "paper's plan (information map)",
}


def plot_navigation(
    bathymetry: BathymetryGrid, evaluations: Mapping[str, PlanNavigation]
) -> Figure:
    """The navigation figure (module notes).

    Parameters
    ----------
    bathymetry : BathymetryGrid
        The map drawn under the tracks.
    evaluations : mapping of str to PlanNavigation
        By plan label, as :func:`auvplan.navigation.evaluation.evaluate_plans` returns them.

    Returns
    -------
    matplotlib.figure.Figure
    """
    labels = list(evaluations)
    names = list(dict.fromkeys(n for e in evaluations.values() for n in e.results))
    figure = NotebookFigure(
        figsize=(5.2 * len(labels) + 1.0, 4.6 + 2.3 * len(names)), layout="constrained"
    )
    grid = figure.add_gridspec(1 + len(names), len(labels), height_ratios=[2.2] + [1] * len(names))
    bounds = _track_bounds(evaluations)
    colors = vehicle_colors(len(names))
    error_axes: list[Axes] = []
    for column, label in enumerate(labels):
        evaluation = evaluations[label]
        map_axes = figure.add_subplot(grid[0, column])
        _draw_map(map_axes, bathymetry, evaluation, names, bounds, colors)
        energy = sum(evaluation.energy.values())
        rmse = np.mean([result.rmse.mean() for result in evaluation.results.values()])
        map_axes.set_title(
            f"{PLAN_TITLES.get(label, label)}\nTAN RMSE {rmse:.2f} m, energy {energy / 1e3:.1f} kJ"
        )
        for row, name in enumerate(names):
            axes = figure.add_subplot(
                grid[1 + row, column], sharey=error_axes[0] if error_axes else None
            )
            error_axes.append(axes)
            if name in evaluation.results:
                _draw_errors(axes, evaluation, name, colors[names.index(name)], is_first=row == 0)
            axes.set_title(name, fontsize="medium", loc="left")
            axes.set_ylabel("position error [m]")
            if row == len(names) - 1:
                axes.set_xlabel("time [s]")
    top = max(
        float(np.max(np.concatenate(list(time_series(result).values()))))
        for evaluation in evaluations.values()
        for result in evaluation.results.values()
    )
    error_axes[0].set_ylim(0.0, 1.5 * top)  # room for the legend above the curves
    return plain_tick_labels(figure)


def _track_bounds(evaluations: Mapping[str, PlanNavigation]) -> tuple[float, ...]:
    """South, north, west, east [m] of every drawn track, plus the margin."""
    points = np.vstack(
        [
            np.vstack([r.truth, r.example_estimate, r.example_dead_reckoning])
            for e in evaluations.values()
            for r in e.results.values()
        ]
    )
    low = points.min(axis=0) - MAP_MARGIN_M
    high = points.max(axis=0) + MAP_MARGIN_M
    # at least MAP_MIN_ASPECT as wide as tall, so that a northbound mission is not a sliver
    half_width = max(0.5 * (high[1] - low[1]), 0.5 * MAP_MIN_ASPECT * (high[0] - low[0]))
    centre = 0.5 * (low[1] + high[1])
    return float(low[0]), float(high[0]), centre - half_width, centre + half_width


def _draw_map(
    axes: Axes,
    bathymetry: BathymetryGrid,
    evaluation: PlanNavigation,
    names: list[str],
    bounds: tuple[float, ...],
    colors: tuple[str, ...],
) -> None:
    geometry = bathymetry.geometry
    mesh = axes.pcolormesh(
        geometry.east, geometry.north, bathymetry.depth, cmap="viridis_r", shading="nearest",
        rasterized=True,
    )  # fmt: skip
    axes.figure.colorbar(mesh, ax=axes, label="depth [m]", shrink=0.9)
    for name, result in evaluation.results.items():
        color = colors[names.index(name)]
        axes.plot(result.truth[:, 1], result.truth[:, 0], "-", color=color, lw=2.0, label=name)
        axes.plot(
            result.example_dead_reckoning[:, 1],
            result.example_dead_reckoning[:, 0],
            ":",
            color="white",
            lw=1.4,
        )
        axes.plot(
            result.example_estimate[:, 1], result.example_estimate[:, 0], "--", color="k", lw=1.0
        )
    axes.plot([], [], ":", color="white", label="dead reckoning (run 1)")
    axes.plot([], [], "--", color="k", label="TAN estimate (run 1)")
    axes.set_facecolor("0.85")
    axes.legend(
        loc="upper center",
        bbox_to_anchor=(0.5, -0.14),
        ncol=2,
        fontsize="x-small",
        facecolor="0.75",
    )
    axes.set_aspect("equal")
    axes.set_xlim(bounds[2], bounds[3])
    axes.set_ylim(bounds[0], bounds[1])
    axes.set_xlabel("east [m]")
    axes.set_ylabel("north [m]")
    if bathymetry.projection is not None:
        add_geographic_axes(axes, bathymetry.projection, latitude=False)


def _draw_errors(
    axes: Axes, evaluation: PlanNavigation, name: str, color: str, *, is_first: bool
) -> None:
    result = evaluation.results[name]
    curves = time_series(result)
    time = result.time
    axes.fill_between(
        time, 0.0, curves["sigma"], color=color, alpha=0.2, lw=0, label="filter σ (mean)"
    )
    axes.plot(time, curves["tan"], color=color, lw=1.8, label=f"TAN error (RMS of {result.n_runs})")
    axes.plot(time, curves["dead_reckoning"], "--", color="k", lw=1.0, label="dead reckoning")
    axes.plot(time, curves["pcrb"], ":", color="0.3", lw=1.2, label="PCRB")
    axes.grid(alpha=0.3)
    if is_first:
        axes.legend(fontsize="x-small", ncol=2, loc="upper right")


def plot_predicted_error(
    names: tuple[str, ...],
    plans: Mapping[str, tuple[ErrorPrediction, ...]],
    *,
    budget: float | None = None,
    settle_s: float = 0.0,
) -> Figure:
    """The predicted TAN error (1-σ radial) [m] against time, one panel per vehicle.

    ``plans`` maps a plan's title to each vehicle's prediction along its flown track (the
    first drawn solid, the others dashed and dotted); ``budget`` [m], if given, is drawn from
    ``settle_s`` [s] on.
    """
    figure = NotebookFigure(figsize=(9.0, 1.2 + 2.0 * len(names)), layout="constrained")
    axes_list = figure.subplots(len(names), 1, sharex=True, squeeze=False)[:, 0]
    colors = vehicle_colors(len(names))
    styles = ("-", "--", ":")
    for index, (name, axes) in enumerate(zip(names, axes_list, strict=True)):
        for style, (title, predictions) in zip(styles, plans.items(), strict=False):
            prediction = predictions[index]
            axes.plot(prediction.time, prediction.sigma, style, color=colors[index], label=title)
        if budget is not None:
            end = max(float(p[index].time[-1]) for p in plans.values())
            axes.hlines(budget, settle_s, end, colors="r", linestyles="--", label="budget")
        axes.set_ylabel(f"{name}: σ [m]")
        axes.set_ylim(bottom=0.0)
        axes.grid(alpha=0.3)
        axes.legend(fontsize="small", loc="upper left")
    axes_list[-1].set_xlabel("time [s]")
    figure.suptitle("Predicted TAN position error along the flown plans")
    return plain_tick_labels(figure)
