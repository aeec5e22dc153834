"""Replan a plan from where its vehicles are: what ``auvplan replan`` and ``MissionPlan.replan`` do.

:func:`replan` plans the rest of a plan from time ``at`` [s] (:mod:`auvplan.mission.replan`):
the states given (``STATES.csv`` or a mapping, :mod:`auvplan.mission.states`) replace those
the plan has at ``at``; a plan read from its folder has its mission pre-planned again and
its stage-2 schedule read from its ``summary.json`` first (:mod:`auvplan.mission.parent`).
:func:`replan_to_folder` reads a folder, replans it and writes the new plan's output folder,
a normal one whose ``summary.json`` adds ``replan`` (the parent folder, its
``trajectories.csv`` digest, ``at_s``, ``schedule``).

>>> import auvplan                                                    # doctest: +SKIP
>>> rest = auvplan.load("out/run1").replan(1800.0, "states.csv")      # doctest: +SKIP
>>> rest.status, rest.summary["replan"]                               # doctest: +SKIP
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from contextlib import nullcontext
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from auvplan._figures import DEFAULT_DPI
from auvplan.api.companion import Companion, resolve_jobs
from auvplan.api.result import MissionPlan, load, logged_warnings, progress_reporter
from auvplan.errors import InputError
from auvplan.mission.config import MissionConfig
from auvplan.mission.parent import (
    ParentPlan,
    parent_from_record,
    parent_from_result,
    record_mission,
)
from auvplan.mission.pipeline import MissionResult
from auvplan.mission.progress import ProgressReporter, no_progress
from auvplan.mission.replan import replan_mission, replan_record, replan_step
from auvplan.mission.states import given_states, read_states
from auvplan.mission.tables import StartPose
from auvplan.record.files import MAIN_PLAN, PLAN_FILES

#: The states of :func:`replan`: a ``STATES.csv`` file, or vehicle -> ``{north, east | lat,
#: lon, heading_deg, speed}``; None: every vehicle where the plan has it.
StatesSource = str | os.PathLike[str] | Mapping[str, Mapping[str, Any]] | None


@dataclass(frozen=True)
class SavedReplan:
    """A replan's run and the files of its output folder."""

    result: MissionResult
    """The run (:attr:`~auvplan.mission.MissionResult.problem`: why it is not a usable plan)."""
    written: tuple[Path, ...]
    """The files written, under the output folder."""


def replan(
    plan: MissionPlan,
    at: float,
    states: StatesSource = None,
    *,
    progress: bool = True,
    jobs: int | None = None,
) -> MissionPlan:
    """Plan the rest of ``plan`` from time ``at`` [s] and the vehicles' ``states`` then.

    Parameters
    ----------
    plan : MissionPlan
        A full plan, made in this session or loaded from its folder.
    at : float
        The plan's time [s] that is the new plan's ``t = 0``: ``0 < at < T``, a multiple of
        ``solver.dt_s``.
    states : path, mapping or None
        ``STATES.csv`` (:mod:`auvplan.mission.states`) or vehicle -> state; vehicles not
        given start where ``plan`` has them at ``at``.
    progress : bool
        Show progress on the console.
    jobs : int, optional
        Cores, 1 or 2 (default: :func:`~auvplan.api.companion.resolve_jobs`): a coupled
        fleet's optimiser runs on ``jobs`` threads, a decomposed one in ``jobs`` processes.

    Returns
    -------
    MissionPlan
        The new plan (horizon ``T - at``, same goals and constraints), also when it failed:
        see :attr:`MissionPlan.status` and ``summary["optimization"]``.

    Raises
    ------
    InputError, DataFormatError
        For a bad ``at``, a bad states file or state, or a plan that cannot be replanned
        (one line naming the cause), before anything is planned.
    """
    if not plan.record.has_plan:
        raise InputError(f"nothing to replan: {plan!r} holds no optimised plan")
    folder = None if plan.folder is None else str(plan.folder)
    config = (
        record_mission(plan.record, folder=folder) if plan.result is None else plan.result.config
    )
    replan_step(at, float(plan.record.plans[MAIN_PLAN][0].time[-1]), config.solver.dt)
    poses = _poses(states, plan.names)
    cores = resolve_jobs(jobs)
    with logged_warnings() as warnings, progress_reporter(config, progress) as reporter:
        stages = no_progress if reporter is None else reporter
        parent = _parent(plan, config, folder, stages)
        replanned = replan_mission(
            parent,
            at,
            poses,
            callback=None if reporter is None else reporter.iteration,
            progress=stages,
            jobs=cores,
        )
    return MissionPlan(replan_record(replanned, warnings=warnings), result=replanned.result)


def replan_to_folder(
    folder: Path,
    at: float,
    states: Path | None,
    target: Path,
    *,
    progress: bool = True,
    figures: bool = True,
    figure_format: str = "png",
    dpi: int = DEFAULT_DPI,
    jobs: int | None = None,
) -> SavedReplan:
    """Replan the plan of output folder ``folder`` (:func:`replan`) into ``target``.

    ``figures``, ``figure_format`` and ``dpi`` (dots per inch) as for
    :meth:`auvplan.MissionPlan.save`, ``jobs`` as for :func:`replan`; the folder is written
    also when the plan failed. With two cores the figures are drawn by two processes, as
    :func:`~auvplan.api.planning.plan_to_folder` draws them: the second
    (:class:`~auvplan.api.companion.Companion`) is started first, so that its imports overlap
    the replanning.

    Raises
    ------
    InputError, DataFormatError
        As :func:`replan` and :func:`auvplan.load`; nothing is written.
    """
    with Companion() if figures and resolve_jobs(jobs) == 2 else nullcontext() as companion:
        if companion is not None:
            companion.start()
        new_plan = replan(load(folder), at, states, progress=progress, jobs=jobs)
        written = new_plan.save(
            target, figures=figures, figure_format=figure_format, dpi=dpi, companion=companion
        )
    assert new_plan.result is not None  # planned in this session
    return SavedReplan(new_plan.result, tuple(written))


def _poses(states: StatesSource, names: tuple[str, ...]) -> dict[str, StartPose]:
    if states is None:
        return {}
    if isinstance(states, Mapping):
        return given_states(states, names)
    return read_states(Path(states), names)


def _parent(
    plan: MissionPlan, config: MissionConfig, folder: str | None, stages: ProgressReporter
) -> ParentPlan:
    if plan.result is not None:
        digest = (plan.record.summary.digest or {}).get(PLAN_FILES[MAIN_PLAN].csv)
        return parent_from_result(plan.result, digest=digest)
    return parent_from_record(plan.record, config, folder=folder, progress=stages)


__all__ = ["SavedReplan", "StatesSource", "replan", "replan_to_folder"]
