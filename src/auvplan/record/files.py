"""The output folder's file names, declared once (SPEC §8).

Every module that writes or reads an output folder of ``auvplan plan``/``demo`` takes the
names from here. The names are part of the user-facing contract: they are only ever added to.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

#: Every number needed to verify a plan (:class:`auvplan.record.PlanSummary`).
SUMMARY_FILE: Final = "summary.json"
#: The resolved mission: ``auvplan plan`` of it reruns the mission.
MISSION_FILE: Final = "mission.toml"
#: Bathymetry and terrain maps (:mod:`auvplan.io.maps_file`).
MAPS_FILE: Final = "maps.nc"
#: The pre-planned, smoothed paths (GeoJSON).
PATHS_FILE: Final = "paths.geojson"
#: The timed, deconflicted desired trajectories.
DESIRED_FILE: Final = "desired.csv"
#: The self-contained report page.
REPORT_FILE: Final = "report.html"
#: The sub-folder of the input files the folder carries (vehicle files, propeller tables,
#: current file), which ``mission.toml`` names relative to itself (:mod:`auvplan.mission.carry`).
INPUTS_FOLDER: Final = "inputs"
#: The sub-folder of the exports (``plan --export``, ``auvplan export``).
EXPORT_FOLDER: Final = "export"
#: The navigation evaluation (``auvplan evaluate``, ``sweep --evaluate``).
NAVIGATION_FILE: Final = "navigation.json"
#: A sweep's record of the run that wrote the folder (:mod:`auvplan.sweep.table`).
RUN_RECORD_FILE: Final = "sweep_run.json"


@dataclass(frozen=True)
class PlanFiles:
    """Where one optimised plan lives: its ``summary.json`` record and its trajectory files.

    Parameters
    ----------
    record : str
        Key of the plan's record in ``summary.json``.
    stem : str
        File stem of its trajectories: ``{stem}.csv`` and ``{stem}.nc``.
    """

    record: str
    stem: str

    @property
    def csv(self) -> str:
        """File name of the plan's ``trajectories.csv`` table."""
        return f"{self.stem}.csv"

    @property
    def netcdf(self) -> str:
        """File name of the plan's CF trajectory NetCDF file."""
        return f"{self.stem}.nc"


#: Plan label -> its files, in the order plans are written and reported.
PLAN_FILES: Final = {
    "terrain_aware": PlanFiles("optimization", "trajectories"),
    "energy_only": PlanFiles("energy_only", "trajectories_energy_only"),
    "paper": PlanFiles("paper", "trajectories_paper"),
}
#: The label of the optimised plan every full run has.
MAIN_PLAN: Final = "terrain_aware"

__all__ = [
    "DESIRED_FILE",
    "EXPORT_FOLDER",
    "INPUTS_FOLDER",
    "MAIN_PLAN",
    "MAPS_FILE",
    "MISSION_FILE",
    "NAVIGATION_FILE",
    "PATHS_FILE",
    "PLAN_FILES",
    "REPORT_FILE",
    "RUN_RECORD_FILE",
    "SUMMARY_FILE",
    "PlanFiles",
]
