"""Per-vehicle trajectory tables: what ``trajectories.csv`` holds of each vehicle.

A :class:`VehicleTrajectory` carries its vehicle's own state and input names, so a fleet of
vehicles with different state vectors (a 6-state and an 8-state type) needs no common shape.
:func:`read_trajectory_tables` is the one reader of the trajectory tables: it checks each
vehicle's rows against the vehicle's record in ``summary.json`` and refuses, in one line
naming the file, the line, the vehicle and the column, what no run of auvplan writes.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError
from auvplan.io.results import PROFILE_COLUMNS
from auvplan.record.summary import VehicleSummary

#: Margin on a vehicle's top speed [-] beyond which a row is not a plan of that vehicle.
SPEED_MARGIN: Final = 1.5
#: The states of every vehicle type: pose ``eta`` and body velocities ``nu`` (Fossen).
BODY_STATES: Final = ("north", "east", "psi", "u", "v", "r")


@dataclass(frozen=True)
class VehicleTrajectory:
    """One vehicle's optimised trajectory on the solver's time grid.

    Parameters
    ----------
    name : str
        Vehicle name.
    state_names, input_names : tuple of str
        The vehicle's own states (``north, east, psi, u, v, r``, then its actuators) and
        inputs, in model order.
    time : ndarray of shape (n_t,)
        Time since the plan's start [s], increasing.
    states : ndarray of shape (n_t, n_x)
        States named by ``state_names`` [m, m, rad, m/s, m/s, rad/s, rev/s…, rad…].
    inputs : ndarray of shape (n_t - 1, n_u)
        Inputs named by ``input_names`` [-], held over each step.
    power : ndarray of shape (n_t,)
        Electrical power [W].
    depth, altitude : ndarray of shape (n_t,), optional
        The depth profile of a plan of ``[mission] altitude_m``
        (:mod:`auvplan.mission.depth_profile`): depth [m], positive down, and height above
        the seabed [m] (``trajectories.csv``'s ``depth_m``, ``altitude_m``); ``None`` for a
        plan flown at the constant ``depth_m``.
    """

    name: str
    state_names: tuple[str, ...]
    input_names: tuple[str, ...]
    time: FloatArray
    states: FloatArray
    inputs: FloatArray
    power: FloatArray
    depth: FloatArray | None = None
    altitude: FloatArray | None = None

    def state(self, name: str) -> FloatArray:
        """The time series of state ``name``, shape ``(n_t,)``."""
        return self.states[:, self.state_names.index(name)]

    @property
    def positions(self) -> FloatArray:
        """``north, east`` [m], shape ``(n_t, 2)``."""
        return np.column_stack([self.state("north"), self.state("east")])

    @property
    def heading(self) -> FloatArray:
        """``psi`` [rad], shape ``(n_t,)``."""
        return self.state("psi")

    @property
    def energy(self) -> float:
        """Electrical energy [J]: trapezoidal integral of ``power`` over ``time``."""
        return float(np.trapezoid(self.power, self.time))


def depth_profiles(
    tables: tuple[VehicleTrajectory, ...],
) -> list[tuple[FloatArray, FloatArray]] | None:
    """Each vehicle's ``(depth, altitude)`` [m] of a plan with a depth profile, else ``None``.

    Raises
    ------
    DataFormatError
        If some vehicles have a profile and others not.
    """
    pairs = [(table.depth, table.altitude) for table in tables]
    complete = [
        (depth, altitude) for depth, altitude in pairs if depth is not None and altitude is not None
    ]
    if not complete:
        return None
    if len(complete) != len(pairs):
        raise DataFormatError("a depth profile (depth_m, altitude_m) for some vehicles only")
    return complete


def read_trajectory_tables(
    path: Path, vehicles: Sequence[VehicleSummary], *, max_current: float
) -> tuple[VehicleTrajectory, ...]:
    """Read a ``trajectories.csv`` of the vehicles ``vehicles`` (in their order).

    Each vehicle's rows must hold a finite number in each of its own columns (``t``, its
    ``state_names``, ``input_names``, ``power``, and ``depth_m``, ``altitude_m`` when the
    table has them) and nothing in the others; its time must
    increase over at least 2 rows; its speed through the water ``hypot(u, v)`` must stay
    within :data:`SPEED_MARGIN` times its top speed, and each step within
    ``SPEED_MARGIN * (top speed + max_current) * dt``. (A summary written before auvplan
    recorded each vehicle's columns and top speed: its filled cells are its columns, and
    speeds and steps are not bounded.)

    Parameters
    ----------
    path : Path
        The file.
    vehicles : sequence of VehicleSummary
        The vehicles of ``summary.json`` (their ``state_names``, ``input_names`` and
        ``top_speed_m_s`` [m/s]).
    max_current : float
        Largest current speed along the plan [m/s] (0 in still water).

    Raises
    ------
    DataFormatError
        One line naming the file, the line and vehicle, and the column.
    """
    try:
        with path.open(newline="", encoding="utf-8") as handle:
            lines = list(csv.reader(handle))
    except UnicodeDecodeError:
        raise DataFormatError(f"{path}: not a UTF-8 text file") from None
    except csv.Error as error:
        raise DataFormatError(f"{path}: not a CSV table ({error})") from None
    if not lines or not lines[0]:
        raise DataFormatError(f"{path}: empty file (no header)")
    header, rows = lines[0], lines[1:]
    if header[0] != "vehicle":
        raise DataFormatError(f"{path}: the first column is {header[0]!r}, not 'vehicle'")
    if not rows:
        raise DataFormatError(f"{path}: header only, no trajectory rows")
    by_name = {vehicle.name: vehicle for vehicle in vehicles}
    numbered: dict[str, list[tuple[int, list[str]]]] = {name: [] for name in by_name}
    for line, row in enumerate(rows, start=2):
        if len(row) != len(header):
            raise DataFormatError(
                f"{path} line {line}: {len(row)} cells, the header has {len(header)}"
            )
        if row[0] not in numbered:
            raise DataFormatError(f"{path} line {line}: vehicle {row[0]!r} is not in the summary")
        numbered[row[0]].append((line, row))
    return tuple(
        _vehicle_table(path, header, by_name[name], numbered[name], max_current) for name in by_name
    )


def _vehicle_table(
    path: Path,
    header: list[str],
    vehicle: VehicleSummary,
    rows: list[tuple[int, list[str]]],
    max_current: float,
) -> VehicleTrajectory:
    """One vehicle's rows as a :class:`VehicleTrajectory`, checked (see the reader)."""
    if not rows:
        raise DataFormatError(f"{path}: no rows of vehicle {vehicle.name!r}")
    state_names, input_names = _own_columns(vehicle, header, rows[0][1])
    lacking = [name for name in BODY_STATES if name not in state_names]
    if lacking:
        raise DataFormatError(
            f"{path} vehicle {vehicle.name!r}: its states {', '.join(state_names)} lack "
            f"{lacking[0]!r} (every vehicle has {', '.join(BODY_STATES)})"
        )
    profile = tuple(name for name in PROFILE_COLUMNS if name in header)
    own = ("t", *state_names, *input_names, "power", *profile)
    missing = [name for name in own if name not in header]
    if missing:
        raise DataFormatError(f"{path}: no column {missing[0]!r} of vehicle {vehicle.name!r}")
    if len(rows) < 2:
        raise DataFormatError(
            f"{path} vehicle {vehicle.name!r}: 1 row, a trajectory needs at least 2"
        )
    index = {name: header.index(name) for name in own}
    others = [k for k, name in enumerate(header) if k and name not in index]
    table = _finite_table(rows, list(index.values()))
    if table is None or others:  # a fault: the first one, line by line, named
        for line, row in rows:
            for name, k in index.items() if table is None else ():
                _number(row[k], f"{path} line {line}", vehicle.name, name)
            filled = next((k for k in others if row[k].strip()), None)
            if filled is not None:
                raise DataFormatError(
                    f"{path} line {line}: vehicle {vehicle.name!r} has no state "
                    f"{header[filled]!r}, but the cell holds {row[filled]!r}"
                )
    assert table is not None  # else a cell that is not a finite number was named above
    if profile and profile != PROFILE_COLUMNS:
        raise DataFormatError(f"{path}: {profile[0]!r} without {PROFILE_COLUMNS}")
    n_x, n_p = len(state_names), len(profile)
    power = table[:, own.index("power")]
    trajectory = VehicleTrajectory(
        vehicle.name,
        state_names,
        input_names,
        table[:, 0],
        table[:, 1 : 1 + n_x],
        table[:-1, 1 + n_x : -1 - n_p],
        power,
        depth=table[:, -2] if n_p else None,
        altitude=table[:, -1] if n_p else None,
    )
    lines = [line for line, _ in rows]
    _check_motion(path, lines, vehicle, trajectory, max_current)
    return trajectory


@np.errstate(over="ignore")  # finite cells up to 1.8e308 overflow to inf steps, refused below
def _check_motion(
    path: Path,
    lines: list[int],
    vehicle: VehicleSummary,
    trajectory: VehicleTrajectory,
    max_current: float,
) -> None:
    """Refuse non-increasing time and speeds or steps no vehicle of this type can fly."""
    dt = np.diff(trajectory.time)
    if (bad := np.flatnonzero(dt <= 0.0)).size:
        line = lines[bad[0] + 1]
        raise DataFormatError(f"{path} line {line}: vehicle {vehicle.name!r}: t does not increase")
    if vehicle.top_speed_m_s is None:  # a summary written before auvplan recorded it
        return
    top = vehicle.top_speed_m_s
    speed = np.hypot(trajectory.state("u"), trajectory.state("v"))
    if (bad := np.flatnonzero(speed > SPEED_MARGIN * top)).size:
        k = bad[0]
        raise DataFormatError(
            f"{path} line {lines[k]}: vehicle {vehicle.name!r}: speed hypot(u, v) = "
            f"{speed[k]:.3g} m/s is above {SPEED_MARGIN:g} x its top speed {top:.3g} m/s"
        )
    step = np.hypot(*np.diff(trajectory.positions, axis=0).T)
    limit = SPEED_MARGIN * (top + max_current) * dt
    if (bad := np.flatnonzero(step > limit)).size:
        k = bad[0]
        raise DataFormatError(
            f"{path} line {lines[k + 1]}: vehicle {vehicle.name!r}: north/east step of "
            f"{step[k]:.3g} m in {dt[k]:.3g} s is longer than {SPEED_MARGIN:g} x (top speed "
            f"{top:.3g} + current {max_current:.3g} m/s) x dt"
        )


def _own_columns(
    vehicle: VehicleSummary, header: list[str], first_row: list[str]
) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """The vehicle's state and input names: from ``summary.json``, else from its cells.

    A summary written before auvplan recorded ``state_names``/``input_names`` names no
    columns; the vehicle's are then those its first row fills, inputs being the ``c_*``.
    """
    if vehicle.state_names is not None and vehicle.input_names is not None:
        return vehicle.state_names, vehicle.input_names
    filled = [
        name
        for name, cell in zip(header[1:], first_row[1:], strict=True)
        if cell.strip() and name not in ("t", "power", *PROFILE_COLUMNS)
    ]
    return (
        tuple(name for name in filled if not name.startswith("c_")),
        tuple(name for name in filled if name.startswith("c_")),
    )


def _finite_table(rows: list[tuple[int, list[str]]], columns: list[int]) -> FloatArray | None:
    """The cells ``columns`` of ``rows`` as floats, shape ``(n_rows, n_columns)``.

    None when a cell is not a number (``float`` refuses it) or not finite: :func:`_number`
    then names the first such cell.
    """
    try:
        table = np.array([[float(row[k]) for k in columns] for _, row in rows], dtype=np.float64)
    except ValueError:
        return None
    return table if np.all(np.isfinite(table)) else None


def _number(text: str, where: str, vehicle: str, column: str) -> float:
    """``text`` as a finite float, else a DataFormatError naming the place and column."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise DataFormatError(
            f"{where}: vehicle {vehicle!r}: {column} = {text!r} is not a finite number"
        )
    return value


__all__ = [
    "BODY_STATES",
    "SPEED_MARGIN",
    "VehicleTrajectory",
    "depth_profiles",
    "read_trajectory_tables",
]
