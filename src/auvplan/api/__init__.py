"""The notebook-first API behind :mod:`auvplan`'s top-level names (plan, load, MissionPlan).

:mod:`auvplan.api.result` plans and loads missions, :mod:`auvplan.api.folder` writes output
folders (data, exports, figures, ``report.html``), :mod:`auvplan.api.progress` shows progress
on the console. The command line is built on these, one function per verb:
:mod:`auvplan.api.planning` plans a mission into its output folder, :mod:`auvplan.api.maps`
writes the terrain maps of a bathymetry, :mod:`auvplan.api.navigation` flies a folder's
plans through the TAN simulator, :mod:`auvplan.api.sweep` runs a parameter sweep and
:mod:`auvplan.api.vehicle` describes a vehicle type.

The names are imported on first use, so a verb that needs one module (``auvplan vehicle``)
does not load the planning pipeline.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from auvplan._lazy import lazy_attributes

#: Public name -> the module that defines it (imported on first access).
_LAZY = {
    "write_output_folder": "auvplan.api.folder",
    "MapsFolder": "auvplan.api.maps",
    "EvaluatedFolder": "auvplan.api.navigation",
    "evaluate_output_folder": "auvplan.api.navigation",
    "write_terrain_maps": "auvplan.api.maps",
    "ConsoleProgress": "auvplan.api.progress",
    "SavedPlan": "auvplan.api.planning",
    "plan_to_folder": "auvplan.api.planning",
    "MissionPlan": "auvplan.api.result",
    "MissionSource": "auvplan.api.result",
    "load": "auvplan.api.result",
    "plan": "auvplan.api.result",
    "SweepOutcome": "auvplan.api.sweep",
    "sweep_to_folder": "auvplan.api.sweep",
    "VehicleDescription": "auvplan.api.vehicle",
    "describe_vehicle": "auvplan.api.vehicle",
}

if TYPE_CHECKING:
    from auvplan.api.folder import write_output_folder
    from auvplan.api.maps import MapsFolder, write_terrain_maps
    from auvplan.api.navigation import EvaluatedFolder, evaluate_output_folder
    from auvplan.api.planning import SavedPlan, plan_to_folder
    from auvplan.api.progress import ConsoleProgress
    from auvplan.api.result import MissionPlan, MissionSource, load, plan
    from auvplan.api.sweep import SweepOutcome, sweep_to_folder
    from auvplan.api.vehicle import VehicleDescription, describe_vehicle

__all__ = [
    "ConsoleProgress",
    "EvaluatedFolder",
    "MapsFolder",
    "MissionPlan",
    "MissionSource",
    "SavedPlan",
    "SweepOutcome",
    "VehicleDescription",
    "describe_vehicle",
    "evaluate_output_folder",
    "load",
    "plan",
    "plan_to_folder",
    "sweep_to_folder",
    "write_output_folder",
    "write_terrain_maps",
]


__getattr__, __dir__ = lazy_attributes(__name__, _LAZY, __all__)
