"""The mission file (TOML), declared once as pydantic models (SPEC §8).

This is the "friendly shell": each key is declared here exactly once, with its type, default,
physical range, unit and TOML name; nothing else in auvplan repeats a default. Everything a
model exposes is in SI units and radians (``heading_deg`` is read in degrees and offered as
``psi`` in radians, reduced to ``(-π, π]``). Every problem a user can cause raises
:class:`~auvplan.errors.InputError` with one line naming the key path
(``vehicle[2].start.north``) and the offending value. Checks that need the terrain (poses on
land, outside the map) or the vehicle model (speeds above top speed, horizon too short) are
made by the pipeline stages. ``auvplan keys`` prints the reference of every key generated
from these models (:mod:`auvplan.mission.keys`).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any, Final, TypeVar

from pydantic import Field, ValidationError, model_validator

from auvplan.errors import InputError
from auvplan.io.tables import TableModel, one_line
from auvplan.io.text import read_toml
from auvplan.mission.tables import (
    AreaConfig,
    CommConfig,
    CurrentConfig,
    DeconflictionConfig,
    ExecutionConfig,
    FleetConfig,
    GoalPose,
    MapsConfig,
    MetadataConfig,
    NavigationConfig,
    ObstacleConfig,
    PlannerConfig,
    Position,
    SolverConfig,
    StartPose,
    TerrainConfig,
    VehicleConfig,
    WeightsConfig,
    WindowConfig,
)
from auvplan.record.labels import AREA_NAME

#: Most solver steps a mission may ask for (``horizon_s / dt_s``) before anything is allocated.
MAX_SOLVER_STEPS: Final = 200_000


class MissionConfig(TableModel):
    """A validated mission (SI units, radians). Built by :func:`load_mission`."""

    terrain: TerrainConfig
    maps: MapsConfig = Field(default_factory=MapsConfig)
    fleet: FleetConfig
    vehicles: tuple[VehicleConfig, ...] = Field(alias="vehicle", min_length=1, max_length=64)
    obstacles: tuple[ObstacleConfig, ...] = Field((), alias="obstacle", max_length=1000)
    area: AreaConfig | None = Field(None, description="operating area (absent: the whole map)")
    comms: tuple[CommConfig, ...] = Field((), alias="comm", max_length=1000)
    weights: WeightsConfig = Field(default_factory=WeightsConfig)
    planner: PlannerConfig = Field(default_factory=PlannerConfig)
    navigation: NavigationConfig = Field(default_factory=NavigationConfig)
    deconfliction: DeconflictionConfig = Field(default_factory=DeconflictionConfig)
    solver: SolverConfig = Field(default_factory=SolverConfig)
    mission: ExecutionConfig = Field(default_factory=ExecutionConfig)
    current: CurrentConfig | None = Field(None, description="ocean current (absent: still water)")
    metadata: MetadataConfig = Field(
        default_factory=MetadataConfig, description="who made the plan (trajectories.nc)"
    )
    source: Path | None = Field(None, exclude=True, description="the mission file (not a key)")

    @model_validator(mode="before")
    @classmethod
    def _default_vehicle_names(cls, data: Any) -> Any:
        vehicles = data.get("vehicle") if isinstance(data, dict) else None
        if isinstance(vehicles, list):
            data = {
                **data,
                "vehicle": [
                    {"name": f"vehicle{index + 1}", **table} if isinstance(table, dict) else table
                    for index, table in enumerate(vehicles)
                ],
            }
        return data

    @model_validator(mode="after")
    def _cross_checks(self) -> MissionConfig:
        names = [vehicle.name for vehicle in self.vehicles]
        labels = names + list(self.obstacle_names) + ([AREA_NAME] if self.area else [])
        repeated = sorted({label for label in labels if labels.count(label) > 1})
        if repeated:
            raise ValueError(f"vehicle and obstacle names must be unique: {', '.join(repeated)}")
        for index, comm in enumerate(self.comms):
            for name in comm.pair:
                if name not in names:
                    raise ValueError(f"comm[{index}].pair: no vehicle named {name!r}")
            if comm.pair[0] == comm.pair[1]:
                raise ValueError(f"comm[{index}].pair: a vehicle cannot pair with itself")
        if self.fleet.horizon is not None:
            steps = self.fleet.horizon / self.solver.dt
            if steps > MAX_SOLVER_STEPS:
                raise ValueError(
                    f"fleet.horizon_s / solver.dt_s = {steps:.3g} steps exceeds "
                    f"{MAX_SOLVER_STEPS}; use a larger solver.dt_s"
                )
        return self

    @property
    def obstacle_names(self) -> tuple[str, ...]:
        """Each obstacle's label: its ``name`` or ``"obstacle K"``."""
        return tuple(
            obstacle.name or f"obstacle {index}" for index, obstacle in enumerate(self.obstacles)
        )

    def vehicle_index(self, name: str) -> int:
        """Index of the vehicle called ``name``."""
        for index, vehicle in enumerate(self.vehicles):
            if vehicle.name == name:
                return index
        raise InputError(f"no vehicle named {name!r}")


def load_mission(path: Path | str) -> MissionConfig:
    """Read and validate a mission TOML file (paths inside it are relative to its folder).

    Raises
    ------
    DataFormatError
        The file is missing, unreadable or not valid TOML.
    InputError
        A key is unknown, missing, of the wrong type or out of range (the message names it).
    """
    path = Path(path)
    return parse_mission(read_toml(path, what="mission file"), base_dir=path.parent, source=path)


def demo_mission() -> MissionConfig:
    """The packaged demo mission (``auvplan demo``): the paper's scenario on the synthetic bank.

    Examples
    --------
    >>> [vehicle.name for vehicle in demo_mission().vehicles]
    ['blue', 'green']
    """
    from importlib import resources

    with resources.as_file(resources.files("auvplan") / "data/missions/demo.toml") as path:
        return load_mission(path)


def parse_mission(
    data: Mapping[str, Any], *, base_dir: Path = Path(), source: Path | None = None
) -> MissionConfig:
    """Validate an already-parsed TOML document (see :func:`load_mission`)."""
    try:
        config = MissionConfig.model_validate({**data, "source": source})
    except ValidationError as error:
        raise InputError(one_line(error, MissionConfig)) from None
    if config.terrain.file is not None and not config.terrain.file.is_absolute():
        terrain = config.terrain.model_copy(update={"file": base_dir / config.terrain.file})
        config = config.model_copy(update={"terrain": terrain})
    current = config.current
    if current is not None and current.file is not None and not current.file.is_absolute():
        current = current.model_copy(update={"file": base_dir / current.file})
        config = config.model_copy(update={"current": current})
    vehicles = tuple(_resolve_vehicle_file(vehicle, base_dir) for vehicle in config.vehicles)
    obstacles = tuple(_beside(obstacle, base_dir) for obstacle in config.obstacles)
    area = None if config.area is None else _beside(config.area, base_dir)
    return config.model_copy(update={"vehicles": vehicles, "obstacles": obstacles, "area": area})


def resolved_document(config: MissionConfig) -> dict[str, Any]:
    """The mission as a TOML document: every default filled in, every file path absolute.

    :func:`parse_mission` of the document gives back ``config`` (less its ``source``). An
    output folder's ``mission.toml`` is this document with every file one of the folder's
    (:func:`auvplan.mission.carry.carried_mission`), so that ``auvplan plan
    OUTPUT/mission.toml`` runs the same mission (same start time) from any copy of the folder.

    Examples
    --------
    >>> config = parse_mission({
    ...     "terrain": {"synthetic": True},
    ...     "fleet": {"horizon_s": 60.0, "safety_radius_m": 5.0},
    ...     "vehicle": [{"start": {"north": 10.0, "east": 400.0},
    ...                  "goal": {"north": 40.0, "east": 400.0}}]})
    >>> document = resolved_document(config)
    >>> document["maps"]["w"], document["vehicle"][0]["name"], document["solver"]["dt_s"]
    (10.0, 'vehicle1', 0.5)
    >>> parse_mission(document) == config
    True
    """
    from auvplan.io.vehicles import packaged_vehicle_types

    document: dict[str, Any] = config.model_dump(by_alias=True, exclude_none=True)
    for table in document["vehicle"]:
        if table["type"] not in packaged_vehicle_types():  # a vehicle file, as load_vehicle
            table["type"] = str(Path(table["type"]).resolve())
    return {key: _toml_values(value) for key, value in document.items()}


def _toml_values(value: Any) -> Any:
    """Tuples as arrays and paths as absolute strings (TOML has neither)."""
    if isinstance(value, dict):
        return {key: _toml_values(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_toml_values(item) for item in value]
    if isinstance(value, Path):
        return str(value.resolve())
    return value


_GisTable = TypeVar("_GisTable", ObstacleConfig, AreaConfig)


def _beside(table: _GisTable, base_dir: Path) -> _GisTable:
    """``table`` with a relative GIS ``file`` made relative to the mission's folder."""
    if table.file is None or table.file.is_absolute():
        return table
    return table.model_copy(update={"file": base_dir / table.file})


def _resolve_vehicle_file(vehicle: VehicleConfig, base_dir: Path) -> VehicleConfig:
    """A ``type`` naming an existing file next to the mission is made absolute."""
    candidate = base_dir / vehicle.type
    if vehicle.type.endswith(".toml") and candidate.is_file():
        return vehicle.model_copy(update={"type": str(candidate)})
    return vehicle


__all__ = [
    "AREA_NAME",
    "AreaConfig",
    "CommConfig",
    "CurrentConfig",
    "DeconflictionConfig",
    "ExecutionConfig",
    "FleetConfig",
    "GoalPose",
    "MapsConfig",
    "MetadataConfig",
    "MissionConfig",
    "NavigationConfig",
    "ObstacleConfig",
    "PlannerConfig",
    "Position",
    "SolverConfig",
    "StartPose",
    "TerrainConfig",
    "VehicleConfig",
    "WeightsConfig",
    "WindowConfig",
    "demo_mission",
    "load_mission",
    "parse_mission",
    "resolved_document",
]
