"""Reading back the output folder of ``auvplan plan`` / ``auvplan demo`` (SPEC §8).

What :func:`read_plan_folder` uses:

* ``maps.nc``: the bathymetry the plan used (``depth`` on the local north/east grid, after any
  window and projection; :func:`auvplan.io.maps_file.read_maps_netcdf`);
* ``trajectories.csv`` (the plan) and, when present, ``trajectories_energy_only.csv`` (the
  energy-only reference of ``--compare-energy-only``): columns ``vehicle, t, north, east, psi``
  and ``power`` (:data:`auvplan.io.results.TRAJECTORY_COLUMNS`);
* ``summary.json`` when present (its plan records, e.g. the terrain weight).
"""

from __future__ import annotations

import csv
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError
from auvplan.io.maps_file import read_maps_netcdf
from auvplan.terrain import BathymetryGrid

#: Plan label -> trajectory file, in the order plans are reported.
TRAJECTORY_FILES: Final = {
    "terrain_aware": "trajectories.csv",
    "energy_only": "trajectories_energy_only.csv",
    "paper": "trajectories_paper.csv",
}
#: Plan label -> the ``summary.json`` record of that plan.
SUMMARY_RECORDS: Final = {
    "terrain_aware": "optimization",
    "energy_only": "energy_only",
    "paper": "paper",
}
_COLUMNS: Final = ("t", "north", "east", "psi", "power")


@dataclass(frozen=True)
class VehicleTrajectory:
    """One vehicle's planned trajectory as written in ``trajectories.csv``.

    Parameters
    ----------
    time : ndarray of shape (n_t,)
        Time [s], strictly increasing.
    positions : ndarray of shape (n_t, 2)
        ``north, east`` [m].
    heading : ndarray of shape (n_t,)
        ``psi`` [rad].
    power : ndarray of shape (n_t,)
        Electrical power [W].
    """

    time: FloatArray
    positions: FloatArray
    heading: FloatArray
    power: FloatArray

    @property
    def energy(self) -> float:
        """Electrical energy [J]: trapezoidal integral of ``power`` over ``time``."""
        return float(np.trapezoid(self.power, self.time))


@dataclass(frozen=True)
class PlanFolder:
    """The parts of a plan output folder that evaluations need.

    Parameters
    ----------
    path : Path
        The folder.
    bathymetry : BathymetryGrid
        The bathymetry the plan used (from ``maps.nc``).
    plans : dict of str to dict of str to VehicleTrajectory
        ``plans[label][vehicle]`` for each label of :data:`TRAJECTORY_FILES` whose file exists,
        vehicles in file order.
    summary : dict or None
        ``summary.json``, if the folder has one.
    """

    path: Path
    bathymetry: BathymetryGrid
    plans: dict[str, dict[str, VehicleTrajectory]]
    summary: dict[str, Any] | None

    def plan_record(self, label: str) -> dict[str, Any]:
        """The ``summary.json`` record of plan ``label`` (empty without a summary)."""
        if self.summary is None:
            return {}
        record = self.summary.get(SUMMARY_RECORDS[label], {})
        return record if isinstance(record, dict) else {}


def read_plan_folder(path: str | Path) -> PlanFolder:
    """Read a ``plan``/``demo`` output folder (module notes).

    Parameters
    ----------
    path : str or Path
        The folder.

    Returns
    -------
    PlanFolder

    Raises
    ------
    DataFormatError
        If the folder, its ``maps.nc`` or its ``trajectories.csv`` is missing, or a file is
        malformed; the message names the file and what is wrong.
    """
    folder = Path(path)
    if not folder.is_dir():
        raise DataFormatError(f"output folder {folder} not found")
    maps_file = folder / "maps.nc"
    if not maps_file.is_file():
        raise DataFormatError(
            f"{maps_file} not found: give the output folder of 'auvplan plan' or 'auvplan demo'"
        )
    if not (folder / TRAJECTORY_FILES["terrain_aware"]).is_file():
        raise DataFormatError(
            f"{folder} has no trajectories.csv: run the plan to the full stage first"
        )
    plans = {
        label: read_trajectories_csv(folder / name)
        for label, name in TRAJECTORY_FILES.items()
        if (folder / name).is_file()
    }
    summary = None
    summary_file = folder / "summary.json"
    if summary_file.is_file():
        try:
            summary = json.loads(summary_file.read_text(encoding="utf-8"))
        except (json.JSONDecodeError, UnicodeDecodeError) as error:
            raise DataFormatError(f"{summary_file}: not valid JSON ({error})") from None
        if not isinstance(summary, dict):
            raise DataFormatError(f"{summary_file}: not a JSON object")
    return PlanFolder(folder, read_maps_netcdf(maps_file).bathymetry, plans, summary)


def read_trajectories_csv(path: Path) -> dict[str, VehicleTrajectory]:
    """Read ``trajectories.csv`` (or the energy-only file) into one trajectory per vehicle.

    Raises
    ------
    DataFormatError
        Missing columns, a value that is not a finite number, no rows, fewer than 2 rows or
        non-increasing time for a vehicle.
    """
    try:
        with path.open(newline="", encoding="utf-8") as handle:
            reader = csv.DictReader(handle)
            missing = [c for c in ("vehicle", *_COLUMNS) if c not in (reader.fieldnames or ())]
            if missing:
                raise DataFormatError(f"{path}: missing column(s) {', '.join(missing)}")
            rows: dict[str, list[list[float]]] = {}
            for line, record in enumerate(reader, start=2):
                rows.setdefault(record["vehicle"], []).append(
                    [_number(record[column], path, line, column) for column in _COLUMNS]
                )
    except UnicodeDecodeError:
        raise DataFormatError(f"{path}: not a UTF-8 text file") from None
    if not rows:
        raise DataFormatError(f"{path}: no trajectory rows")
    trajectories = {}
    for name, values in rows.items():
        table = np.array(values)
        if table.shape[0] < 2 or not np.all(np.diff(table[:, 0]) > 0.0):
            raise DataFormatError(
                f"{path}: vehicle {name!r} needs at least 2 rows with increasing t"
            )
        trajectories[name] = VehicleTrajectory(table[:, 0], table[:, 1:3], table[:, 3], table[:, 4])
    return trajectories


def _number(text: str | None, path: Path, line: int, column: str) -> float:
    """``text`` as a finite float, else a DataFormatError naming the file, line and column."""
    try:
        value = float(text) if text is not None else math.nan
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise DataFormatError(f"{path} line {line}: {column} = {text!r} is not a finite number")
    return value
