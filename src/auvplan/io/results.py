"""Writers for the ``auvplan plan`` outputs (SPEC §8): JSON summary, CSV time series, GeoJSON.

The column sets are part of the user-facing contract and only ever grow:

* ``trajectories.csv``: ``vehicle,t,north,east,psi,u,v,r,n_ps,n_sb,c_ps,c_sb,power``
  (SI units, ``psi`` in rad, ``n_*`` in rev/s, ``power`` in W). Inputs are held constant over
  each step (zero-order hold); the last row of a vehicle repeats the last input, so that every
  row is complete.
* ``desired.csv``: ``vehicle,t,north,east,psi`` — the timed, deconflicted desired trajectories.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.terrain.projection import LocalProjection

TRAJECTORY_COLUMNS = (
    "vehicle", "t", "north", "east", "psi", "u", "v", "r", "n_ps", "n_sb", "c_ps", "c_sb", "power",
)  # fmt: skip
DESIRED_COLUMNS = ("vehicle", "t", "north", "east", "psi")


def write_json(data: Mapping[str, Any], path: Path) -> None:
    """Write ``data`` as indented JSON; numpy scalars/arrays become numbers/lists, NaN -> null."""
    text = json.dumps(json_values(data), indent=2, allow_nan=False)
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
        path.write_text(text, encoding="utf-8")
        written.append(path)
    return written


def write_trajectories_csv(
    path: Path,
    names: Sequence[str],
    time: FloatArray,
    states: FloatArray,
    inputs: FloatArray,
    power: FloatArray,
) -> None:
    """Write ``trajectories.csv``.

    Parameters
    ----------
    path : Path
        Output file.
    names : sequence of str
        Vehicle names, length ``n_vehicles``.
    time : ndarray of shape (n_t,)
        Time [s].
    states : ndarray of shape (n_vehicles, n_t, 8)
        ``(north, east, psi, u, v, r, n_ps, n_sb)`` in m, m, rad, m/s, m/s, rad/s, rev/s, rev/s.
    inputs : ndarray of shape (n_vehicles, n_t - 1, 2)
        ``(c_ps, c_sb)``, held over each step.
    power : ndarray of shape (n_vehicles, n_t)
        Electrical power [W].
    """
    n_vehicles, n_t, _ = states.shape
    if inputs.shape[:2] != (n_vehicles, n_t - 1) or power.shape != (n_vehicles, n_t):
        raise InputError(
            f"inconsistent shapes: states {states.shape}, inputs {inputs.shape}, "
            f"power {power.shape}"
        )
    held = np.concatenate([inputs, inputs[:, -1:, :]], axis=1)
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(TRAJECTORY_COLUMNS)
        for index, name in enumerate(names):
            block = np.column_stack([time, states[index], held[index], power[index]])
            writer.writerows([name, *(repr(float(value)) for value in row)] for row in block)


def read_trajectories_csv(path: Path) -> dict[str, dict[str, FloatArray]]:
    """Read ``trajectories.csv``: per vehicle (file order), each numeric column by name.

    Raises
    ------
    DataFormatError
        If the file cannot be read or its header is not :data:`TRAJECTORY_COLUMNS`.
    """
    import pandas as pd

    try:
        table = pd.read_csv(path, dtype={"vehicle": str}, keep_default_na=False)
    except (OSError, ValueError) as error:
        raise DataFormatError(f"{path}: unreadable CSV ({error})") from None
    if tuple(table.columns) != TRAJECTORY_COLUMNS:
        raise DataFormatError(f"{path}: header is not {','.join(TRAJECTORY_COLUMNS)}")
    try:
        return {
            str(name): {
                column: rows[column].to_numpy(dtype=np.float64) for column in TRAJECTORY_COLUMNS[1:]
            }
            for name, rows in table.groupby("vehicle", sort=False)
        }
    except ValueError as error:
        raise DataFormatError(f"{path}: a value is not a number ({error})") from None


def write_desired_csv(
    path: Path, names: Sequence[str], time: FloatArray, poses: FloatArray
) -> None:
    """Write ``desired.csv``; ``poses`` ``(n_vehicles, n_t, 3)`` is north, east [m], psi [rad]."""
    with path.open("w", newline="", encoding="utf-8") as handle:
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
