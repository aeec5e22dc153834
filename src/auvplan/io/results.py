"""Writers for the ``auvplan plan`` outputs (SPEC §8): JSON summary, CSV time series, GeoJSON.

The column sets are part of the user-facing contract and only ever grow:

* ``trajectories.csv``: ``vehicle,t,north,east,psi,u,v,r,n_ps,n_sb,c_ps,c_sb,power``
  (SI units, ``psi`` in rad, ``n_*`` in rev/s, ``delta_*`` in rad, ``power`` in W). Inputs are
  held constant over each step (zero-order hold); the last row of a vehicle repeats the last
  input, so that every row is complete. A fleet with other actuators (a ``remus100``: ``n_prop``,
  ``delta_rudder``, ``c_prop``, ``c_rudder``) adds its state and input names after MEDUSA's, in
  model order (:func:`trajectory_columns`); a vehicle's cells of a state it does not have are
  empty.
* ``desired.csv``: ``vehicle,t,north,east,psi`` — the timed, deconflicted desired trajectories.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, Final, TextIO

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.io.writing import writing
from auvplan.terrain.projection import LocalProjection
from auvplan.vehicle import INPUT_NAMES, STATE_NAMES

#: The columns of an all-MEDUSA fleet, present in every ``trajectories.csv``.
TRAJECTORY_COLUMNS: Final = ("vehicle", "t", *STATE_NAMES, *INPUT_NAMES, "power")
#: Columns of a plan with a depth profile (``[mission] altitude_m``), after ``power``: the
#: depth [m], positive down, and the altitude above the seabed [m].
PROFILE_COLUMNS: Final = ("depth_m", "altitude_m")
DESIRED_COLUMNS = ("vehicle", "t", "north", "east", "psi")


def write_json(data: Mapping[str, Any], path: Path) -> None:
    """Write ``data`` as indented JSON; numpy scalars/arrays become numbers/lists, NaN -> null."""
    text = json.dumps(json_values(data), indent=2, allow_nan=False)
    with writing(path):
        path.write_text(text + "\n", encoding="utf-8")


def json_values(value: Any) -> Any:
    """``value`` as plain JSON values, as :func:`write_json` writes and ``json.load`` reads it.

    Mappings become dicts with string keys, tuples and arrays lists, numpy scalars Python
    numbers, and NaN or infinite floats ``None``.

    Examples
    --------
    >>> json_values({1: (np.float64(0.5), np.array([1, 2])), "x": float("inf")})
    {'1': [0.5, [1, 2]], 'x': None}
    """
    if isinstance(value, Mapping):
        return {str(key): json_values(item) for key, item in value.items()}
    if isinstance(value, np.ndarray):
        return json_values(value.tolist())
    if isinstance(value, list | tuple):
        return [json_values(item) for item in value]
    if isinstance(value, np.generic):
        return json_values(value.item())
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_text_files(directory: Path, files: Mapping[str, str]) -> list[Path]:
    """Write each ``name: text`` of ``files`` as a UTF-8 file in ``directory`` (created)."""
    directory.mkdir(parents=True, exist_ok=True)
    written = []
    for name, text in files.items():
        path = directory / name
        with writing(path):
            path.write_text(text, encoding="utf-8")
        written.append(path)
    return written


def union_names(per_vehicle: Sequence[Sequence[str]], first: Sequence[str]) -> tuple[str, ...]:
    """``first``, then each other name of ``per_vehicle`` in order of first appearance.

    Examples
    --------
    >>> union_names([("a", "b"), ("a", "c", "d")], ("a", "b"))
    ('a', 'b', 'c', 'd')
    """
    names = list(first)
    for vehicle in per_vehicle:
        names += [name for name in vehicle if name not in names]
    return tuple(names)


def trajectory_columns(
    state_names: Sequence[Sequence[str]],
    input_names: Sequence[Sequence[str]],
    *,
    has_profile: bool = False,
) -> tuple[str, ...]:
    """Header of ``trajectories.csv`` for vehicles with these state and input names.

    ``vehicle, t``, the states (MEDUSA's :data:`~auvplan.vehicle.STATE_NAMES`, then the
    others in model order), the inputs likewise, ``power``; :data:`TRAJECTORY_COLUMNS` for an
    all-MEDUSA fleet. A plan with a depth profile (``[mission] altitude_m``) adds
    :data:`PROFILE_COLUMNS` at the end.

    Examples
    --------
    >>> remus = (("north", "east", "psi", "u", "v", "r", "n_prop", "delta_rudder"),)
    >>> trajectory_columns(remus, (("c_prop", "c_rudder"),))[8:]
    ('n_ps', 'n_sb', 'n_prop', 'delta_rudder', 'c_ps', 'c_sb', 'c_prop', 'c_rudder', 'power')
    """
    return (
        "vehicle",
        "t",
        *union_names(state_names, STATE_NAMES),
        *union_names(input_names, INPUT_NAMES),
        "power",
        *(PROFILE_COLUMNS if has_profile else ()),
    )


def write_trajectories_csv(
    handle: TextIO,
    names: Sequence[str],
    time: FloatArray,
    states: FloatArray | Sequence[FloatArray],
    inputs: FloatArray | Sequence[FloatArray],
    power: Sequence[FloatArray],
    *,
    state_names: Sequence[Sequence[str]],
    input_names: Sequence[Sequence[str]],
    profiles: Sequence[tuple[FloatArray, FloatArray]] | None = None,
) -> None:
    """Write ``trajectories.csv`` (columns :func:`trajectory_columns`) into a text stream.

    Parameters
    ----------
    handle : text stream
        Where to write (a file opened with ``newline=""``, or a ``StringIO``).
    names : sequence of str
        Vehicle names, length ``n_vehicles``.
    time : ndarray of shape (n_t,)
        Time [s].
    states : sequence of ndarray of shape (n_t, n_x_i)
        Each vehicle's states named by ``state_names[i]`` (SI units, rev/s, rad).
    inputs : sequence of ndarray of shape (n_t - 1, n_u_i)
        Each vehicle's inputs named by ``input_names[i]``, held over each step.
    power : sequence of ndarray of shape (n_t,)
        Each vehicle's electrical power [W].
    state_names, input_names : sequence of sequence of str
        Each vehicle's own state and input names.
    profiles : sequence of (ndarray of shape (n_t,), ndarray of shape (n_t,)), optional
        Each vehicle's depth [m] (positive down) and altitude above the seabed [m], written
        as ``depth_m`` and ``altitude_m`` (a plan of ``[mission] altitude_m``).

    Raises
    ------
    InputError
        If an array does not match ``time``, ``names`` or its names.
    """
    n_t = time.size
    for index, name in enumerate(names):
        state_shape, input_shape = np.shape(states[index]), np.shape(inputs[index])
        if (
            state_shape != (n_t, len(state_names[index]))
            or input_shape != (n_t - 1, len(input_names[index]))
            or np.shape(power[index]) != (n_t,)
        ):
            raise InputError(
                f"inconsistent shapes for vehicle {name}: time ({n_t},), states {state_shape}, "
                f"inputs {input_shape}, power {np.shape(power[index])}"
            )
    columns = trajectory_columns(state_names, input_names, has_profile=profiles is not None)
    writer = csv.writer(handle)
    writer.writerow(columns)
    for index, name in enumerate(names):
        held = np.vstack([inputs[index], inputs[index][-1:]])
        series = {
            "t": time,
            **dict(zip(state_names[index], np.transpose(states[index]), strict=True)),
            **dict(zip(input_names[index], held.T, strict=True)),
            "power": power[index],
            **(
                {} if profiles is None else dict(zip(PROFILE_COLUMNS, profiles[index], strict=True))
            ),
        }
        for k in range(n_t):
            writer.writerow(
                [name, *(repr(float(series[c][k])) if c in series else "" for c in columns[1:])]
            )


def read_trajectories_csv(path: Path) -> dict[str, dict[str, FloatArray]]:
    """Read ``trajectories.csv``: per vehicle (file order), each numeric column by name.

    Empty cells (a state the vehicle does not have) read as NaN.

    Raises
    ------
    DataFormatError
        If the file cannot be read, its header lacks a column of :data:`TRAJECTORY_COLUMNS`
        or a cell is not a number.
    """
    import pandas as pd

    try:
        table = pd.read_csv(path, dtype={"vehicle": str}, keep_default_na=False, na_values=[""])
    except (OSError, ValueError) as error:
        raise DataFormatError(f"{path}: unreadable CSV ({error})") from None
    missing = [column for column in TRAJECTORY_COLUMNS if column not in table.columns]
    if missing or table.columns[0] != "vehicle":
        raise DataFormatError(
            f"{path}: header is not vehicle,t,… with {','.join(TRAJECTORY_COLUMNS[1:])}"
        )
    try:
        return {
            str(name): {
                column: rows[column].to_numpy(dtype=np.float64) for column in table.columns[1:]
            }
            for name, rows in table.groupby("vehicle", sort=False)
        }
    except ValueError as error:
        raise DataFormatError(f"{path}: a value is not a number ({error})") from None


def write_desired_csv(
    path: Path, names: Sequence[str], time: FloatArray, poses: Sequence[FloatArray]
) -> None:
    """Write ``desired.csv``; ``poses[i]`` ``(n_t, 3)`` is north, east [m], psi [rad]."""
    with writing(path), path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(DESIRED_COLUMNS)
        for index, name in enumerate(names):
            block = np.column_stack([time, poses[index]])
            writer.writerows([name, *(repr(float(value)) for value in row)] for row in block)


def write_paths_geojson(
    path: Path,
    names: Sequence[str],
    paths: Sequence[FloatArray],
    projection: LocalProjection | None,
    properties: Sequence[Mapping[str, Any]] | None = None,
) -> None:
    """Write the planned paths as a GeoJSON ``FeatureCollection`` of ``LineString`` features.

    With a projection, coordinates are ``[lon, lat]`` (RFC 7946, WGS84). Without one (synthetic
    terrain) they are local ``[east, north]`` metres and the collection says so in its
    ``"crs_note"`` member, since RFC 7946 has no local-CRS member.
    """
    features = []
    for index, (name, points) in enumerate(zip(names, paths, strict=True)):
        if projection is None:
            coordinates = np.column_stack([points[:, 1], points[:, 0]])
        else:
            lat, lon = projection.to_geographic(points[:, 0], points[:, 1])
            coordinates = np.column_stack([lon, lat])
        feature_properties = {"name": name}
        if properties is not None:
            feature_properties.update(properties[index])
        features.append(
            {
                "type": "Feature",
                "properties": feature_properties,
                "geometry": {"type": "LineString", "coordinates": coordinates},
            }
        )
    collection: dict[str, Any] = {"type": "FeatureCollection", "features": features}
    if projection is None:
        collection["crs_note"] = "local frame: [east, north] in metres from the map origin"
    write_json(collection, path)
