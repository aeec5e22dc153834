"""A mission run as the record of its output folder (SPEC §8; written by :mod:`auvplan.record`).

:func:`plan_record` turns a :class:`~auvplan.mission.pipeline.MissionResult` into the
:class:`~auvplan.record.PlanRecord` that :func:`~auvplan.record.write_record` writes and that
the report, the exports and :class:`auvplan.MissionPlan` read, with each vehicle's
trajectories in its own state and input names.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from auvplan._version import __version__
from auvplan.mission.carry import carried_mission
from auvplan.mission.evaluation import OptimizedPlan
from auvplan.mission.pipeline import MissionResult
from auvplan.mission.summary import mission_summary
from auvplan.record import PlanRecord, RunLayers, VehicleTrajectory, files_digest
from auvplan.record.files import MISSION_FILE
from auvplan.vehicle import headings, positions


def plan_record(result: MissionResult, *, warnings: Sequence[str] = ()) -> PlanRecord:
    """The record of ``result``: summary (with its ``digest``), mission, maps, plans, layers.

    The mission and the input files it names are those the folder carries
    (:func:`~auvplan.mission.carry.carried_mission`): the folder reruns wherever it is copied.

    ``warnings`` are the warnings logged during the run (``summary.json`` keeps them). The
    plans are the optimised plan (``terrain_aware``) and the ``energy_only`` and ``paper``
    comparisons that were run.
    """
    preplan = result.preplan
    plans = {
        label: trajectory_tables(owner, plan)
        for label, owner, plan in (
            ("terrain_aware", result, result.plan),
            ("energy_only", result, result.energy_only),
            ("paper", result.paper, None if result.paper is None else result.paper.plan),
        )
        if owner is not None and plan is not None
    }
    carried = carried_mission(result.config)
    types = [table["type"] for table in carried.document["vehicle"]]
    summary = mission_summary(result, vehicle_types=types, warnings=warnings)
    summary = summary.model_copy(update={"digest": files_digest(preplan.maps, plans)})
    source = result.config.source
    header = (
        f"The mission as auvplan {__version__} ran it"
        + ("" if source is None else f" (from {source.name})")
        + ": every default filled in, every file one of this folder's.\n"
        + f"Run it again, from any copy of the folder, with: auvplan plan {MISSION_FILE} "
        "-o NEW_FOLDER"
    )
    stage2 = result.deconfliction
    layers = RunLayers(
        mission_header=header,
        paths=tuple(preplan.paths),
        path_properties=tuple(
            {"graph_cost": route.cost, "n_cells": len(route.cells)} for route in preplan.routes
        ),
        desired_time=None if stage2 is None else stage2.time,
        desired_poses=()
        if stage2 is None
        else tuple(
            np.column_stack([positions(model, desired), headings(model, desired)])
            for model, desired in zip(stage2.layout.models, stage2.desired_states, strict=True)
        ),
        inputs=carried.files,
    )
    return PlanRecord(summary, carried.document, preplan.maps, plans, layers)


def trajectory_tables(owner: MissionResult, plan: OptimizedPlan) -> tuple[VehicleTrajectory, ...]:
    """Each vehicle's trajectory of ``plan`` (made by the run ``owner``), in its own names."""
    assert owner.deconfliction is not None  # a plan exists only after stage 2
    timed = owner.deconfliction
    profiles = plan.depth_profiles
    return tuple(
        VehicleTrajectory(
            name,
            model.state_names,
            model.input_names,
            timed.time,
            plan.states[i],
            plan.inputs[i],
            np.asarray(plan.power[i], dtype=np.float64),
            depth=None if profiles is None else profiles[i].depth,
            altitude=None if profiles is None else profiles[i].altitude,
        )
        for i, (name, model) in enumerate(
            zip(owner.preplan.names, timed.layout.models, strict=True)
        )
    )


__all__ = ["plan_record", "trajectory_tables"]
