"""Missions: the TOML mission file, the end-to-end pipeline and its results."""

from __future__ import annotations

from auvplan.mission.config import MissionConfig, load_mission, parse_mission
from auvplan.mission.pipeline import MissionResult, Stage, run_mission

__all__ = [
    "MissionConfig",
    "MissionResult",
    "Stage",
    "load_mission",
    "parse_mission",
    "run_mission",
]
