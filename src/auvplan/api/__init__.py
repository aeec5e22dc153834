"""The notebook-first API behind :mod:`auvplan`'s top-level names (plan, load, MissionPlan).

:mod:`auvplan.api.result` plans and loads missions, :mod:`auvplan.api.folder` writes output
folders (data, exports, figures, ``report.html``), :mod:`auvplan.api.maps` writes the terrain
maps of a bathymetry, :mod:`auvplan.api.progress` shows progress on the console. The command
line is built on these.
"""

from __future__ import annotations

from auvplan.api.folder import write_output_folder
from auvplan.api.maps import MapsFolder, write_terrain_maps
from auvplan.api.progress import ConsoleProgress
from auvplan.api.result import MissionPlan, MissionSource, load, plan

__all__ = [
    "ConsoleProgress",
    "MapsFolder",
    "MissionPlan",
    "MissionSource",
    "load",
    "plan",
    "write_output_folder",
    "write_terrain_maps",
]
