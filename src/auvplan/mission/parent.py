"""The plan a replan continues: its first two stages and its optimised trajectories.

A plan made in this session (:func:`parent_from_result`) holds them already. A plan read from
its output folder (:func:`parent_from_record`) has its mission (``mission.toml``, every
default filled in) planned again up to stage 2, which gives the same maps, paths and time laws
as its own run; the maps, the pre-planned paths and the time grid are checked against the
folder's, so a terrain file that changed since is refused rather than replanned on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.mission.config import MissionConfig, parse_mission
from auvplan.mission.pipeline import MissionResult, fleet_layout, timed_stage
from auvplan.mission.preplan import PreplanStage, run_preplan
from auvplan.mission.progress import ProgressReporter, no_progress, with_checkpoints
from auvplan.mission.timing import DeconflictStage, run_deconfliction
from auvplan.record import PlanRecord
from auvplan.record.files import MAIN_PLAN, MISSION_FILE, PLAN_FILES
from auvplan.terrain import TerrainMaps

#: The terrain maps compared by :func:`same_maps` (besides the depth).
MAP_NAMES = ("information", "excitation", "cost", "shifted_cost")


@dataclass(frozen=True)
class ParentPlan:
    """A plan to replan (module notes).

    ``states[i]`` ``(n_t, n_x_i)`` and ``inputs[i]`` ``(n_t - 1, n_u_i)`` are vehicle ``i``'s
    optimised trajectory on ``deconfliction.time``; ``folder`` is the output folder it was
    read from (None: planned in memory), ``digest`` the SHA-256 of its ``trajectories.csv``,
    ``delta`` the barrier's final switching point ``δ`` (None: unknown) and ``timings`` the
    wall seconds [s] of planning its mission again, by stage.
    """

    config: MissionConfig
    preplan: PreplanStage
    deconfliction: DeconflictStage
    states: tuple[FloatArray, ...]
    inputs: tuple[FloatArray, ...]
    folder: str | None
    digest: str | None
    delta: float | None = None
    timings: dict[str, float] = field(default_factory=dict)


def parent_from_result(result: MissionResult, *, digest: str | None) -> ParentPlan:
    """The parent of a plan made in this session (``digest``: its ``trajectories.csv``'s).

    Raises
    ------
    InputError
        If the run has no optimised plan.
    """
    if result.plan is None or result.deconfliction is None:
        raise InputError(f"nothing to replan: {result.problem or 'the run stopped early'}")
    return ParentPlan(
        result.config, result.preplan, result.deconfliction, result.plan.states,
        result.plan.inputs, None, digest, result.plan.result.delta,
    )  # fmt: skip


def record_mission(record: PlanRecord, *, folder: str | None) -> MissionConfig:
    """The mission of a plan read from ``folder`` (its ``mission.toml``), to replan it.

    Raises
    ------
    InputError
        If the folder holds no optimised plan, no ``mission.toml`` or an invalid one.
    """
    where = folder or "the plan"
    if not record.has_plan:
        raise InputError(f"nothing to replan in {where}: it holds no optimised plan")
    if not record.mission:
        raise InputError(f"cannot replan {where}: it has no {MISSION_FILE}")
    return parse_mission(record.mission, base_dir=Path(folder or "."))


def parent_from_record(
    record: PlanRecord,
    config: MissionConfig,
    *,
    folder: str | None,
    progress: ProgressReporter = no_progress,
) -> ParentPlan:
    """The parent of a plan read from ``folder``: its mission ``config`` planned again.

    ``config`` is :func:`record_mission` of the record; ``progress`` is told of the stages
    ``preplan`` and ``deconflict``.

    Raises
    ------
    DataFormatError
        If the mission planned again does not give the folder's maps, vehicles or time grid.
    """
    where = folder or "the plan"
    progress = with_checkpoints(progress)
    timings: dict[str, float] = {}
    preplan = timed_stage(
        progress, timings, "preplan", lambda: run_preplan(config, progress=progress)
    )
    if not same_maps(record.maps, preplan.maps):
        raise DataFormatError(
            f"the terrain of {where}/{MISSION_FILE} is no longer the one its plan was made on: "
            "plan the mission again"
        )
    for vehicle, route in zip(record.summary.vehicles, preplan.routes, strict=True):
        points = np.asarray(vehicle.preplan.get("points_north_east_m", []), dtype=np.float64)
        if points.shape != np.shape(route.points) or not np.allclose(points, route.points):
            raise DataFormatError(
                f"{where}: vehicle {vehicle.name}'s pre-planned path is not the one its mission "
                "gives now: plan the mission again"
            )
    layout = fleet_layout(config)
    stage2 = timed_stage(
        progress, timings, "deconflict",
        lambda: run_deconfliction(
            layout, preplan.paths, preplan.starts[:, 2], preplan.goals[:, 2], fleet=config.fleet,
            settings=config.deconfliction, dt=config.solver.dt, current=preplan.current,
        ),
    )  # fmt: skip
    tables = record.plans[MAIN_PLAN]
    for table, model in zip(tables, layout.models, strict=True):
        if table.state_names != model.state_names or table.input_names != model.input_names:
            raise DataFormatError(
                f"{where}: vehicle {table.name}'s columns are not those of its type now "
                f"({', '.join(model.state_names)}): plan the mission again"
            )
    time = tables[0].time
    if time.shape != stage2.time.shape or not np.allclose(time, stage2.time, atol=1e-6):
        raise DataFormatError(
            f"{where}/{PLAN_FILES[MAIN_PLAN].csv}: its time grid is not the one its mission "
            "gives now: plan the mission again"
        )
    return ParentPlan(
        config, preplan, stage2, tuple(table.states for table in tables),
        tuple(table.inputs for table in tables), folder,
        (record.summary.digest or {}).get(PLAN_FILES[MAIN_PLAN].csv), _final_delta(record),
        timings,
    )  # fmt: skip


def same_maps(a: TerrainMaps, b: TerrainMaps) -> bool:
    """Whether two sets of terrain maps hold the same arrays, up to round-off (1e-9 relative).

    The maps of a mission planned again from its folder (the bathymetry read back from
    ``maps.nc``) differ from the folder's in the last bits only.
    """
    pairs = [(a.bathymetry.depth, b.bathymetry.depth)]
    pairs += [(getattr(a, name), getattr(b, name)) for name in MAP_NAMES]
    return all(
        x.shape == y.shape and np.allclose(x, y, rtol=1e-9, atol=1e-12, equal_nan=True)
        for x, y in pairs
    )


def _final_delta(record: PlanRecord) -> float | None:
    """The barrier's ``δ`` at the plan's last iteration (``summary.json``'s history)."""
    outcome = record.summary.optimization
    history = [] if outcome is None or outcome.history is None else outcome.history
    last = history[-1] if history else None
    delta = last.get("delta") if isinstance(last, dict) else None
    return float(delta) if isinstance(delta, int | float) and math.isfinite(delta) else None


__all__ = [
    "MAP_NAMES",
    "ParentPlan",
    "parent_from_record",
    "parent_from_result",
    "record_mission",
    "same_maps",
]
