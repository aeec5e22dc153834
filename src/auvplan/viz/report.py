"""All figures of a mission run, rendered as PNG, SVG or PDF files."""

from __future__ import annotations

import io
from collections.abc import Callable, Collection, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from auvplan._figures import DEFAULT_DPI, FIGURE_FORMATS, RenderedFigure
from auvplan.errors import InputError
from auvplan.interrupts import checkpoint
from auvplan.io.writing import writing
from auvplan.mission.evaluation import OptimizedPlan
from auvplan.mission.navigation import budget_of
from auvplan.mission.pipeline import MissionResult
from auvplan.planning import CircleObstacle, OperatingArea, PolygonObstacle
from auvplan.vehicle import positions
from auvplan.viz._notices import notices_as_debug
from auvplan.viz.coordination import plot_coordination_space
from auvplan.viz.current import add_current_arrows
from auvplan.viz.maps import plot_terrain_maps
from auvplan.viz.mission import plot_mission_paths, plot_separation, plot_time_series
from auvplan.viz.navigation import plot_predicted_error


def render_figure(
    figure: Figure, *, figure_format: str = "png", dpi: int = DEFAULT_DPI
) -> RenderedFigure:
    """Render ``figure`` as ``figure_format`` at ``dpi`` dots per inch (raster parts).

    Raises
    ------
    InputError
        If ``figure_format`` is not one of :data:`FIGURE_FORMATS` or ``dpi`` is not positive.
    """
    if figure_format not in FIGURE_FORMATS:
        raise InputError(
            f"figure format {figure_format!r} is not one of {', '.join(FIGURE_FORMATS)}"
        )
    if not dpi > 0:
        raise InputError(f"dpi must be positive, got {dpi}")

    def render(file_format: str) -> bytes:
        buffer = io.BytesIO()
        metadata = {"Date": None} if file_format == "svg" else {}  # reproducible files
        with notices_as_debug():  # missing glyphs (a vehicle named in CJK), collapsed layouts
            figure.savefig(buffer, format=file_format, dpi=dpi, metadata=metadata)
        return buffer.getvalue()

    checkpoint()  # a stop request (SIGINT/SIGTERM) between figures
    data = render(figure_format)
    if figure_format == "pdf":
        return RenderedFigure(figure_format, data, render("png"), FIGURE_FORMATS["png"])
    return RenderedFigure(figure_format, data, data, FIGURE_FORMATS[figure_format])


def mission_figures(result: MissionResult) -> dict[str, Figure]:
    """The figures of a run, by file stem (:func:`figure_builders`)."""
    return {stem: build() for stem, build in figure_builders(result).items()}


def figure_builders(result: MissionResult) -> dict[str, Callable[[], Figure]]:
    """What draws each figure of a run, by file stem, in the order of the report.

    ``maps`` (paper Fig. 5), ``paths`` (Fig. 6 over the bathymetry), ``paths_cost`` (over the
    cost map), and by stage ``coordination``, ``time_series`` (speeds, propellers, power),
    ``separation`` and, with the comparisons, ``paths_energy_only`` and ``paths_paper``.
    """
    preplan = result.preplan
    circles = np.array(
        [(o.north, o.east, o.radius) for o in preplan.obstacles if isinstance(o, CircleObstacle)]
    ).reshape(-1, 3)
    polygons = [o.rings for o in preplan.obstacles if isinstance(o, PolygonObstacle)]
    area = next((o.region.rings for o in preplan.obstacles if isinstance(o, OperatingArea)), ())
    planned = [route.points for route in preplan.routes]
    stage2 = result.deconfliction
    plan = result.plan
    radius = result.config.fleet.safety_radius

    def paths(tracks: OptimizedPlan | None, **options: Any) -> Figure:
        return plot_mission_paths(
            preplan.bathymetry, preplan.names, planned,
            None if tracks is None else _tracks(result, tracks.states), safety_radius=radius,
            circles=circles, polygons=polygons, area=area, **options,
        )  # fmt: skip

    builders: dict[str, Callable[[], Figure]] = {
        "maps": lambda: plot_terrain_maps(preplan.maps),
        "paths": lambda: add_current_arrows(paths(plan), preplan.bathymetry, preplan.current),
        "paths_cost": lambda: paths(
            plan,
            background=_cost_on_bathymetry_grid(result),
            background_label="shifted cost ω + w·M_C",
            cmap="magma",
            title="Pre-planned paths over the cost map",
        ),
    }
    energy_only = result.energy_only
    if energy_only is not None:
        builders["paths_energy_only"] = lambda: paths(
            energy_only,
            title="Energy-only optimum (terrain weight 0) against the pre-planned paths",
        )
    paper = result.paper
    if paper is not None and paper.plan is not None:
        paper_plan = paper.plan
        builders["paths_paper"] = lambda: plot_mission_paths(
            preplan.bathymetry, preplan.names, [route.points for route in paper.preplan.routes],
            _tracks(paper, paper_plan.states), safety_radius=radius, circles=circles,
            polygons=polygons, area=area,
            title="The paper's plan: information-map routes and their optimum",
        )  # fmt: skip
    if plan is not None:
        builders["navigation_predicted"] = lambda: _predicted_error(result)
    if stage2 is not None and len(preplan.names) >= 2:
        builders["coordination"] = lambda: plot_coordination_space(
            stage2.problem, stage2.coordination, pair=(0, 1)
        )
    if plan is not None and stage2 is not None:
        builders["time_series"] = lambda: plot_time_series(
            stage2.time, preplan.names, plan.states, plan.power, models=stage2.layout.models
        )
        if plan.fine_distances:
            builders["separation"] = lambda: plot_separation(
                plan.fine_time,
                {str(pair): distance for pair, distance in plan.fine_distances.items()},
                2 * radius,
            )
    return builders


def _predicted_error(result: MissionResult) -> Figure:
    """The predicted TAN error of the plan and of its comparisons, per vehicle."""
    assert result.plan is not None
    plans = {
        title: plan.predicted_navigation
        for title, plan in (
            ("plan", result.plan),
            ("energy-only plan", result.energy_only),
            ("paper's plan", result.paper_plan),
        )
        if plan is not None
    }
    navigation = result.config.navigation
    return plot_predicted_error(
        result.preplan.names,
        plans,
        budget=budget_of(result.config),
        settle_s=navigation.settle,
    )


def _tracks(result: MissionResult, states: Sequence[np.ndarray]) -> list[np.ndarray]:
    """North/east ``(n_t, 2)`` of each vehicle's states."""
    assert result.deconfliction is not None  # a plan exists only after stage 2
    models = result.deconfliction.layout.models
    return [positions(model, track) for model, track in zip(models, states, strict=True)]


def _cost_on_bathymetry_grid(result: MissionResult) -> np.ndarray:
    """The block cost map expanded back onto the bathymetry grid (for drawing)."""
    maps = result.preplan.maps
    r_n, r_e = maps.parameters.block
    expanded = np.kron(maps.shifted_cost, np.ones((r_n, r_e)))
    shape = result.preplan.bathymetry.geometry.shape
    field = np.full(shape, np.nan)
    field[: expanded.shape[0], : expanded.shape[1]] = expanded
    return field


def render_mission_figures(
    result: MissionResult,
    *,
    figure_format: str = "png",
    dpi: int = DEFAULT_DPI,
    stems: Collection[str] | None = None,
) -> dict[str, RenderedFigure]:
    """The figures of :func:`figure_builders` (those of ``stems``, default all), rendered.

    Raises
    ------
    InputError
        As :func:`render_figure`.
    """
    return {
        stem: render_figure(build(), figure_format=figure_format, dpi=dpi)
        for stem, build in figure_builders(result).items()
        if stems is None or stem in stems
    }


def save_mission_figures(
    result: MissionResult, directory: Path, *, figure_format: str = "png", dpi: int = DEFAULT_DPI
) -> list[Path]:
    """Save :func:`mission_figures` as ``directory/<stem>.<figure_format>``; returns the paths."""
    written = []
    for stem, rendered in render_mission_figures(
        result, figure_format=figure_format, dpi=dpi
    ).items():
        path = directory / f"{stem}.{figure_format}"
        with writing(path):
            path.write_bytes(rendered.data)
        written.append(path)
    return written
