"""Write a mission run's files (SPEC §8) into a directory (figures: :mod:`auvplan.viz.report`)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from auvplan import __version__
from auvplan.io.maps_file import write_maps_netcdf
from auvplan.io.results import (
    union_names,
    write_desired_csv,
    write_json,
    write_paths_geojson,
    write_trajectories_csv,
)
from auvplan.io.text import write_toml
from auvplan.io.trajectories_file import SERIES, trajectories_dataset
from auvplan.mission.config import resolved_document
from auvplan.mission.evaluation import OptimizedPlan
from auvplan.mission.pipeline import MissionResult
from auvplan.mission.summary import mission_summary
from auvplan.vehicle import STATE_NAMES, headings, positions

if TYPE_CHECKING:
    import xarray as xr


def write_mission_files(
    result: MissionResult, directory: Path, *, warnings: Sequence[str] = ()
) -> list[Path]:
    """Write the mission's data files into ``directory`` and return their paths.

    Always ``summary.json`` (with ``warnings``, the warnings logged during the run),
    ``mission.toml`` (the resolved mission: ``auvplan plan`` of it reruns the mission),
    ``maps.nc`` and ``paths.geojson``; after deconfliction ``desired.csv``; after
    optimisation ``trajectories.csv`` and ``trajectories.nc`` (and
    ``trajectories_energy_only.csv``/``.nc``, ``trajectories_paper.csv``/``.nc`` when those
    comparisons were run).
    """
    preplan = result.preplan
    names = preplan.names
    written = [
        directory / "summary.json",
        directory / "mission.toml",
        directory / "maps.nc",
        directory / "paths.geojson",
    ]
    write_json(mission_summary(result, warnings=warnings), written[0])
    source = result.config.source
    write_toml(
        resolved_document(result.config),
        written[1],
        header=f"The mission as auvplan {__version__} ran it"
        + ("" if source is None else f" (from {source})")
        + ": every default filled in.\nRun it again with: auvplan plan mission.toml -o NEW_FOLDER",
    )
    write_maps_netcdf(preplan.maps, written[2])
    write_paths_geojson(
        written[3],
        names,
        preplan.paths,
        preplan.bathymetry.projection,
        [{"graph_cost": route.cost, "n_cells": len(route.cells)} for route in preplan.routes],
    )
    stage2 = result.deconfliction
    if stage2 is not None:
        path = directory / "desired.csv"
        poses = [
            np.column_stack([positions(model, desired), headings(model, desired)])
            for model, desired in zip(stage2.layout.models, stage2.desired_states, strict=True)
        ]
        write_desired_csv(path, names, stage2.time, np.stack(poses))
        written.append(path)
    paper = result.paper
    for owner, plan, stem in (
        (result, result.plan, "trajectories"),
        (result, result.energy_only, "trajectories_energy_only"),
        (paper, None if paper is None else paper.plan, "trajectories_paper"),
    ):
        timed = None if owner is None else owner.deconfliction
        if plan is not None and owner is not None and timed is not None:
            csv_path, netcdf_path = directory / f"{stem}.csv", directory / f"{stem}.nc"
            models = timed.layout.models
            write_trajectories_csv(
                csv_path, names, timed.time, plan.states, plan.inputs, np.asarray(plan.power),
                state_names=[model.state_names for model in models],
                input_names=[model.input_names for model in models],
            )  # fmt: skip
            plan_dataset(owner, plan).to_netcdf(netcdf_path)
            written += [csv_path, netcdf_path]
    return written


def plan_dataset(result: MissionResult, plan: OptimizedPlan) -> xr.Dataset:
    """``trajectories.nc`` of one optimised plan of ``result``, in memory.

    The dataset of :func:`auvplan.io.trajectories_file.trajectories_dataset`: what
    :func:`~auvplan.io.trajectories_file.read_trajectories_netcdf` reads back from the file
    that :func:`write_mission_files` writes. The states of :data:`SERIES`, then the fleet's
    other states (:func:`auvplan.io.results.union_names`), NaN where a vehicle has no such
    state; ``vehicle_type`` unless every vehicle has MEDUSA's states.
    """
    assert result.deconfliction is not None  # a plan exists only after stage 2
    models = result.deconfliction.layout.models
    names = union_names([model.state_names for model in models], tuple(SERIES))
    series = {
        name: np.stack(
            [
                plan.states[i][:, model.index(name)]
                if name in model.state_names
                else np.full(plan.states[i].shape[0], np.nan)
                for i, model in enumerate(models)
            ]
        )
        for name in names
        if name not in ("power", "psi")
    }
    psi = np.stack([headings(model, plan.states[i]) for i, model in enumerate(models)])
    is_medusa_layout = all(model.state_names == STATE_NAMES for model in models)
    return trajectories_dataset(
        result.preplan.names,
        result.deconfliction.time,
        {**series, "power": np.asarray(plan.power)},
        psi=psi,
        start_time=result.config.mission.start_time,
        depth=result.config.mission.depth,
        projection=result.preplan.bathymetry.projection,
        attributes={
            "source": f"auvplan {__version__}",
            "history": f"written by auvplan {__version__} (auvplan plan)",
            "references": "Häusler et al., Cooperative AUV Motion Planning using Terrain "
            "Information, OCEANS 2013",
            "terrain_weight": plan.terrain_weight,
        },
        vehicle_types=None if is_medusa_layout else [model.vehicle.name for model in models],
    )
