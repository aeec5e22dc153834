"""Replanning (issue 27): the rest of a plan from time ``at``, from where the vehicles are.

A plan of horizon ``T`` is replanned at ``0 < at < T`` (a multiple of ``solver.dt_s``) from
new initial states: each vehicle given a state (:mod:`auvplan.mission.states`) starts in steady
straight motion at that pose and surge speed; the others start in the full state their plan
has at ``at``. The goals, the horizon's end (the new horizon is ``T - at``), the constraints
and the weights are kept; the new plan's ``t = 0`` is the old plan's ``t = at`` (its
``start_time`` moves by ``at``, and a time-varying current is read ``at`` later).

1. Each vehicle must still reach its goal: the remainder of its path
   (:mod:`auvplan.mission.remainder`) no longer than its top speed times ``T - at``;
   otherwise the run fails naming it (no plan, exit 3).
2. The old schedule, shifted by ``at`` and led in from the new starts, is kept when its
   continuous separation certificate still holds: the desired trajectories are then the old
   ones from ``at``, and PRONTO starts from the old optimised trajectory from ``at`` one
   barrier level above the last, at the old plan's ``δ`` (its projection from the new
   initial states is the first iterate; :func:`auvplan.mission.pipeline.run_optimization`
   says why); should that not give a plan that meets every constraint, PRONTO
   starts again from the desired trajectories with the full barrier continuation.
   Otherwise the remainder paths are deconflicted anew over ``T - at`` as stage 2 does
   (:func:`auvplan.mission.timing.run_deconfliction`) and PRONTO starts from the new desired
   trajectories with the full barrier continuation.
3. The plan is evaluated and judged like any plan (:func:`auvplan.mission.evaluation.
   evaluate_plan`); its record is a normal output folder whose ``summary.json`` adds
   ``replan`` (:func:`replan_record`).

With states taken from the old plan at ``at``, the new problem is the old one's tail, so its
optimum is the old plan's remainder (Bellman's principle of optimality).
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from datetime import timedelta
from pathlib import Path
from typing import Any

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InfeasibleError, InputError, SolverError
from auvplan.mission.assembly import WarmStart
from auvplan.mission.config import MissionConfig
from auvplan.mission.evaluation import OptimizedPlan
from auvplan.mission.outputs import plan_record
from auvplan.mission.parent import ParentPlan
from auvplan.mission.pipeline import MissionResult, Stage, run_optimization, timed_stage
from auvplan.mission.progress import ProgressReporter, no_progress, with_checkpoints
from auvplan.mission.remainder import Remainder, shift_schedule
from auvplan.mission.tables import StartPose
from auvplan.mission.timing import (
    SPEED_MARGIN,
    DeconflictStage,
    desired_states,
    run_deconfliction,
)
from auvplan.mission.zones import resolve_position
from auvplan.ocean import CurrentField
from auvplan.optimization import Trajectory
from auvplan.planning import path_length
from auvplan.record import PlanRecord, parse_summary
from auvplan.vehicle import headings, positions, reference_states, top_speed


@dataclass(frozen=True)
class ReplanOrigin:
    """The plan a replan continues (``summary.json``'s ``replan``).

    ``parent`` is its output folder (None: planned in memory; ``summary.json`` keeps its name
    only, no path: folders travel), ``parent_digest`` the SHA-256
    of its ``trajectories.csv``, ``at`` [s] the time of the parent plan that is the new
    plan's ``t = 0``; ``schedule`` is ``"kept"`` when the parent's time laws, shifted, are
    still certified for the new starts, ``"deconflicted"`` when they were planned again.
    """

    parent: str | None
    parent_digest: str | None
    at: float
    schedule: str

    def document(self) -> dict[str, Any]:
        """The ``replan`` entry of ``summary.json``."""
        return {
            "parent": None if self.parent is None else Path(self.parent).name,
            "parent_digest": self.parent_digest,
            "at_s": self.at,
            "schedule": self.schedule,
        }


@dataclass(frozen=True)
class Replan:
    """A replan's run (``result.problem``: why it is not a usable plan) and its origin."""

    result: MissionResult
    origin: ReplanOrigin


@dataclass(frozen=True)
class NewStarts:
    """The vehicles at the replanning time.

    ``poses`` ``(n_vehicles, 3)``: north, east [m], psi [rad] (unwrapped next to the old
    plan's heading); ``speeds`` ``(n_vehicles,)`` surge [m/s]; ``state`` ``(n_x,)`` the
    stacked initial state.
    """

    poses: FloatArray
    speeds: FloatArray
    state: FloatArray


@dataclass(frozen=True)
class ShiftedCurrent:
    """A current field read ``offset`` [s] later: ``v_c(n, e, t + offset)``."""

    field: CurrentField
    offset: float

    def velocity(
        self, north: FloatArray, east: FloatArray, time: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """``(v_N, v_E)`` [m/s] of the field at ``time + offset``."""
        return self.field.velocity(north, east, np.asarray(time) + self.offset)

    def gradient(self, north: FloatArray, east: FloatArray, time: FloatArray) -> FloatArray:
        """Spatial Jacobian [1/s] of the field at ``time + offset``."""
        return self.field.gradient(north, east, np.asarray(time) + self.offset)


def replan_step(at: float, horizon: float, dt: float) -> int:
    """The solver step ``k = at / dt`` of the replanning time ``at`` [s].

    Raises
    ------
    InputError
        Unless ``0 < at < horizon`` and ``at`` is a multiple of ``dt``.
    """
    if not (math.isfinite(at) and 0.0 < at < horizon):
        raise InputError(
            f"--at = {at:g} s must lie strictly between 0 and the horizon {horizon:g} s"
        )
    step = round(at / dt)
    if not math.isclose(step * dt, at, rel_tol=1e-9, abs_tol=1e-9):
        raise InputError(f"--at = {at:g} s is not a multiple of the plan's solver.dt_s = {dt:g} s")
    return step


def new_starts(parent: ParentPlan, step: int, states: Mapping[str, StartPose]) -> NewStarts:
    """Each vehicle's pose, speed and state at solver step ``step`` (module notes).

    Raises
    ------
    InputError
        If a vehicle is not in the plan, a state is off the map or faster than its vehicle's
        top speed.
    """
    layout = parent.deconfliction.layout
    unknown = sorted(set(states) - set(layout.names))
    if unknown:
        raise InputError(f"no vehicle named {unknown[0]!r} in the plan ({', '.join(layout.names)})")
    grid = parent.preplan.bathymetry.geometry
    poses, speeds, blocks = [], [], []
    for i, (name, model) in enumerate(zip(layout.names, layout.models, strict=True)):
        old = parent.states[i][step]
        given = states.get(name)
        if given is None:
            poses.append(np.array([*positions(model, old), headings(model, old)]))
            speeds.append(float(old[model.index("u")]))
            blocks.append(old)
            continue
        north, east = resolve_position(given, parent.preplan.bathymetry, f"vehicle {name} state")
        if not grid.contains(np.array(north), np.array(east)):
            raise InputError(f"vehicle {name} state ({north:g}, {east:g}) m is outside the map")
        fastest = top_speed(model)
        if given.speed > fastest:
            raise InputError(
                f"vehicle {name} speed = {given.speed:g} m/s exceeds its top speed "
                f"{fastest:.2f} m/s"
            )
        psi = given.psi + 2 * np.pi * np.round((headings(model, old) - given.psi) / (2 * np.pi))
        pose = np.array([north, east, psi])
        poses.append(pose)
        speeds.append(given.speed)
        blocks.append(reference_states(model, pose[None], np.array([given.speed]), np.zeros(1))[0])
    return NewStarts(np.array(poses), np.array(speeds), np.concatenate(blocks))


def continued_mission(
    config: MissionConfig, starts: NewStarts, at: float, remaining: float
) -> MissionConfig:
    """The mission of the rest: new starts, horizon ``remaining`` [s], start ``at`` [s] later.

    Planning it from scratch (``auvplan plan``) plans the same rest anew (``remaining`` is
    ``T - at`` with ``T`` the parent's horizon, given or derived from its cruise speed).
    """
    vehicles = tuple(
        vehicle.model_copy(
            update={
                "start": StartPose(
                    north=float(pose[0]),
                    east=float(pose[1]),
                    heading_deg=math.degrees(math.remainder(float(pose[2]), 2 * math.pi)),
                    speed=float(np.clip(speed, 0.0, 10.0)),
                )
            }
        )
        for vehicle, pose, speed in zip(config.vehicles, starts.poses, starts.speeds, strict=True)
    )
    fleet = config.fleet.model_copy(update={"horizon": remaining, "cruise_speed": None})
    return config.model_copy(
        update={
            "vehicles": vehicles,
            "fleet": fleet,
            "mission": config.mission.model_copy(
                update={"start_time": config.mission.start_time + timedelta(seconds=at)}
            ),
            "source": None,
        }
    )


def replan_mission(
    parent: ParentPlan,
    at: float,
    states: Mapping[str, StartPose],
    *,
    callback: Callable[[Any], None] | None = None,
    progress: ProgressReporter = no_progress,
    jobs: int = 1,
) -> Replan:
    """Replan ``parent`` at ``at`` [s] from ``states`` (vehicle -> state; module notes).

    ``callback``, ``progress`` and ``jobs`` as for :func:`auvplan.mission.run_mission`. The
    timings [s] are ``parent_preplan`` and ``parent_deconflict`` (a parent read from a
    folder: its mission pre-planned again, its schedule read back), ``schedule`` (the
    shifted schedule and its certificate), ``deconflict`` (when the certificate fails) and
    ``optimize``.

    Raises
    ------
    InputError
        For a bad ``at`` (:func:`replan_step`) or state (:func:`new_starts`).
    """
    config, preplan, stage2 = parent.config, parent.preplan, parent.deconfliction
    layout, dt = stage2.layout, stage2.dt
    step = replan_step(at, stage2.horizon, dt)
    remaining = stage2.horizon - at
    starts = new_starts(parent, step, states)
    planned = np.stack(
        [positions(model, x[step]) for model, x in zip(layout.models, parent.states, strict=True)]
    )
    child = continued_mission(config, starts, at, remaining)
    progress = with_checkpoints(progress)
    timings = {f"parent_{name}": seconds for name, seconds in parent.timings.items()}
    origin = ReplanOrigin(parent.folder, parent.digest, at, "kept")
    current = None if preplan.current is None else ShiftedCurrent(preplan.current, at)
    limits = np.array([SPEED_MARGIN * top_speed(model) for model in layout.models])
    remainder = timed_stage(
        progress, timings, "schedule",
        lambda: shift_schedule(
            stage2.problem, stage2.coordination, at=at, horizon=stage2.horizon,
            deviations=starts.poses[:, :2] - planned, speed_limits=limits,
        ),
    )  # fmt: skip
    rest = dataclasses.replace(
        preplan, starts=starts.poses, start_speeds=starts.speeds, paths=remainder.problem.paths,
        current=current,
    )  # fmt: skip

    def failed(failure: str, timed: DeconflictStage | None = None) -> Replan:
        result = MissionResult(child, Stage.FULL, rest, timed, timings=timings, failure=failure)
        return Replan(result, origin)

    fastest = [top_speed(model) for model in layout.models]
    late = unreachable(layout.names, remainder.problem.paths, fastest, remaining)
    if late is not None:
        return failed(late)
    guess: Trajectory | None = None
    if remainder.schedule.success:
        time = stage2.time[step:] - at
        desired, guess = kept_schedule(parent, step, remainder, time, starts, current)
        timed = DeconflictStage(
            layout, remaining, dt, stage2.cruise_speeds, remainder.problem, remainder.schedule,
            time, desired,
        )  # fmt: skip
    else:
        origin = dataclasses.replace(origin, schedule="deconflicted")
        try:
            timed = timed_stage(
                progress, timings, "deconflict",
                lambda: run_deconfliction(
                    layout, remainder.problem.paths, starts.poses[:, 2], preplan.goals[:, 2],
                    fleet=child.fleet, settings=config.deconfliction, dt=dt, current=current,
                ),
            )  # fmt: skip
        except InfeasibleError as error:
            return failed(f"the rest of the mission cannot be deconflicted: {error}")

    def optimize(warm_start: WarmStart) -> OptimizedPlan:
        return run_optimization(
            child, layout, rest, timed, config.weights.terrain, callback=callback,
            warm_start=warm_start, jobs=jobs,
        )  # fmt: skip

    def solve() -> OptimizedPlan:
        if guess is not None:
            with contextlib.suppress(SolverError):  # a diverged projection: start cold
                warm = optimize(WarmStart(starts.state, guess, parent.delta))
                if warm.verdict.success:
                    return warm
        return optimize(WarmStart(starts.state))

    try:
        plan = timed_stage(progress, timings, "optimize", solve)
    except SolverError as error:
        return failed(f"the optimiser failed: {error}", timed)
    result = MissionResult(child, Stage.FULL, rest, timed, plan, timings=timings)
    return Replan(result, origin)


def kept_schedule(
    parent: ParentPlan,
    step: int,
    remainder: Remainder,
    time: FloatArray,
    starts: NewStarts,
    current: CurrentField | None,
) -> tuple[tuple[FloatArray, ...], Trajectory]:
    """The desired trajectories and PRONTO's guess on ``time`` [s] when the schedule is kept.

    A vehicle where its plan has it keeps its old desired and optimised trajectories from
    ``step``; a vehicle moved gets the reference states along its led-in remainder path
    (:func:`auvplan.mission.timing.desired_states`, turning from its new heading) as both,
    with zero inputs, so that the projection starts it on a trajectory it can fly.
    """
    layout = parent.deconfliction.layout
    moved = np.hypot(*remainder.deviations.T) > 0.0
    fresh: tuple[FloatArray, ...] = ()
    if np.any(moved):
        ends = (starts.poses[:, 2], parent.preplan.goals[:, 2])
        fresh = desired_states(layout, remainder.problem, remainder.schedule, time, ends, current)
    old = parent.deconfliction.desired_states
    desired = tuple(fresh[i] if moved[i] else old[i][step:] for i in range(layout.n_vehicles))
    states = [fresh[i] if moved[i] else x[step:] for i, x in enumerate(parent.states)]
    inputs = [
        np.zeros_like(u[step:]) if moved[i] else u[step:] for i, u in enumerate(parent.inputs)
    ]
    return desired, Trajectory(states=layout.stack(states), inputs=layout.stack(inputs))


def unreachable(
    names: Sequence[str], paths: Sequence[FloatArray], top_speeds: Sequence[float], remaining: float
) -> str | None:
    """The first vehicle whose remaining path [m] is longer than top speed x ``remaining`` [s].

    Returns the one line naming it and what to change, or None when every vehicle can arrive.
    """
    for name, path, fastest in zip(names, paths, top_speeds, strict=True):
        length = path_length(path)
        if length > fastest * remaining:
            return (
                f"vehicle {name} can no longer reach its goal: {length:.0f} m to go need "
                f">= {length / fastest:.0f} s at its top speed {fastest:.2f} m/s, "
                f"{remaining:g} s remain; plan mission.toml again with a longer fleet.horizon_s"
            )
    return None


def replan_record(replan: Replan, *, warnings: Sequence[str] = ()) -> PlanRecord:
    """The output folder's record of ``replan``: its ``summary.json`` adds ``replan``."""
    record = plan_record(replan.result, warnings=warnings)
    document = {**record.summary.document(), "replan": replan.origin.document()}
    summary = parse_summary(document, source="the replan's summary")
    return dataclasses.replace(record, summary=summary)


__all__ = [
    "NewStarts",
    "Replan",
    "ReplanOrigin",
    "ShiftedCurrent",
    "continued_mission",
    "kept_schedule",
    "new_starts",
    "replan_mission",
    "replan_record",
    "replan_step",
    "unreachable",
]
