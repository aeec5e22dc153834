"""All figures of a mission run, saved as PNG files."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from auvplan.mission.pipeline import MissionResult
from auvplan.planning import CircleObstacle, PolygonObstacle
from auvplan.vehicle import positions
from auvplan.viz.coordination import plot_coordination_space
from auvplan.viz.maps import plot_terrain_maps
from auvplan.viz.mission import plot_mission_paths, plot_separation, plot_time_series


def mission_figures(result: MissionResult) -> dict[str, Figure]:
    """The figures of a run, by file stem.

    ``maps`` (paper Fig. 5), ``paths`` (Fig. 6 over the bathymetry), ``paths_cost`` (over the
    cost map), and by stage ``coordination``, ``time_series`` (speeds, propellers, power),
    ``separation`` and, with the comparison, ``paths_energy_only``.
    """
    preplan = result.preplan
    config = result.config
    circles = np.array(
        [(o.north, o.east, o.radius) for o in preplan.obstacles if isinstance(o, CircleObstacle)]
    ).reshape(-1, 3)
    polygons = [o.vertices for o in preplan.obstacles if isinstance(o, PolygonObstacle)]
    planned = [route.points for route in preplan.routes]
    stage2 = result.deconfliction
    optimized = None if result.plan is None else _tracks(result, result.plan.states)
    radius = config.fleet.safety_radius
    figures: dict[str, Figure] = {"maps": plot_terrain_maps(preplan.maps)}
    figures["paths"] = plot_mission_paths(
        preplan.bathymetry, preplan.names, planned, optimized, safety_radius=radius,
        circles=circles, polygons=polygons,
    )  # fmt: skip
    cost_on_grid = _cost_on_bathymetry_grid(result)
    figures["paths_cost"] = plot_mission_paths(
        preplan.bathymetry, preplan.names, planned, optimized, safety_radius=radius,
        circles=circles, polygons=polygons, background=cost_on_grid,
        background_label="shifted cost ω + w·M_C", cmap="magma",
        title="Pre-planned paths over the cost map",
    )  # fmt: skip
    if result.energy_only is not None:
        figures["paths_energy_only"] = plot_mission_paths(
            preplan.bathymetry, preplan.names, planned,
            _tracks(result, result.energy_only.states), safety_radius=radius,
            circles=circles, polygons=polygons,
            title="Energy-only optimum (terrain weight 0) against the pre-planned paths",
        )  # fmt: skip
    if stage2 is not None and len(preplan.names) >= 2:
        figures["coordination"] = plot_coordination_space(
            stage2.problem, stage2.coordination, pair=(0, 1)
        )
    if result.plan is not None and stage2 is not None:
        figures["time_series"] = plot_time_series(
            stage2.time, preplan.names, result.plan.states, result.plan.power
        )
        if result.plan.fine_distances:
            figures["separation"] = plot_separation(
                result.plan.fine_time, result.plan.fine_distances, 2 * radius
            )
    return figures


def _tracks(result: MissionResult, states: np.ndarray) -> list[np.ndarray]:
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


def save_mission_figures(result: MissionResult, directory: Path) -> list[Path]:
    """Save :func:`mission_figures` as ``directory/<stem>.png``; returns the paths."""
    written = []
    for stem, figure in mission_figures(result).items():
        path = directory / f"{stem}.png"
        figure.savefig(path, dpi=120)
        written.append(path)
    return written
