"""Terrain-aided navigation of plan output folders: ``auvplan evaluate`` and ``sweep --evaluate``.

:func:`evaluate_folder` flies every vehicle of every plan of an output folder of
``plan``/``demo`` (or of a sweep's run), as :func:`auvplan.record.read_record` reads it,
through the Monte-Carlo TAN simulator (:func:`auvplan.navigation.evaluate_plans`) and returns
the evaluations with their ``navigation.json`` document.
:func:`evaluate_run_folder` does that for one sweep run and writes ``navigation.json``
(atomically) next to its plan; :func:`is_evaluated` tells whether a folder's
``navigation.json`` was made with the same settings, run count and seed, so a resumed sweep
evaluates only the folders that lack it.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from auvplan.errors import DataFormatError, InputError
from auvplan.io.output import staged_output_file
from auvplan.io.results import write_json
from auvplan.io.text import read_json
from auvplan.mission.folder import mission_navigation
from auvplan.navigation import (
    NavigationSettings,
    PlanNavigation,
    Track,
    VehiclePlan,
    evaluate_plans,
    navigation_summary,
    settings_document,
)
from auvplan.navigation.evaluation import EvaluationProgress
from auvplan.record import PlanRecord, read_record
from auvplan.record.files import MAIN_PLAN, NAVIGATION_FILE, PLAN_FILES


@dataclass(frozen=True)
class NavigationOptions:
    """How a folder's plans are evaluated.

    ``settings`` is the simulated navigation system, ``n_runs`` the Monte-Carlo runs per
    vehicle and plan, ``seed`` their base seed (a sweep uses each row's seed instead when it
    has ``--seeds``), ``threads`` the threads of the Monte-Carlo runs (default: every CPU the
    process may use).
    """

    settings: NavigationSettings = field(default_factory=NavigationSettings)
    n_runs: int = 100
    seed: int = 0
    threads: int | None = None

    @property
    def settings_document(self) -> dict[str, Any]:
        """``navigation.json``'s ``settings`` for these options."""
        return settings_document(self.settings, n_runs=self.n_runs, seed=self.seed)


@dataclass(frozen=True)
class NavigationRequest:
    """The navigation to fly along a plan, as ``auvplan evaluate`` and ``sweep --evaluate`` ask.

    ``overrides`` are keys of the mission's ``[navigation]`` table (``sensor``,
    ``update_period_s``, ``initial_sigma_m``, ``drift_percent``) put over the plan's table;
    ``n_runs`` is the Monte-Carlo runs per vehicle and plan, ``particles`` the particles per
    filter and ``convergence_updates`` the updates with sigma <= 5 m in a row that count as
    converged.
    """

    overrides: Mapping[str, Any] = field(default_factory=dict)
    n_runs: int = 100
    particles: int = 5000
    convergence_updates: int = 200

    def options(
        self, record: PlanRecord | None, *, seed: int, threads: int | None = None
    ) -> NavigationOptions:
        """The :class:`NavigationOptions` of this request for ``record``'s plan.

        The model is the ``[navigation]`` table of ``record``'s mission (its defaults without
        a record) with :attr:`overrides` on top
        (:func:`auvplan.mission.folder.mission_navigation`), at the plan's depth [m] (0
        without a record); ``seed`` is the runs' base seed and ``threads`` their threads.

        Raises
        ------
        InputError
            If a model value is out of its range.
        """
        table = mission_navigation({} if record is None else record.mission, self.overrides)
        settings = table.settings(
            vehicle_depth=0.0 if record is None else record.depth,
            particles=self.particles,
            convergence_updates=self.convergence_updates,
        )
        return NavigationOptions(settings, n_runs=self.n_runs, seed=seed, threads=threads)


@dataclass(frozen=True)
class FolderNavigation:
    """The navigation of a folder's plans by plan label, and the ``navigation.json`` document."""

    evaluations: dict[str, PlanNavigation]
    document: dict[str, Any]


def evaluate_folder(
    record: PlanRecord, options: NavigationOptions, *, progress: EvaluationProgress | None = None
) -> FolderNavigation:
    """Evaluate every plan of an output folder's record (module notes); nothing is written.

    Raises
    ------
    InputError
        If the record has no optimised plan, or a track cannot be flown (too short, or it
        starts where the map has no depth).
    """
    if not record.has_plan:
        raise InputError(
            f"the folder has no {PLAN_FILES[MAIN_PLAN].csv} (stage {record.summary.stage}): "
            "run the plan to the full stage first"
        )
    plans = {
        label: {
            v.name: VehiclePlan(Track(v.time, v.positions, v.heading, v.depth), v.energy)
            for v in vehicles
        }
        for label, vehicles in record.plans.items()
    }
    evaluations = evaluate_plans(
        record.maps.bathymetry,
        plans,
        options.settings,
        n_runs=options.n_runs,
        seed=options.seed,
        workers=options.threads,
        progress=progress,
    )
    document = navigation_summary(
        evaluations,
        options.settings,
        n_runs=options.n_runs,
        seed=options.seed,
        plan_records={label: _outcome_document(record, label) for label in plans},
    )
    return FolderNavigation(evaluations, document)


def _outcome_document(record: PlanRecord, label: str) -> dict[str, Any]:
    """``summary.json``'s record of plan ``label`` as JSON values (empty without one)."""
    outcome = record.summary.outcome(label)
    return {} if outcome is None else outcome.model_dump(mode="json", exclude_unset=True)


def has_plan(path: Path) -> bool:
    """Whether ``path`` holds a plan to fly (the optimised ``trajectories.csv``)."""
    return (path / PLAN_FILES[MAIN_PLAN].csv).is_file()


def is_evaluated(path: Path, options: NavigationOptions) -> bool:
    """Whether ``path/navigation.json`` exists and was made with ``options`` (settings, seed)."""
    target = path / NAVIGATION_FILE
    if not target.is_file():
        return False
    try:
        document = read_json(target, what="navigation file")
    except DataFormatError:
        return False
    expected = json.loads(json.dumps(options.settings_document))
    return isinstance(document, Mapping) and document.get("settings") == expected


def evaluate_run_folder(path: Path, options: NavigationOptions) -> Path:
    """Evaluate a run folder's plan and write its ``navigation.json`` (all or nothing).

    Returns the file written.

    Raises
    ------
    DataFormatError
        If the folder or one of its files is missing or malformed.
    InputError
        If a track cannot be flown (:func:`evaluate_folder`).
    """
    document = evaluate_folder(read_record(path), options).document
    target = path / NAVIGATION_FILE
    with staged_output_file(target) as staging:
        write_json(document, staging)
    return target


__all__ = [
    "NAVIGATION_FILE",
    "FolderNavigation",
    "NavigationOptions",
    "NavigationRequest",
    "evaluate_folder",
    "evaluate_run_folder",
    "has_plan",
    "is_evaluated",
]
