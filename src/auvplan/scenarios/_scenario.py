"""The record of a generated scenario and what every family kind shares with the others.

:class:`Scenario` is what :func:`auvplan.scenarios.generate` returns, whatever the kind
(``"reliability"``: :mod:`auvplan.scenarios.family`; ``"transit"``:
:mod:`auvplan.scenarios.transit`).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final

import numpy as np
import tomli_w

from auvplan._typing import FloatArray
from auvplan.record.files import MISSION_FILE
from auvplan.scenarios import _terrain
from auvplan.scenarios._plain import Feature
from auvplan.terrain import BathymetryGrid

#: ``(largest horizon [s], dt_s)``: the step a user picks for a mission of that length.
DT_BY_HORIZON: Final = ((900.0, 0.5), (3000.0, 1.0), (math.inf, 2.0))
VEHICLE_NAMES: Final = ("blue", "green", "orange", "purple", "red", "cyan")
#: What a transit scenario's terrain holds beside the vehicles' lines (:attr:`Scenario.features`).
FEATURE_CLASSES: Final = ("flat", "offset", "real")


@dataclass(frozen=True)
class Scenario:
    """One generated mission.

    ``mission`` is the TOML document as a dict (a real grid's ``terrain.file`` is absolute;
    :meth:`write` makes it relative to the scenario folder). ``synthetic_terrain`` is written
    next to the mission as ``terrain.nc`` when the terrain is generated.

    ``kind`` is the family kind that drew it. Transit scenarios also set ``features`` (one of
    :data:`FEATURE_CLASSES`: ``"flat"`` a plain without any feature, ``"offset"`` a plain
    with rough ``relief`` features beside the line, ``"real"`` a window of a real grid),
    ``distance_m`` (the straight start-goal distance [m], the same for every vehicle) and
    ``feature_offsets_m`` (each feature's perpendicular offset [m] from the nearest vehicle
    line on its side; empty unless ``features == "offset"``). Reliability scenarios leave
    them ``None`` / empty.
    """

    seed: int
    mission: dict[str, Any]
    terrain: str
    n_vehicles: int
    horizon_s: float
    dt_s: float
    description: str
    synthetic_terrain: BathymetryGrid | None = field(default=None, repr=False)
    kind: str = "reliability"
    features: str | None = None
    distance_m: float | None = None
    feature_offsets_m: tuple[float, ...] = ()
    relief: tuple[Feature, ...] = field(default=(), repr=False)

    @property
    def flat(self) -> bool:
        """True for a transit scenario over a featureless plain (``features == "flat"``)."""
        return self.features == "flat"

    def toml(self, folder: Path | None = None) -> str:
        """The mission file's text; a real grid's path is relative to ``folder`` if given."""
        document = dict(self.mission)
        terrain = dict(document["terrain"])
        if folder is not None and "file" in terrain and Path(terrain["file"]).is_absolute():
            terrain["file"] = os.path.relpath(terrain["file"], Path(folder).resolve())
        document["terrain"] = terrain
        header = f"# auvplan scenario {self.seed}: {self.description}\n\n"
        return header + tomli_w.dumps(document)

    def write(self, folder: Path | str) -> Path:
        """Write ``mission.toml`` (and ``terrain.nc`` if generated) into ``folder``; its path."""
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        if self.synthetic_terrain is not None:
            _terrain.write_synthetic_terrain(
                self.synthetic_terrain, folder / _terrain.SYNTHETIC_FILE
            )
        path = folder / MISSION_FILE
        path.write_text(self.toml(folder), encoding="utf-8")
        return path


def position_table(point: FloatArray, drawn: _terrain.DrawnTerrain) -> dict[str, float]:
    """A point (north, east) [m] as ``{lat, lon}`` on geographic terrain, else ``{north, east}``."""
    projection = drawn.grid.projection
    if projection is None:
        return {"north": round(float(point[0]), 2), "east": round(float(point[1]), 2)}
    lat, lon = projection.to_geographic(np.array([point[0]]), np.array([point[1]]))
    return {"lat": round(float(lat[0]), 7), "lon": round(float(lon[0]), 7)}
