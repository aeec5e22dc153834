"""The inputs an output folder carries, so that it reruns wherever it is copied.

``auvplan plan DIR/mission.toml -o NEW`` plans the same mission after ``DIR`` was moved or
copied to another machine without the original input files. The folder's ``mission.toml``
therefore names only files inside the folder, relative to itself (:func:`parse_mission`
reads paths relative to the mission file's folder):

* a bathymetry ``file`` becomes ``maps.nc``: the folder's own grid, already cropped to the
  window and in the local frame, which :func:`~auvplan.io.bathymetry.read_bathymetry` reads
  back node for node (the same depths, spacings and local frame); the window is dropped. A
  packaged ``sample`` and the synthetic bank need nothing;
* each vehicle file is copied byte for byte into ``inputs/``, with the propeller tables it
  names at the same place relative to it. A table named by an absolute path or from outside
  the vehicle file's folder is copied beside it, and the copy of the vehicle file (written
  again from its TOML document, without its comments) names it so;
* a current file, a GIS ``file`` of ``[[obstacle]]`` or ``[area]`` (a Shapefile with the
  files of its stem), and the file of any key added later, is copied into ``inputs/``.

A different file of a name already taken goes to ``inputs/2/``, ``inputs/3/``, …
"""

from __future__ import annotations

import glob
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import Any

from pydantic import BaseModel

from auvplan.io._propeller_tables import propeller_table_file
from auvplan.io.text import read_bytes, read_toml, toml_text
from auvplan.io.vehicles import packaged_vehicle_types
from auvplan.mission.config import MissionConfig, TerrainConfig, resolved_document
from auvplan.record.files import INPUTS_FOLDER, MAPS_FILE


@dataclass(frozen=True)
class CarriedMission:
    """A mission as its output folder holds it.

    Parameters
    ----------
    document : dict
        ``mission.toml``: the resolved mission (:func:`resolved_document`) whose files are
        the folder's own, named relative to it.
    files : dict of str to bytes
        The carried input files: path relative to the folder (POSIX) -> content.
    """

    document: dict[str, Any]
    files: dict[str, bytes]


def carried_mission(config: MissionConfig) -> CarriedMission:
    """The mission document and input files of ``config``'s output folder (module notes).

    Raises
    ------
    DataFormatError
        If an input file can no longer be read (one line naming it).
    """
    document = resolved_document(config)
    files: dict[str, bytes] = {}
    if config.terrain.file is not None:
        document["terrain"] = {**document["terrain"], "file": MAPS_FILE, "window": {}}
    _carry_paths(config, document, files)
    for table, vehicle in zip(document["vehicle"], config.vehicles, strict=True):
        if vehicle.type not in packaged_vehicle_types():
            table["type"] = _carry_vehicle(files, Path(vehicle.type))
    return CarriedMission(document, files)


def _carry_paths(model: BaseModel, table: dict[str, Any], files: dict[str, bytes]) -> None:
    """Copy each file a key of ``model`` names into ``files``; ``table`` names the copy.

    ``table`` is ``model``'s document. Every key whose value is a :class:`~pathlib.Path`
    (``current.file``, and any file key added later), in the tables and arrays of tables
    below ``model``; the terrain is the folder's ``maps.nc`` (:func:`carried_mission`).
    """
    for name, field in type(model).model_fields.items():
        value, key = getattr(model, name), field.alias or name
        if key not in table or isinstance(value, TerrainConfig):  # not a key, or maps.nc
            continue
        if isinstance(value, Path):
            bundle = {part.name: read_bytes(part, what="input file") for part in _parts(value)}
            table[key] = f"{_place(files, bundle)}/{value.name}"
        elif isinstance(value, BaseModel):
            _carry_paths(value, table[key], files)
        elif isinstance(value, tuple):
            for item, entry in zip(value, table[key], strict=True):
                if isinstance(item, BaseModel):
                    _carry_paths(item, entry, files)


def _parts(path: Path) -> list[Path]:
    """The files read as ``path``: the file alone, or for a Shapefile the files of its stem.

    A Shapefile is its ``.shp`` and the files of the same stem beside it (``.shx``, ``.dbf``,
    ``.prj``, ``.cpg``, …: ESRI Shapefile Technical Description, 1998).
    """
    if path.suffix.lower() != ".shp":
        return [path]
    return [path, *sorted(p for p in path.parent.glob(f"{glob.escape(path.stem)}.*") if p != path)]


def _carry_vehicle(files: dict[str, bytes], path: Path) -> str:
    """Add vehicle file ``path`` and its propeller tables to ``files``; the copy's path.

    The copy's name ends in ``.toml`` (a mission names a vehicle file by that suffix).
    """
    document = read_toml(path, what="vehicle file")
    name = f"{path.stem}.toml"
    bundle = {name: read_bytes(path, what="vehicle file")}
    rewritten = False
    holders = _table_holders(document)
    outside = [_escapes(holder["table"]) for holder in holders]
    # the tables kept in place first: a table moved beside the file takes a free name
    for holder, moved in sorted(zip(holders, outside, strict=True), key=lambda pair: pair[1]):
        source = propeller_table_file(holder["table"], path.parent)
        if source is None:  # a packaged table
            continue
        content = read_bytes(source, what="propeller table")
        if moved:
            holder["table"] = _free_name(bundle, source.name, content)
            rewritten = True
        bundle[PurePosixPath(holder["table"]).as_posix()] = content
    if rewritten:
        header = f"{path.name} as carried by auvplan: its propeller tables copied beside it"
        bundle[name] = toml_text(document, header=header).encode("utf-8")
    return f"{_place(files, bundle)}/{name}"


def _table_holders(document: dict[str, Any]) -> list[dict[str, Any]]:
    """The propeller tables of a vehicle file's document that name a ``table``.

    ``[propeller]`` of the twin-thruster shorthand and each ``[thruster.propeller]``
    (:class:`~auvplan.io.vehicle_tables.VehicleFile`).
    """
    thrusters = document.get("thruster", [])
    holders = [document.get("propeller")] + [
        thruster.get("propeller") for thruster in thrusters if isinstance(thruster, dict)
    ]
    return [
        holder
        for holder in holders
        if isinstance(holder, dict) and isinstance(holder.get("table"), str)
    ]


def _escapes(table: str) -> bool:
    """Whether a table path is absolute or leaves the vehicle file's folder."""
    path = PurePosixPath(table)
    return path.is_absolute() or ".." in path.parts


def _free_name(bundle: dict[str, bytes], name: str, content: bytes) -> str:
    """``name``, or ``K_name`` for the first K = 2, 3, … free in ``bundle``.

    A name that already holds ``content`` counts as free.
    """
    candidate, k = name, 1
    while bundle.get(candidate, content) != content:
        k += 1
        candidate = f"{k}_{name}"
    return candidate


def _place(files: dict[str, bytes], bundle: dict[str, bytes]) -> str:
    """Add ``bundle`` (names relative to one folder) to ``files``; that folder's path.

    ``inputs``, or ``inputs/K`` for the first K = 2, 3, … where no name holds other content.
    """
    folder, k = INPUTS_FOLDER, 1
    while True:
        placed = {f"{folder}/{name}": content for name, content in bundle.items()}
        if all(files.get(name, content) == content for name, content in placed.items()):
            files.update(placed)
            return folder
        k += 1
        folder = f"{INPUTS_FOLDER}/{k}"


__all__ = ["CarriedMission", "carried_mission"]
