"""The output folder of a run as one typed record: file names, models, one writer, one reader.

* :mod:`~auvplan.record.files` — every file name of the folder, declared once;
* :class:`PlanSummary` — ``summary.json`` (pydantic; entries only ever added);
* :class:`VehicleTrajectory` — a vehicle's rows of ``trajectories.csv``, with its own state
  and input names (vehicles of different state sizes in one fleet);
* :class:`PlanRecord` — the folder in memory; :func:`write_record` writes it,
  :func:`read_record` reads it back (and refuses bad or stale files, one line each);
* :func:`export_plan` and :func:`trajectories_dataset_of` — the exports and
  ``trajectories.nc`` made from a record, never by reading the folder back.

The record sits above ``io``, ``terrain``, ``vehicle`` and ``export``, and below ``mission``
(which builds a record from a run), ``sweep``, ``scenarios``, ``api`` and ``cli``.
"""

from __future__ import annotations

from auvplan.record.dataset import trajectories_dataset_of
from auvplan.record.export import export_plan
from auvplan.record.folder import (
    PlanRecord,
    RunLayers,
    files_digest,
    read_record,
    read_summary,
    write_record,
)
from auvplan.record.summary import PlanOutcome, PlanSummary, VehicleSummary, parse_summary
from auvplan.record.trajectories import VehicleTrajectory

__all__ = [
    "PlanOutcome",
    "PlanRecord",
    "PlanSummary",
    "RunLayers",
    "VehicleSummary",
    "VehicleTrajectory",
    "export_plan",
    "files_digest",
    "parse_summary",
    "read_record",
    "read_summary",
    "trajectories_dataset_of",
    "write_record",
]
