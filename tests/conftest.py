"""Shared fixtures: a seeded RNG and the real bathymetry grids of ../shared/data."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import matplotlib
import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from auvplan.io.samples import samples_folder
from auvplan.scenarios._terrain import write_synthetic_terrain
from auvplan.terrain import BathymetryGrid, GridGeometry

matplotlib.use("Agg")
# the CLI's second process (auvplan.api.companion) is tested on its own: the many in-process
# `auvplan plan` runs of the suite use one process each, as `--jobs 1`
os.environ.setdefault("AUVPLAN_JOBS", "1")

SHARED_DATA = Path(
    os.environ.get("AUVPLAN_SHARED_DATA", Path(__file__).parents[1] / ".." / "shared" / "data")
)


@pytest.fixture
def rng() -> np.random.Generator:
    """A seeded generator; tests never touch global random state."""
    return np.random.default_rng(20131023)


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """``../shared/data`` (skip the test when the folder is absent)."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"shared data folder not found at {SHARED_DATA}")
    return SHARED_DATA.resolve()


@pytest.fixture(scope="session")
def bathymetry_dir() -> Path:
    """The real bathymetry grids: the samples packaged with auvplan (no ``../shared`` needed)."""
    return samples_folder()


#: A mission writer of :func:`transit_mission`: ``(folder, ridge=..., navigation=...)``.
TransitMission = Callable[..., Path]

SPACING = 10.0
N = 160  # 1.6 km square


def _plain(path: Path, *, ridge: bool) -> Path:
    """A featureless plain, with a rough ridge 160 m north of the transit line if asked."""
    rows = np.arange(N)[:, None] + np.zeros((1, N))
    depth = 60.0 + 0.002 * SPACING * np.arange(N)[None, :] + np.zeros((N, N))
    if ridge:
        band = np.exp(-0.5 * ((rows - 96) / 4.0) ** 2)
        rough = gaussian_filter(np.random.default_rng(5).normal(0.0, 10.0, (N, N)), 1.5)
        depth = depth - 15.0 * band + band * rough
    write_synthetic_terrain(BathymetryGrid(depth, GridGeometry(N, N, SPACING, SPACING)), path)
    return path


def _transit_mission(folder: Path, *, ridge: bool, navigation: str = "") -> Path:
    _plain(folder / "terrain.nc", ridge=ridge)
    mission = folder / "mission.toml"
    mission.write_text(
        f"""
[terrain]
file = "terrain.nc"
[fleet]
horizon_s = 2200.0
safety_radius_m = 5.0
[solver]
dt_s = 2.0
[navigation]
settle_s = 300.0
{navigation}
[[vehicle]]
name = "blue"
start = {{ north = 800.0, east = 50.0, heading_deg = 90.0 }}
goal = {{ north = 800.0, east = 1550.0, heading_deg = 90.0 }}
""",
        encoding="utf-8",
    )
    return mission


@pytest.fixture
def transit_mission() -> TransitMission:
    """Writes a 1.5 km, 37 min transit of one MEDUSA over a plain (with or without a rough
    ridge 160 m beside the line) and its ``terrain.nc`` into a folder; returns the mission file.
    ``navigation`` adds lines to its ``[navigation]`` table."""
    return _transit_mission


#: Writes an output folder of hand-made trajectories through :func:`auvplan.record.write_record`.
PlanFolderWriter = Callable[..., Path]


@pytest.fixture
def write_plan_folder() -> PlanFolderWriter:
    """``write(folder, maps, plans, *, top_speed=2.0, extra=None, mission=None) -> folder``.

    ``plans`` maps plan labels (``terrain_aware``, ``energy_only``, ``paper``) to tuples of
    :class:`auvplan.record.VehicleTrajectory`; the summary is the smallest valid
    :class:`auvplan.record.PlanSummary` of those vehicles (each of top speed ``top_speed``
    [m/s]), with the ``extra`` entries and the files' digest.
    """
    from auvplan.record import PlanRecord, RunLayers, files_digest, parse_summary, write_record
    from auvplan.record.files import PLAN_FILES
    from auvplan.record.trajectories import VehicleTrajectory
    from auvplan.terrain import TerrainMaps

    def write(
        folder: Path,
        maps: TerrainMaps,
        plans: dict[str, tuple[VehicleTrajectory, ...]],
        *,
        top_speed: float = 2.0,
        extra: dict[str, object] | None = None,
        mission: dict[str, object] | None = None,
    ) -> Path:
        tables = next(iter(plans.values()))
        pose = {"north": 0.0, "east": 0.0, "heading_rad": 0.0}
        vehicles = [
            {"name": t.name, "type": "medusa", "start": pose, "goal": pose, "preplan": {},
             "type_name": "medusa", "state_names": t.state_names, "input_names": t.input_names,
             "top_speed_m_s": top_speed}
            for t in tables
        ]  # fmt: skip
        outcomes = {
            PLAN_FILES[label].record: {
                "terrain_weight": 0.0 if label == "energy_only" else 1.0,
                "plan_status": "CONVERGED",
                "verdict": "",
            }
            for label in plans
        }
        document = {
            "auvplan_version": "test", "mission": None, "inputs": {},
            "start_time": "2026-05-01T08:00:00+00:00", "stage": "full",
            "terrain": {"name": "test", "origin": {"north": 0.0, "east": 0.0}},
            "obstacles": [], "current": None,
            "fleet": {"safety_radius_m": 5.0, "edge_model": "paper",
                      "deconfliction_method": "astar", "max_current_m_s": 0.0},
            "solver": {}, "vehicles": vehicles, "wall_time_s": {}, "warnings": [],
            **outcomes, **(extra or {}),
        }  # fmt: skip
        summary = parse_summary(document, source="test summary")
        summary = summary.model_copy(update={"digest": files_digest(maps, plans)})
        layers = RunLayers("test", tuple(t.positions for t in tables), tuple({} for _ in tables))
        folder.mkdir(parents=True, exist_ok=True)
        write_record(PlanRecord(summary, dict(mission or {}), maps, plans, layers), folder)
        return folder

    return write


#: The golden mission (tests/regression): two MEDUSAs whose paths cross, deconfliction active.
GOLDEN_MISSION = Path(__file__).parent / "regression" / "golden_mission.toml"


@pytest.fixture(scope="session")
def golden_solved() -> tuple[Any, Any, Any]:
    """The golden mission planned in full, and its stage-3 problem assembled again:
    ``(config, result, assembled)`` (read only)."""
    from auvplan.mission.assembly import assemble_problem
    from auvplan.mission.config import load_mission
    from auvplan.mission.pipeline import Stage, run_mission

    config = load_mission(GOLDEN_MISSION)
    result = run_mission(config, stage=Stage.FULL)
    assert result.plan is not None
    assert result.deconfliction is not None
    assembled = assemble_problem(
        result.deconfliction.layout, result.preplan, result.deconfliction,
        weights=config.weights, terrain_weight=config.weights.terrain,
        safety_radius=config.fleet.safety_radius, comms=config.comms,
    )  # fmt: skip
    return config, result, assembled
