"""``summary.json``: every number needed to verify a plan without rerunning it (SPEC §8)."""

from __future__ import annotations

import dataclasses
import platform
import re
from collections.abc import Sequence
from datetime import UTC, datetime
from enum import Enum
from importlib import metadata
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Any, Final

import numpy as np

from auvplan._version import __version__
from auvplan.io.results import json_values
from auvplan.io.text import file_sha256
from auvplan.io.vehicles import vehicle_file
from auvplan.mission.assembly import integration_substeps
from auvplan.mission.config import CurrentConfig, MissionConfig
from auvplan.mission.evaluation import CHECK_REFINEMENT, OptimizedPlan
from auvplan.mission.pipeline import MissionResult
from auvplan.mission.preplan import PreplanStage
from auvplan.mission.still_water import CurrentComparison
from auvplan.navigation.prediction import ErrorPrediction
from auvplan.planning import CircleObstacle, OperatingArea, path_length
from auvplan.record import PlanSummary, parse_summary
from auvplan.terrain import LocalProjection
from auvplan.vehicle import positions, top_speed


def _record(record: Any) -> Any:
    """A per-iteration history record as plain JSON values (enums by name)."""
    if dataclasses.is_dataclass(record) and not isinstance(record, type):
        return {
            key: (value.name if isinstance(value, Enum) else value)
            for key, value in dataclasses.asdict(record).items()
        }
    return record


def _predicted(prediction: ErrorPrediction, settle_s: float) -> dict[str, float]:
    """A vehicle's predicted TAN error along its flown track [m] (the evaluator's model)."""
    return {
        "rms_m": prediction.rms,
        "peak_after_settle_m": prediction.peak_after(settle_s),
        "final_m": float(prediction.sigma[-1]),
    }


def _battery(energy: float, capacity: float | None) -> dict[str, float | None]:
    """What a plan of ``energy`` [J] leaves in a battery of ``capacity`` [J] (None: unknown).

    ``energy_remaining_J`` = ``C − E`` [J], ``energy_remaining_fraction`` = ``(C − E) / C``.
    """
    if capacity is None:
        return {"energy_remaining_J": None, "energy_remaining_fraction": None}
    remaining = capacity - energy
    return {"energy_remaining_J": remaining, "energy_remaining_fraction": remaining / capacity}


def _plan_summary(
    plan: OptimizedPlan,
    names: tuple[str, ...],
    settle_s: float,
    capacities: tuple[float | None, ...],
) -> dict[str, Any]:
    """A plan's record; ``capacities`` [J] are the vehicles' batteries (None: unknown)."""
    result = plan.result
    return {
        "terrain_weight": plan.terrain_weight,
        "plan_status": plan.verdict.status.name,
        "verdict": plan.verdict.message,
        "violations": [dataclasses.asdict(violation) for violation in plan.verdict.violations],
        "status": result.status.name,
        "message": result.message,
        "fleet_solve": plan.fleet_solve,
        "n_iter": result.n_iter,
        "cost": result.cost,
        "history": [_record(record) for record in result.history],
        "vehicles": {
            name: {
                "energy_J": float(plan.energy[i]),
                **_battery(float(plan.energy[i]), capacities[i]),
                "mean_terrain_information": float(plan.terrain_information[i]),
                "arrival_error_m": float(plan.arrival_error[i]),
                "tracking_error_m": float(plan.tracking_error[i]),
                "min_separation_m": plan.separations[name],
                "predicted_navigation_error": _predicted(plan.predicted_navigation[i], settle_s),
                "cost_terms_J": {
                    term: float(values[i]) for term, values in plan.costs.running.items()
                },
            }
            for i, name in enumerate(names)
        },
        "total_energy_J": float(np.sum(plan.energy)),
        "cost_terms_J": plan.costs.totals(),
        "constraint_slack": plan.constraint_slack,
    }


def _pose(pose: np.ndarray) -> dict[str, float]:
    return {"north": float(pose[0]), "east": float(pose[1]), "heading_rad": float(pose[2])}


def _place(projection: LocalProjection | None, north: float, east: float) -> dict[str, float]:
    """A local point [m], with its WGS 84 ``lat``/``lon`` [deg] on georeferenced terrain."""
    point = {"north": float(north), "east": float(east)}
    if projection is not None:
        lat, lon = projection.to_geographic(np.array([north]), np.array([east]))
        point.update(lat=float(lat[0]), lon=float(lon[0]))
    return point


def _obstacles(preplan: PreplanStage) -> list[dict[str, Any]]:
    """The obstacles in the map frame (and lat/lon), as the planners saw them.

    A polygon's ``holes`` (free water) and the operating area (``shape = "area"``: the
    region every vehicle stays inside) are listed when the mission has them.
    """
    projection = preplan.bathymetry.projection
    shapes: list[dict[str, Any]] = []
    for name, obstacle in zip(preplan.obstacle_names, preplan.obstacles, strict=True):
        if isinstance(obstacle, CircleObstacle):
            shapes.append(
                {
                    "name": name,
                    "shape": "circle",
                    "center": _place(projection, obstacle.north, obstacle.east),
                    "radius_m": obstacle.radius,
                }
            )
        else:
            area = isinstance(obstacle, OperatingArea)
            polygon = obstacle.region if isinstance(obstacle, OperatingArea) else obstacle
            shape: dict[str, Any] = {
                "name": name,
                "shape": "area" if area else "polygon",
                "vertices": [_place(projection, n, e) for n, e in polygon.vertices],
            }
            if polygon.holes:
                shape["holes"] = [[_place(projection, n, e) for n, e in h] for h in polygon.holes]
            shapes.append(shape)
    return shapes


#: The folders of an absolute POSIX path (``/home/me/data/``), before its last name.
_FOLDERS: Final = re.compile(r"(?<![\w./~-])/(?:[^\s/'\"]+/)+(?=[^\s/'\"])")


def without_folders(message: str) -> str:
    """``message`` with each absolute path cut to its last name (outputs hold no folder).

    Examples
    --------
    >>> without_folders("bathymetry /home/me/data/grid.nc: 3 of 9 values beyond ±12000 m")
    'bathymetry grid.nc: 3 of 9 values beyond ±12000 m'
    >>> without_folders("speed 0.5 m/s, pair blue / green, ./rel/path.csv")
    'speed 0.5 m/s, pair blue / green, ./rel/path.csv'
    """
    return _FOLDERS.sub("", message)


def _fingerprint(path: Path | Traversable) -> dict[str, str]:
    """A file the run read: its name (an output folder holds no absolute path) and SHA-256."""
    return {"path": path.name, "sha256": file_sha256(path)}


#: The distributions whose versions decide a plan's numbers (recorded in ``summary.json``).
NUMERIC_PACKAGES: Final = (
    "numpy", "scipy", "casadi", "numba", "llvmlite", "xarray", "netCDF4", "pyproj", "shapely",
    "pydantic", "rasterio",
)  # fmt: skip


def environment() -> dict[str, Any]:
    """Python, the platform and the versions of :data:`NUMERIC_PACKAGES`.

    What to install to rerun a folder to the same numbers on another machine.
    """
    versions: dict[str, str | None] = {}
    for name in NUMERIC_PACKAGES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = None
    return {
        "python": platform.python_version(),
        "platform": platform.platform(terse=True),
        "packages": versions,
    }


def _inputs(config: MissionConfig, vehicle_types: Sequence[str]) -> dict[str, Any]:
    """Name and SHA-256 of every file the run read: mission, bathymetry, current, vehicles.

    The vehicle files by their ``vehicle_types`` (as the folder's ``mission.toml`` names them);
    ``zones``, the GIS files of ``[[obstacle]]`` and ``[area]``, when the mission has any.
    """
    zones = [obstacle.file for obstacle in config.obstacles if obstacle.file is not None]
    if config.area is not None and config.area.file is not None:
        zones.append(config.area.file)
    return {
        "mission": None if config.source is None else _fingerprint(config.source),
        "bathymetry": None if config.terrain.path is None else _fingerprint(config.terrain.path),
        "current": None
        if config.current is None or config.current.file is None
        else _fingerprint(config.current.file),
        "vehicles": {
            kind: _fingerprint(vehicle_file(vehicle.type))
            for kind, vehicle in zip(vehicle_types, config.vehicles, strict=True)
        },
        **({"zones": [_fingerprint(zone) for zone in zones]} if zones else {}),
    }


def _current(current: CurrentConfig) -> dict[str, Any]:
    """The ``[current]`` table, a file by its name."""
    table: dict[str, Any] = current.model_dump(mode="json", exclude_none=True)
    if current.file is not None:
        table["file"] = current.file.name
    return table


def _max_current(result: MissionResult) -> float:
    """Largest current speed [m/s] along every optimised plan of ``result`` (0: still water)."""
    current = result.preplan.current
    if current is None:
        return 0.0
    fastest = 0.0
    for owner, plan in _plans(result):
        assert owner.deconfliction is not None  # a plan exists only after stage 2
        models = owner.deconfliction.layout.models
        for model, states in zip(models, plan.states, strict=True):
            north, east = positions(model, states).T
            v_north, v_east = current.velocity(north, east, owner.deconfliction.time)
            fastest = max(fastest, float(np.max(np.hypot(v_north, v_east))))
    return fastest


def _plans(result: MissionResult) -> list[tuple[MissionResult, OptimizedPlan]]:
    """Each optimised plan of ``result`` with the run that made it (the paper's plan: its own)."""
    plans = [(result, plan) for plan in (result.plan, result.energy_only) if plan is not None]
    if result.paper is not None and result.paper.plan is not None:
        plans.append((result.paper, result.paper.plan))
    return plans


def mission_summary(
    result: MissionResult, *, vehicle_types: Sequence[str], warnings: Sequence[str] = ()
) -> PlanSummary:
    """Build the ``summary.json`` document of a mission run (without its ``digest``).

    ``vehicle_types`` are the vehicles' ``type`` as the output folder's ``mission.toml``
    names them (a packaged type or a carried file, :mod:`auvplan.mission.carry`): no path
    outside the folder. ``warnings`` are the warnings logged during the run (one line each),
    kept under ``"warnings"`` with each absolute path cut to its file name
    (:func:`without_folders`).
    """
    config = result.config
    preplan = result.preplan
    settle_s = config.navigation.settle
    maps = preplan.maps
    grid = preplan.bathymetry.geometry
    stage2 = result.deconfliction
    method = config.deconfliction.method if stage2 is None else stage2.coordination.method
    summary: dict[str, Any] = {
        "auvplan_version": __version__,
        "created": datetime.now(UTC).isoformat(timespec="seconds"),
        "environment": environment(),
        "mission": None if config.source is None else config.source.name,
        "inputs": _inputs(config, vehicle_types),
        "start_time": config.mission.start_time.isoformat(),
        "stage": result.stage.value,
        "terrain": {
            "name": preplan.bathymetry.name,
            "shape": list(grid.shape),
            "spacing_m": [grid.spacing_north, grid.spacing_east],
            "cost_grid_shape": list(maps.cost_geometry.shape),
            "cost_grid_spacing_m": [
                maps.cost_geometry.spacing_north,
                maps.cost_geometry.spacing_east,
            ],
            "map_parameters": dataclasses.asdict(maps.parameters),
            "origin": _place(preplan.bathymetry.projection, 0.0, 0.0),
        },
        "obstacles": _obstacles(preplan),
        "current": None if config.current is None else _current(config.current),
        "fleet": {
            "safety_radius_m": config.fleet.safety_radius,
            "edge_model": config.planner.edge_model,
            "deconfliction_method": str(method),
        },
        # the settings by field name, "full" propeller order as null (keys users already read)
        "solver": {**config.solver.model_dump(), "propeller_order": config.solver.harmonics},
        "vehicles": [],
        "wall_time_s": dict(result.timings),
        "warnings": [without_folders(line) for line in warnings],
    }
    for i, name in enumerate(preplan.names):
        route = preplan.routes[i]
        vehicle: dict[str, Any] = {
            "name": name,
            "type": vehicle_types[i],
            "start": _pose(preplan.starts[i]),
            "goal": _pose(preplan.goals[i]),
            "preplan": {
                "cells": route.cells,
                "graph_cost": route.cost,
                "n_expanded": route.n_expanded,
                "points_north_east_m": route.points,
                "smoothed_length_m": path_length(preplan.paths[i]),
            },
        }
        if preplan.navigation is not None:
            vehicle["preplan"]["navigation"] = preplan.navigation[i].document()
        summary["vehicles"].append(vehicle)
    if stage2 is not None:
        coordination = stage2.coordination
        n_substeps = integration_substeps(stage2.layout, stage2.dt)
        summary["fleet"]["max_current_m_s"] = _max_current(result)
        summary["deconfliction"] = {
            "horizon_s": stage2.horizon,
            "integration": {"n_substeps": n_substeps, "substep_s": stage2.dt / n_substeps},
            "status": coordination.status.name,
            "message": coordination.message,
            "objective": coordination.objective,
            "n_expanded": coordination.n_expanded,
            "method": str(coordination.method),
            "weight": coordination.weight,
            "fallback": coordination.fallback,
            "within_speed_limits": list(coordination.within_limits),
            "certified_min_separation_m": coordination.certificate.min_separation,
            "certificate": dataclasses.asdict(coordination.certificate),
        }
        models = stage2.layout.models
        for i, (vehicle, model) in enumerate(zip(summary["vehicles"], models, strict=True)):
            vehicle["timing"] = {
                "nominal_speed_m_s": stage2.cruise_speeds[i],
                "arrival_time_s": coordination.arrival_times[i],
                "delay_s": coordination.delays[i],
                "time_law": {
                    "t_s": coordination.time,
                    "progress_m": coordination.progress[i],
                    "speed_m_s": None if coordination.speeds is None else coordination.speeds[i],
                },
            }
            vehicle.update(
                type_name=model.vehicle.name,
                state_names=model.state_names,
                input_names=model.input_names,
                top_speed_m_s=top_speed(model),
                battery_capacity_J=model.vehicle.battery_capacity,
            )
    if result.failure is not None:
        summary["optimization"] = {"plan_status": "FAILED", "verdict": result.failure}
    capacities = (
        () if stage2 is None else tuple(m.vehicle.battery_capacity for m in stage2.layout.models)
    )
    if result.plan is not None:
        summary["optimization"] = _plan_summary(result.plan, preplan.names, settle_s, capacities)
    if result.energy_only is not None:
        summary["energy_only"] = _plan_summary(
            result.energy_only, preplan.names, settle_s, capacities
        )
    if result.paper is not None and result.paper.plan is not None:
        summary["paper"] = {
            **_plan_summary(result.paper.plan, preplan.names, settle_s, capacities),
            "edge_model": result.paper.config.planner.edge_model,
            "smoothed_length_m": {
                name: path_length(path)
                for name, path in zip(preplan.names, result.paper.preplan.paths, strict=True)
            },
        }
    if result.current_comparison is not None:
        summary["current_comparison"] = _comparison_summary(
            result.current_comparison, preplan.names, settle_s, capacities
        )
    return parse_summary(json_values(summary), source="the run's summary")


def _comparison_summary(
    comparison: CurrentComparison,
    names: tuple[str, ...],
    settle_s: float,
    capacities: tuple[float | None, ...],
) -> dict[str, Any]:
    """``--compare-no-current``: both plans flown in the current (:mod:`.still_water`)."""
    using, still = comparison.using_current, comparison.still_water
    total_using, total_still = float(np.sum(using.energy)), float(np.sum(still.energy))
    return {
        "method": "both plans flown in the current with their own tracking regulators "
        f"(RK4, {CHECK_REFINEMENT} substeps per solver step); energy = trapezoidal ∫ P dt",
        "total_energy_using_current_J": total_using,
        "total_energy_still_water_plan_J": total_still,
        "saving_J": comparison.saving,
        "saving_percent": 100.0 * comparison.saving / total_still if total_still > 0 else 0.0,
        "still_water_plan": _plan_summary(comparison.still_water_plan, names, settle_s, capacities),
        "vehicles": {
            name: {
                "energy_using_current_J": float(using.energy[i]),
                "energy_still_water_plan_J": float(still.energy[i]),
                "arrival_error_using_current_m": float(using.arrival_error[i]),
                "arrival_error_still_water_plan_m": float(still.arrival_error[i]),
            }
            for i, name in enumerate(names)
        },
    }
