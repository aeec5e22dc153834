"""The plan a replan continues: its first two stages and its optimised trajectories.

A plan made in this session (:func:`parent_from_result`) holds them already. A plan read from
its output folder (:func:`parent_from_record`) has its mission (``mission.toml``, every
default filled in) pre-planned again (stage 1), which gives the same maps and paths as its own
run, and its stage-2 schedule read from ``summary.json`` (:func:`recorded_deconfliction`: the
time laws, their speeds and the schedule's outcome as written, the desired states sampled from
them as stage 2 samples them); a folder whose ``summary.json`` does not hold the laws' speeds
(written before they were) has stage 2 planned again. The maps, the pre-planned paths, the
time laws' path lengths and the time grid are checked against the folder's, so a terrain file
that changed since is refused rather than replanned on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from auvplan._typing import FloatArray
from auvplan.deconfliction import (
    CoordinationResult,
    CoordinationStatus,
    DeconflictionMethod,
    SeparationCertificate,
)
from auvplan.errors import DataFormatError, InputError
from auvplan.mission.config import MissionConfig, parse_mission
from auvplan.mission.fleet import FleetLayout
from auvplan.mission.pipeline import MissionResult, fleet_layout, timed_stage
from auvplan.mission.preplan import PreplanStage, run_preplan
from auvplan.mission.progress import ProgressReporter, no_progress, with_checkpoints
from auvplan.mission.timing import (
    DeconflictStage,
    coordination_problem,
    run_deconfliction,
    sampled_stage,
    speed_range,
)
from auvplan.planning import path_length
from auvplan.record import PlanRecord
from auvplan.record.files import MAIN_PLAN, MISSION_FILE, PLAN_FILES, SUMMARY_FILE
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
        lambda: recorded_deconfliction(record, config, layout, preplan, where=where)
        or run_deconfliction(
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


def recorded_deconfliction(
    record: PlanRecord,
    config: MissionConfig,
    layout: FleetLayout,
    preplan: PreplanStage,
    *,
    where: str,
) -> DeconflictStage | None:
    """Stage 2 of the plan of folder ``where`` as its ``summary.json`` records it.

    The coordination problem is that of :func:`~auvplan.mission.timing.run_deconfliction`
    on the paths ``preplan`` gives again at the recorded nominal speeds [m/s]; the schedule
    (time grid [s], progress [m] and speeds [m/s] of each time law, arrival times and delays
    [s], certificate, status, method, weight, message) is the one written, whose JSON
    numbers read back to the same floats; the desired states are sampled from it on the
    solver grid (:func:`~auvplan.mission.timing.sampled_stage`). None when the time laws
    have no ``speed_m_s`` (a folder written before they had).

    Raises
    ------
    DataFormatError
        If the time laws do not have one sample per time, or do not end at the lengths of
        the paths planned again.
    """
    document = record.summary.deconfliction
    timings = [vehicle.timing or {} for vehicle in record.summary.vehicles]
    if document is None or any("speed_m_s" not in t.get("time_law", {}) for t in timings):
        return None
    laws = [t["time_law"] for t in timings]
    time = np.asarray(laws[0]["t_s"], dtype=np.float64)
    lengths = np.array([path_length(path) for path in preplan.paths])
    speeds = [law["speed_m_s"] for law in laws]
    samples = {len(law["progress_m"]) for law in laws} | {len(v) for v in speeds if v is not None}
    stale = DataFormatError(
        f"{where}/{SUMMARY_FILE}: its time laws are not those of the paths its mission gives "
        "now: plan the mission again"
    )
    if time.size < 2 or samples != {time.size} or len({v is None for v in speeds}) != 1:
        raise stale
    progress = np.array([law["progress_m"] for law in laws], dtype=np.float64)
    if not np.allclose(progress[:, -1], lengths, rtol=1e-9, atol=1e-9):
        raise stale
    _, slowest, _ = speed_range(
        layout, preplan.paths, lengths, fleet=config.fleet, current=preplan.current
    )
    nominal = np.array([t["nominal_speed_m_s"] for t in timings], dtype=np.float64)
    problem = coordination_problem(
        layout, preplan.paths, nominal, slowest, fleet=config.fleet,
        settings=config.deconfliction,
    )  # fmt: skip
    certificate = document["certificate"]
    coordination = CoordinationResult(
        status=CoordinationStatus[document["status"]],
        message=document["message"],
        method=DeconflictionMethod(document["method"]),
        weight=math.nan if document["weight"] is None else float(document["weight"]),
        time=time,
        progress=progress,
        arrival_times=np.array([t["arrival_time_s"] for t in timings], dtype=np.float64),
        delays=np.array([t["delay_s"] for t in timings], dtype=np.float64),
        certificate=SeparationCertificate(**{**certificate, "pair": tuple(certificate["pair"])}),
        n_expanded=int(document["n_expanded"]),
        objective=(float(document["objective"][0]), float(document["objective"][1])),
        fallback=document["fallback"],
        speeds=None if speeds[0] is None else np.array(speeds, dtype=np.float64),
        within_limits=tuple(document["within_speed_limits"]),
    )
    ends = (preplan.starts[:, 2], preplan.goals[:, 2])
    return sampled_stage(
        layout, problem, coordination, float(document["horizon_s"]), config.solver.dt, ends,
        preplan.current,
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
    "recorded_deconfliction",
    "same_maps",
]
