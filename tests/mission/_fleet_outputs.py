"""Digests of the trajectory files that :mod:`auvplan.record` writes for a plan.

``output_digest`` writes ``trajectories.csv`` and ``trajectories.nc`` of a stand-in mission
result and summarises them: the CSV's SHA-256, and per NetCDF variable its dimensions, type,
attributes (``_FillValue`` included) and the SHA-256 of its raw stored bytes. The expectation
``all_medusa_outputs.json`` was computed by this module with the writers of commit 0f7ae5e
(before mixed fleets) from a seeded stand-in plan: an all-MEDUSA fleet must still write
exactly those files.
"""

from __future__ import annotations

import hashlib
from datetime import UTC, datetime
from pathlib import Path
from types import SimpleNamespace
from typing import Any, cast

import numpy as np

from auvplan import __version__
from auvplan.io.vehicles import load_vehicle
from auvplan.mission.outputs import trajectory_tables
from auvplan.record import PlanRecord, trajectories_dataset_of
from auvplan.record.folder import trajectories_csv_text
from auvplan.vehicle import VehicleModel, build_vehicle_model

#: Seed and length of the stand-in plan.
SEED = 20261123
N_SAMPLES = 121
EXPECTATION = Path(__file__).parent / "all_medusa_outputs.json"
START = datetime(2026, 5, 1, 8, 0, 0, tzinfo=UTC)
DT = 0.5


def stand_in_result(
    names: tuple[str, ...], models: tuple[VehicleModel, ...], states: Any, inputs: Any, power: Any
) -> Any:
    """The attributes of a MissionResult and OptimizedPlan that the trajectory writers read."""
    time = DT * np.arange(np.shape(power)[1], dtype=np.float64)
    plan = SimpleNamespace(
        states=states, inputs=inputs, power=power, terrain_weight=1.0, depth_profiles=None
    )
    result = SimpleNamespace(
        config=SimpleNamespace(mission=SimpleNamespace(start_time=START, depth=0.0)),
        preplan=SimpleNamespace(names=names, bathymetry=SimpleNamespace(projection=None)),
        deconfliction=SimpleNamespace(layout=SimpleNamespace(models=models), time=time),
    )
    return result, plan


def golden_medusa_result() -> Any:
    """Stand-in result of two MEDUSAs with a seeded plan (fixed: independent of the solver)."""
    rng = np.random.default_rng(SEED)
    states = rng.normal(size=(2, N_SAMPLES, 8)) * [100.0, 100.0, 1.0, 0.5, 0.1, 0.1, 40.0, 40.0]
    inputs = rng.uniform(-1.0, 1.0, size=(2, N_SAMPLES - 1, 2))
    model = build_vehicle_model(load_vehicle("medusa"))
    power = 40.0 + np.abs(states[..., 6]) + np.abs(states[..., 7])
    return stand_in_result(("blue", "green"), (model, model), states, inputs, power)


def write_files(result: Any, plan: Any, folder: Path) -> tuple[Path, Path]:
    """``trajectories.csv`` and ``trajectories.nc`` of the stand-in, as the record writes them."""
    tables = trajectory_tables(result, plan)
    models = result.deconfliction.layout.models
    record = SimpleNamespace(
        plans={"terrain_aware": tables},
        summary=SimpleNamespace(
            start=START,
            created_at=None,
            vehicles=[SimpleNamespace(type_name=model.vehicle.name) for model in models],
            outcome=lambda label: SimpleNamespace(terrain_weight=plan.terrain_weight),
        ),
        mission={},
        depth=result.config.mission.depth,
        maps=SimpleNamespace(bathymetry=result.preplan.bathymetry),
    )
    csv_path, netcdf_path = folder / "trajectories.csv", folder / "trajectories.nc"
    csv_path.write_text(trajectories_csv_text(tables), encoding="utf-8", newline="")
    stand_in = cast("PlanRecord", record)  # the attributes the dataset reads
    trajectories_dataset_of(stand_in, "terrain_aware").to_netcdf(netcdf_path)
    return csv_path, netcdf_path


def netcdf_digest(path: Path) -> dict[str, Any]:
    """Dimensions, type, attributes and stored bytes (SHA-256) of every variable.

    The package version in attributes reads ``<version>`` (a release changes nothing else).
    """
    import netCDF4

    with netCDF4.Dataset(path) as dataset:
        dataset.set_auto_maskandscale(False)
        variables = {}
        for name, variable in dataset.variables.items():
            attributes = {key: _text(variable.getncattr(key)) for key in variable.ncattrs()}
            data = np.asarray(variable[...])
            variables[name] = {
                "dimensions": list(variable.dimensions),
                "dtype": str(variable.dtype),
                "attributes": attributes,
                "sha256": hashlib.sha256(np.ascontiguousarray(data).tobytes()).hexdigest(),
            }
        global_attributes = {key: _text(dataset.getncattr(key)) for key in dataset.ncattrs()}
    return {"variables": variables, "attributes": global_attributes}


def _text(value: Any) -> str:
    return repr(value).replace(__version__, "<version>")


def output_digest(folder: Path) -> dict[str, Any]:
    """The digest of the golden all-MEDUSA plan's trajectory files (module notes)."""
    csv_path, netcdf_path = write_files(*golden_medusa_result(), folder)
    return {
        "csv_sha256": hashlib.sha256(csv_path.read_bytes()).hexdigest(),
        "csv_header": csv_path.read_text(encoding="utf-8").splitlines()[0],
        "netcdf": netcdf_digest(netcdf_path),
    }
