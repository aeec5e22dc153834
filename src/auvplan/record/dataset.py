"""A plan of a record as the CF trajectory dataset of ``trajectories.nc``.

:func:`trajectories_dataset_of` is what :func:`~auvplan.record.write_record` writes and what
:meth:`auvplan.MissionPlan.to_xarray` returns, for a plan made in memory and for one read
back from its folder alike (:func:`auvplan.io.trajectories_file.trajectories_dataset`).
Who made the plan comes from ``mission.toml``'s ``[metadata]``
(:class:`auvplan.mission.tables.MetadataConfig`), the platform from the vehicle types.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from auvplan._typing import FloatArray
from auvplan._version import __version__
from auvplan.errors import DataFormatError
from auvplan.io.results import union_names
from auvplan.io.trajectories_file import SERIES, trajectories_dataset
from auvplan.record.files import MISSION_FILE
from auvplan.record.trajectories import VehicleTrajectory, depth_profiles
from auvplan.vehicle import STATE_NAMES

if TYPE_CHECKING:
    import xarray as xr

    from auvplan.record.folder import PlanRecord


def fleet_series(tables: tuple[VehicleTrajectory, ...], name: str) -> FloatArray:
    """State ``name`` of every vehicle, shape ``(n_vehicles, n_t)``; NaN for vehicles without it."""
    return np.array(
        [
            table.state(name) if name in table.state_names else np.full(table.time.size, np.nan)
            for table in tables
        ]
    )


def trajectories_dataset_of(record: PlanRecord, label: str) -> xr.Dataset:
    """``trajectories.nc`` of plan ``label`` of ``record``, in memory.

    The states of :data:`~auvplan.io.trajectories_file.SERIES`, then the fleet's other states
    (:func:`auvplan.io.results.union_names`), NaN where a vehicle has no such state;
    ``vehicle_type`` unless every vehicle has MEDUSA's states.
    """
    tables = record.plans[label]
    outcome = record.summary.outcome(label)
    if outcome is None or outcome.terrain_weight is None:
        raise DataFormatError(f"summary.json has no terrain_weight of the {label} plan")
    names = union_names([table.state_names for table in tables], tuple(SERIES))
    series = {name: fleet_series(tables, name) for name in names if name not in ("power", "psi")}
    is_medusa_layout = all(table.state_names == STATE_NAMES for table in tables)
    profiles = depth_profiles(tables)
    types = [vehicle.type_name or vehicle.type for vehicle in record.summary.vehicles]
    return trajectories_dataset(
        [table.name for table in tables],
        tables[0].time,
        {**series, "power": np.array([table.power for table in tables])},
        psi=fleet_series(tables, "psi"),
        start_time=record.summary.start,
        depth=record.depth if profiles is None else np.array([depth for depth, _ in profiles]),
        altitude=None if profiles is None else np.array([altitude for _, altitude in profiles]),
        projection=record.maps.bathymetry.projection,
        attributes={
            "source": f"auvplan {__version__}",
            "history": f"written by auvplan {__version__} (auvplan plan)",
            "references": "Häusler et al., Cooperative AUV Motion Planning using Terrain "
            "Information, OCEANS 2013",
            "terrain_weight": outcome.terrain_weight,
            "platform": ", ".join(dict.fromkeys(types)),
        },
        vehicle_types=None if is_medusa_layout else types,
        metadata=operator_metadata(record.mission),
        created=record.summary.created_at,
    )


def operator_metadata(mission: dict[str, object]) -> dict[str, str]:
    """The ``[metadata]`` table of a resolved mission document: attribute name -> text.

    Raises
    ------
    DataFormatError
        If the table or one of its values is not text (a ``mission.toml`` edited by hand).
    """
    table = mission.get("metadata", {})
    if not isinstance(table, dict) or not all(isinstance(v, str) for v in table.values()):
        raise DataFormatError(f"{MISSION_FILE}: [metadata] must hold text values only")
    return {str(key): value for key, value in table.items()}


__all__ = ["fleet_series", "operator_metadata", "trajectories_dataset_of"]
