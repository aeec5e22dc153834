"""Reading a finished output folder back as an :class:`~auvplan.export.plan.ExportPlan`.

``auvplan export`` (and ``plan --export``) work from the folder only, never from the run's
memory, so an export made later is the same as one made with the plan. The folder must hold
``summary.json`` (start time, local origin, obstacles, safety radius) and the plan's
trajectories: ``trajectories.nc`` (positions in lat/lon and in the local frame), or, without it,
``trajectories.csv`` (local frame) placed on the globe through the terrain named in the
folder's ``mission.toml``.
"""

from __future__ import annotations

import logging
from datetime import datetime
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import ValidationError

from auvplan.errors import DataFormatError, InputError
from auvplan.export.plan import CircleZone, ExportPlan, PolygonZone, VehicleTrack
from auvplan.io.results import read_trajectories_csv
from auvplan.io.text import read_json, read_toml
from auvplan.io.trajectories_file import read_trajectories_netcdf
from auvplan.mission.config import one_line
from auvplan.mission.tables import NavigationConfig

logger = logging.getLogger(__name__)


def load_export_plan(folder: Path) -> ExportPlan:
    """The optimised plan of an ``auvplan plan`` output folder, ready to export.

    Raises
    ------
    InputError
        If ``folder`` is missing or not a folder, holds no optimised plan (``--stage``
        stopped early or the optimiser failed), or its terrain has no geographic reference
        (the synthetic bank): exports need lat/lon.
    DataFormatError
        If a file of the folder is unreadable or lacks a key.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"output folder {folder} not found (or not a folder)")
    if not (folder / "summary.json").is_file():
        raise InputError(f"{folder} is not an auvplan output folder (no summary.json)")
    summary = read_json(folder / "summary.json", what="summary file")
    try:
        return _plan_from(folder, summary)
    except InputError:
        raise
    except (KeyError, TypeError, ValueError) as error:
        raise DataFormatError(f"{folder}/summary.json: missing or bad entry {error}") from None


def _plan_from(folder: Path, summary: dict[str, Any]) -> ExportPlan:
    netcdf, table = folder / "trajectories.nc", folder / "trajectories.csv"
    if not (netcdf.is_file() or table.is_file()):
        status = summary.get("optimization", {}).get("plan_status")
        reason = f"the optimiser {status}" if status else f"--stage {summary.get('stage')}"
        raise InputError(f"{folder} holds no optimised plan ({reason}); nothing to export")
    origin = summary["terrain"]["origin"]
    if "lat" not in origin:
        raise InputError(
            f"the plan in {folder} is on terrain without geographic reference "
            f"({summary['terrain']['name']}); exports need lat/lon: plan on a georeferenced grid"
        )
    status = summary["optimization"]["plan_status"]
    if status != "CONVERGED":
        logger.warning(
            "the plan in %s is %s (see summary.json): check it before a vehicle flies it",
            folder, status,
        )  # fmt: skip
    start_time = datetime.fromisoformat(summary["start_time"])
    tracks, depth = _tracks_netcdf(netcdf, start_time) if netcdf.is_file() else _tracks_csv(folder)
    return ExportPlan(
        tracks=tracks,
        start_time=start_time,
        depth=depth,
        origin_lat=float(origin["lat"]),
        origin_lon=float(origin["lon"]),
        capture_radius=float(summary["fleet"]["safety_radius_m"]),
        zones=tuple(_zone(obstacle) for obstacle in summary["obstacles"]),
    )


def _tracks_netcdf(path: Path, start_time: datetime) -> tuple[tuple[VehicleTrack, ...], float]:
    dataset = read_trajectories_netcdf(path)
    if "lat" not in dataset.variables:
        raise DataFormatError(f"{path}: no lat/lon")
    epoch = np.datetime64(start_time.replace(tzinfo=None), "ns")
    seconds = (dataset["time"].values - epoch) / np.timedelta64(1, "s")
    tracks = tuple(
        VehicleTrack(
            name=str(name),
            time=seconds[i],
            north=dataset["north"].values[i],
            east=dataset["east"].values[i],
            lat=dataset["lat"].values[i],
            lon=dataset["lon"].values[i],
        )
        for i, name in enumerate(dataset["trajectory"].values)
    )
    return tracks, float(dataset["depth"].values.flat[0])


def _tracks_csv(folder: Path) -> tuple[tuple[VehicleTrack, ...], float]:
    from auvplan.mission.config import load_mission
    from auvplan.mission.preplan import load_terrain

    if not (folder / "mission.toml").is_file():
        raise InputError(f"{folder} has trajectories.csv but no mission.toml to place it")
    config = load_mission(folder / "mission.toml")
    projection = load_terrain(config.terrain).projection
    if projection is None:
        raise DataFormatError(f"{folder}/mission.toml: its terrain has no geographic reference")
    tracks = []
    for name, columns in read_trajectories_csv(folder / "trajectories.csv").items():
        lat, lon = projection.to_geographic(columns["north"], columns["east"])
        tracks.append(VehicleTrack(name, columns["t"], columns["north"], columns["east"], lat, lon))
    return tuple(tracks), config.mission.depth


def _zone(obstacle: dict[str, Any]) -> CircleZone | PolygonZone:
    """A keep-out zone from an ``obstacles`` entry of ``summary.json``."""
    if obstacle["shape"] == "circle":
        center = obstacle["center"]
        return CircleZone(
            obstacle["name"], float(center["lat"]), float(center["lon"]), obstacle["radius_m"]
        )
    vertices = obstacle["vertices"]
    return PolygonZone(
        obstacle["name"],
        np.array([vertex["lat"] for vertex in vertices], dtype=np.float64),
        np.array([vertex["lon"] for vertex in vertices], dtype=np.float64),
    )


__all__ = ["load_export_plan"]


def folder_navigation(
    folder: Path | None, overrides: dict[str, Any]
) -> tuple[NavigationConfig, float]:
    """The ``[navigation]`` table the folder's plan was made with, and the plan's depth [m].

    Read from the folder's ``mission.toml`` (defaults without a folder or when it has no
    ``mission.toml``), with ``overrides`` (TOML keys of the table, e.g.
    ``{"drift_percent": 0.5}``) on top, so that ``auvplan evaluate`` flies the navigation the
    planner predicted.

    Raises
    ------
    InputError
        If a value (of the file or an override) is out of its range; the message names it.
    DataFormatError
        If ``mission.toml`` is not valid TOML.
    """
    path = None if folder is None else folder / "mission.toml"
    document = read_toml(path, what="mission file") if path and path.is_file() else {}
    table = document.get("navigation", {})
    execution = document.get("mission", {})
    depth = execution.get("depth_m", 0.0) if isinstance(execution, dict) else 0.0
    try:
        config = NavigationConfig.model_validate(
            {**(table if isinstance(table, dict) else {}), **overrides}
        )
    except ValidationError as error:
        raise InputError(one_line(error, within=("navigation",))) from None
    return config, float(depth) if isinstance(depth, int | float) else 0.0
