"""The output folder as one record in memory: :class:`PlanRecord`, its one writer and reader.

:func:`write_record` writes every data file of a run (``summary.json``, ``mission.toml``,
``maps.nc``, ``paths.geojson``, ``desired.csv``, each plan's ``trajectories*.csv``/``.nc``,
the input files ``mission.toml`` names in ``inputs/``, so the folder reruns wherever it is
copied); :func:`read_record` reads a folder back into the same :class:`PlanRecord`. The CLI,
:func:`auvplan.load`, the exports, ``auvplan evaluate``, the sweep and the report all work on a
record, so a plan made in memory and the same plan read back from its folder answer alike.

``summary.json`` records the ``digest`` of the data files (:func:`files_digest`): the SHA-256
of each trajectory table's bytes and of the maps' arrays. The reader refuses a trajectory table
or ``maps.nc`` that the run of ``summary.json`` did not write (a ``--stage preplan`` rerun into
a full folder leaves the old trajectories next to new maps).
"""

from __future__ import annotations

import hashlib
import io
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.io.maps_file import read_maps_netcdf, write_maps_netcdf
from auvplan.io.results import (
    write_desired_csv,
    write_json,
    write_paths_geojson,
    write_trajectories_csv,
)
from auvplan.io.text import read_json, read_toml, write_toml
from auvplan.io.writing import writing
from auvplan.record.dataset import operator_metadata, trajectories_dataset_of
from auvplan.record.files import (
    DESIRED_FILE,
    MAIN_PLAN,
    MAPS_FILE,
    MISSION_FILE,
    PATHS_FILE,
    PLAN_FILES,
    SUMMARY_FILE,
)
from auvplan.record.summary import PlanSummary, parse_summary
from auvplan.record.trajectories import (
    VehicleTrajectory,
    depth_profiles,
    read_trajectory_tables,
)
from auvplan.terrain import TerrainMaps


@dataclass(frozen=True)
class RunLayers:
    """What a run writes that no reader reads back.

    Parameters
    ----------
    mission_header : str
        The comment at the top of ``mission.toml``.
    paths : tuple of ndarray of shape (n_i, 2)
        Each vehicle's smoothed pre-planned path, ``north, east`` [m] (``paths.geojson``).
    path_properties : tuple of dict
        Each path's GeoJSON properties besides its name.
    desired_time : ndarray of shape (n_t,) or None
        The deconflicted time grid [s] (``desired.csv``; ``None`` before stage 2).
    desired_poses : tuple of ndarray of shape (n_t, 3)
        Each vehicle's desired ``north, east`` [m], ``psi`` [rad].
    inputs : dict of str to bytes
        The input files the folder carries: path relative to the folder (POSIX, under
        :data:`~auvplan.record.files.INPUTS_FOLDER`) -> content; ``mission.toml`` names them.
    """

    mission_header: str
    paths: tuple[FloatArray, ...]
    path_properties: tuple[dict[str, Any], ...]
    desired_time: FloatArray | None = None
    desired_poses: tuple[FloatArray, ...] = ()
    inputs: Mapping[str, bytes] = field(default_factory=dict)


@dataclass(frozen=True)
class PlanRecord:
    """An output folder in memory (module notes).

    Parameters
    ----------
    summary : PlanSummary
        ``summary.json``.
    mission : dict
        ``mission.toml``: the resolved mission document.
    maps : TerrainMaps
        ``maps.nc``: the bathymetry (after any window and projection) and terrain maps.
    plans : dict of str to tuple of VehicleTrajectory
        Each optimised plan's trajectories by label (:data:`~auvplan.record.files.PLAN_FILES`),
        vehicles in mission order.
    layers : RunLayers or None
        The files only written (``None`` for a record read from a folder).
    """

    summary: PlanSummary
    mission: dict[str, Any]
    maps: TerrainMaps
    plans: dict[str, tuple[VehicleTrajectory, ...]] = field(default_factory=dict)
    layers: RunLayers | None = None

    @property
    def depth(self) -> float:
        """The plan's constant depth [m], positive down (``mission.toml``'s ``depth_m``).

        Raises
        ------
        DataFormatError
            If ``mission.depth_m`` is not a finite number.
        """
        table = self.mission.get("mission", {})
        depth = table.get("depth_m", 0.0) if isinstance(table, dict) else None
        if (
            isinstance(depth, bool)
            or not isinstance(depth, int | float)
            or not math.isfinite(depth)
        ):
            raise DataFormatError(f"{MISSION_FILE}: mission.depth_m = {depth!r} is not a number")
        return float(depth)

    @property
    def has_plan(self) -> bool:
        """Whether the record holds the optimised plan (a full run whose optimiser succeeded)."""
        return MAIN_PLAN in self.plans


def trajectories_csv_text(tables: tuple[VehicleTrajectory, ...]) -> str:
    """The text of a plan's ``trajectories.csv`` (written by ``write_trajectories_csv``)."""
    buffer = io.StringIO(newline="")
    write_trajectories_csv(
        buffer,
        [table.name for table in tables],
        tables[0].time,
        [table.states for table in tables],
        [table.inputs for table in tables],
        [table.power for table in tables],
        state_names=[table.state_names for table in tables],
        input_names=[table.input_names for table in tables],
        profiles=depth_profiles(tables),
    )
    return buffer.getvalue()


def maps_digest(maps: TerrainMaps) -> str:
    """SHA-256 of the maps' arrays (depth, information, excitation, cost, shifted cost).

    The same for the maps in memory and as :func:`auvplan.io.maps_file.read_maps_netcdf`
    reads them back from ``maps.nc`` (float64 round-trips exactly).
    """
    digest = hashlib.sha256()
    for array in (
        maps.bathymetry.depth,
        maps.information,
        maps.excitation,
        maps.cost,
        maps.shifted_cost,
    ):
        values = np.ascontiguousarray(array, dtype=np.float64)
        digest.update(repr(values.shape).encode())
        digest.update(np.where(np.isnan(values), np.nan, values).tobytes())
    return digest.hexdigest()


def files_digest(
    maps: TerrainMaps, plans: Mapping[str, tuple[VehicleTrajectory, ...]]
) -> dict[str, str]:
    """``summary.json``'s ``digest``: file name -> SHA-256.

    Of ``maps.nc``: its arrays (:func:`maps_digest`); of each trajectory table: its bytes.
    """
    digest = {MAPS_FILE: maps_digest(maps)}
    for label, tables in plans.items():
        text = trajectories_csv_text(tables)
        digest[PLAN_FILES[label].csv] = hashlib.sha256(text.encode("utf-8")).hexdigest()
    return digest


def write_record(record: PlanRecord, directory: Path) -> list[Path]:
    """Write the data files of ``record`` into ``directory``; returns their paths.

    ``summary.json``, ``mission.toml``, ``maps.nc``, ``paths.geojson``; after
    deconfliction ``desired.csv``; per optimised plan its ``.csv`` and ``.nc`` trajectories
    (:data:`~auvplan.record.files.PLAN_FILES`); the carried input files
    (:attr:`RunLayers.inputs`).

    Raises
    ------
    InputError
        If ``record`` was read from a folder (it has no :class:`RunLayers` to write).
    """
    layers = record.layers
    if layers is None:
        raise InputError("a record read from a folder is copied, not written again")
    names = record.summary.names
    written = [directory / name for name in (SUMMARY_FILE, MISSION_FILE, MAPS_FILE, PATHS_FILE)]
    write_json(record.summary.document(), written[0])
    write_toml(record.mission, written[1], header=layers.mission_header)
    write_maps_netcdf(
        record.maps,
        written[2],
        metadata=operator_metadata(record.mission),
        created=record.summary.created_at,
    )
    write_paths_geojson(
        written[3], names, layers.paths, record.maps.bathymetry.projection, layers.path_properties
    )
    if layers.desired_time is not None:
        written.append(directory / DESIRED_FILE)
        write_desired_csv(written[-1], names, layers.desired_time, layers.desired_poses)
    for label, tables in record.plans.items():
        files = PLAN_FILES[label]
        csv_path, netcdf_path = directory / files.csv, directory / files.netcdf
        with writing(csv_path):
            csv_path.write_text(trajectories_csv_text(tables), encoding="utf-8", newline="")
        with writing(netcdf_path):
            trajectories_dataset_of(record, label).to_netcdf(netcdf_path)
        written += [csv_path, netcdf_path]
    for name, content in layers.inputs.items():
        written.append(directory / name)
        written[-1].parent.mkdir(parents=True, exist_ok=True)
        with writing(written[-1]):
            written[-1].write_bytes(content)
    return written


def read_summary(folder: Path) -> PlanSummary:
    """Read and validate ``folder/summary.json``.

    Raises
    ------
    InputError
        If ``folder`` is not a folder or has no ``summary.json``.
    DataFormatError
        If ``summary.json`` is not JSON, not an object or lacks an entry (one line naming it).
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"output folder {folder} not found (or not a folder)")
    path = folder / SUMMARY_FILE
    if not path.is_file():
        raise InputError(f"{folder} is not an auvplan output folder (no {SUMMARY_FILE})")
    return parse_summary(read_json(path, what="summary file"), source=str(path))


def read_record(folder: Path) -> PlanRecord:
    """Read an output folder of ``auvplan plan``/``demo`` into a :class:`PlanRecord`.

    Every trajectory table is checked (:func:`~auvplan.record.trajectories.
    read_trajectory_tables`), and, when ``summary.json`` has a ``digest``, ``maps.nc`` and
    every trajectory table present must be the ones its run wrote.

    Raises
    ------
    InputError
        If ``folder`` is not an output folder.
    DataFormatError
        If a file is missing, malformed, or was not written by the run of ``summary.json``;
        one line naming the file (and the line, vehicle and column of a bad table cell).
    """
    folder = Path(folder)
    summary = read_summary(folder)
    maps_path = folder / MAPS_FILE
    if not maps_path.is_file():
        raise DataFormatError(f"{maps_path} not found: the folder is incomplete")
    maps = read_maps_netcdf(maps_path)
    digest = summary.digest
    if digest is not None and digest.get(MAPS_FILE) != maps_digest(maps):
        raise DataFormatError(
            f"{maps_path} was not written by the run of {folder / SUMMARY_FILE}: plan again"
        )
    plans = {}
    max_current = summary.fleet.max_current_m_s or 0.0
    for label, files in PLAN_FILES.items():
        path = folder / files.csv
        if not path.is_file():
            if label == MAIN_PLAN and digest is not None and files.csv in digest:
                raise DataFormatError(
                    f"{path} is missing: the run of {folder / SUMMARY_FILE} wrote it"
                )
            continue
        if digest is not None and files.csv not in digest:
            raise DataFormatError(
                f"{path} is stale: the run of {folder / SUMMARY_FILE} did not write it (a "
                "rerun with --stage stopped earlier); plan to the full stage again or remove it"
            )
        plans[label] = read_trajectory_tables(path, summary.vehicles, max_current=max_current)
        if digest is not None and _sha256(path) != digest[files.csv]:
            raise DataFormatError(
                f"{path} is not the file the run of {folder / SUMMARY_FILE} wrote (its SHA-256 "
                "differs)"
            )
    mission_path = folder / MISSION_FILE
    mission = read_toml(mission_path, what="mission file") if mission_path.is_file() else {}
    return PlanRecord(summary, mission, maps, plans)


def _sha256(path: Path) -> str:
    """SHA-256 of the bytes of ``path``, in hex."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


__all__ = [
    "PlanRecord",
    "RunLayers",
    "files_digest",
    "maps_digest",
    "read_record",
    "read_summary",
    "trajectories_csv_text",
    "write_record",
]
