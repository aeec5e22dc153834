"""The missions a sweep starts from: one mission file, or the public scenario family by seed."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Final

from auvplan.io.text import read_toml
from auvplan.mission.config import parse_mission
from auvplan.scenarios import Scenario, generate
from auvplan.scenarios.family import MISSION_FILE
from auvplan.sweep.spec import MissionBase

#: Folder of the generated scenario missions inside the sweep's output folder.
SCENARIOS_FOLDER: Final = "scenarios"


def mission_file_base(path: Path) -> MissionBase:
    """The mission file as a sweep's base, validated as ``auvplan plan`` would.

    Raises
    ------
    DataFormatError
        The file is missing or not TOML.
    InputError
        The mission is invalid (the message names the key).
    """
    path = Path(path).resolve()
    document = read_toml(path, what="mission file")
    parse_mission(document, base_dir=path.parent, source=path)
    return MissionBase(document, path.parent, path, path.name)


def scenario_bases(
    seeds: Sequence[int], directory: Path, *, data_dir: Path | None = None
) -> dict[int, tuple[MissionBase, Scenario]]:
    """Each seed's generated scenario (:func:`auvplan.scenarios.generate`), not yet written.

    Its base folder is ``directory/scenarios/seed_NNNN`` (absolute), where
    :meth:`~auvplan.scenarios.Scenario.write` puts the mission (and a generated terrain)
    before the runs start.
    """
    bases = {}
    for seed in seeds:
        scenario = generate(seed, data_dir=data_dir)
        folder = (Path(directory) / SCENARIOS_FOLDER / f"seed_{seed:04d}").resolve()
        base = MissionBase(scenario.mission, folder, folder / MISSION_FILE, f"scenario {seed}")
        bases[seed] = (base, scenario)
    return bases


__all__ = ["SCENARIOS_FOLDER", "mission_file_base", "scenario_bases"]
