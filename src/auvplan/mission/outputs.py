"""Write a mission run's files (SPEC §8) into a directory (figures: :mod:`auvplan.viz.report`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from auvplan.io.maps_file import write_maps_netcdf
from auvplan.io.results import (
    write_desired_csv,
    write_json,
    write_paths_geojson,
    write_trajectories_csv,
)
from auvplan.mission.pipeline import MissionResult
from auvplan.mission.summary import mission_summary
from auvplan.vehicle import headings, positions


def write_mission_files(result: MissionResult, directory: Path) -> list[Path]:
    """Write the mission's data files into ``directory`` and return their paths.

    Always ``summary.json``, ``maps.nc`` and ``paths.geojson``; after deconfliction
    ``desired.csv``; after optimisation ``trajectories.csv`` (and
    ``trajectories_energy_only.csv`` when the comparison was run).
    """
    preplan = result.preplan
    names = preplan.names
    written = [directory / "summary.json", directory / "maps.nc", directory / "paths.geojson"]
    write_json(mission_summary(result), written[0])
    write_maps_netcdf(preplan.maps, written[1])
    write_paths_geojson(
        written[2],
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
    for plan, file_name in (
        (result.plan, "trajectories.csv"),
        (result.energy_only, "trajectories_energy_only.csv"),
    ):
        if plan is not None and stage2 is not None:
            path = directory / file_name
            write_trajectories_csv(
                path, names, stage2.time, plan.states, plan.inputs, np.asarray(plan.power)
            )
            written.append(path)
    return written
