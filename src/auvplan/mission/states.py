"""The vehicles' states at a replanning time: ``STATES.csv`` and its mapping form.

``auvplan replan --states STATES.csv`` reads one row per vehicle whose state differs from its
plan: columns ``vehicle,north,east,heading_deg,speed`` (``north``/``east`` [m] in the map
frame), or ``lat,lon`` [deg] in place of ``north,east`` (georeferenced terrain), with
``heading_deg`` clockwise from north [deg] and ``speed`` the surge speed [m/s]. Each row is
validated as a mission's start pose (:class:`~auvplan.mission.tables.StartPose`), so the
ranges and the error messages are those of ``vehicle.start`` in a mission file.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Final

from pydantic import ValidationError

from auvplan.errors import DataFormatError, InputError
from auvplan.io.tables import one_line
from auvplan.io.text import read_text
from auvplan.mission.tables import StartPose

#: The columns besides the position, in any order.
STATE_COLUMNS: Final = ("vehicle", "heading_deg", "speed")
#: The two ways to give the position.
POSITION_COLUMNS: Final = (("north", "east"), ("lat", "lon"))


def read_states(path: Path, names: tuple[str, ...]) -> dict[str, StartPose]:
    """Read ``STATES.csv`` (module notes) for the vehicles ``names``: vehicle -> state.

    Raises
    ------
    DataFormatError
        If the file is unreadable or not a CSV table, a column is missing, or a row has the
        wrong number of cells (one line naming the file and line).
    InputError
        If a row names an unknown vehicle or one already given, or holds a value that is not
        a finite number in range (one line naming the file, line and column).
    """
    text = read_text(path, what="states file")
    try:
        lines = list(csv.reader(io.StringIO(text, newline="")))
    except csv.Error as error:
        raise DataFormatError(f"states file {path}: not a CSV table ({error})") from None
    lines = [line for line in lines if any(cell.strip() for cell in line)]
    if not lines:
        raise DataFormatError(f"states file {path}: empty (no header)")
    header = [cell.strip() for cell in lines[0]]
    position = next((pair for pair in POSITION_COLUMNS if set(pair) <= set(header)), None)
    missing = [column for column in STATE_COLUMNS if column not in header]
    if position is None or missing:
        wanted = ", ".join(missing + ([] if position else ["north,east (or lat,lon)"]))
        raise DataFormatError(
            f"states file {path}: missing column(s) {wanted}; the header must hold "
            "vehicle,north,east,heading_deg,speed (or lat,lon for north,east)"
        )
    states: dict[str, dict[str, Any]] = {}
    for number, row in enumerate(lines[1:], start=2):
        where = f"states file {path} line {number}"
        if len(row) != len(header):
            raise DataFormatError(f"{where}: {len(row)} cells, the header has {len(header)}")
        cells = dict(zip(header, (cell.strip() for cell in row), strict=True))
        name = cells["vehicle"]
        if name in states:
            raise InputError(f"{where}: vehicle {name!r} is given twice")
        states[name] = {
            column: _number(cells[column], f"{where}: {column}")
            for column in (*position, "heading_deg", "speed")
        }
    return given_states(states, names, source=f"states file {path}")


def given_states(
    states: Mapping[str, Mapping[str, Any]], names: tuple[str, ...], *, source: str = "states"
) -> dict[str, StartPose]:
    """Validate vehicle -> ``{north, east | lat, lon, heading_deg, speed}`` as start poses.

    Raises
    ------
    InputError
        If a vehicle is not one of ``names`` or a state is not a valid start pose (one line
        naming ``source``, the vehicle and the key).
    """
    poses = {}
    for name, state in states.items():
        if name not in names:
            raise InputError(
                f"{source}: no vehicle named {name!r} in the plan (vehicles: {', '.join(names)})"
            )
        try:
            poses[name] = StartPose.model_validate(dict(state))
        except ValidationError as error:
            raise InputError(f"{source}: vehicle {name!r}: {one_line(error, StartPose)}") from None
    return poses


def _number(text: str, where: str) -> float:
    """``text`` as a finite float, else an InputError naming ``where``."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise InputError(f"{where} = {text!r} is not a finite number")
    return value


__all__ = ["POSITION_COLUMNS", "STATE_COLUMNS", "given_states", "read_states"]
