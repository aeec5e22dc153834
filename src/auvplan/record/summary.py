"""``summary.json`` as a typed document: :class:`PlanSummary` (SPEC §8).

The model types every entry a reader of the output folder relies on (the vehicles, their
state names and top speed, the terrain's origin, the fleet's safety radius, the obstacles,
each plan's status and per-vehicle energy, the digest) and keeps every other entry as it
was written (``extra="allow"``), so the document written is the document read:
``PlanSummary.model_validate(document).document() == document``. Entries are only added,
never renamed.
"""

from __future__ import annotations

from datetime import datetime
from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    model_validator,
)

from auvplan.errors import DataFormatError
from auvplan.record.files import PLAN_FILES


class _Entry(BaseModel):
    """A JSON object of ``summary.json``: typed keys, other keys kept as written."""

    model_config = ConfigDict(extra="allow", frozen=True)


def _iso_time(text: str) -> str:
    datetime.fromisoformat(text)  # ValueError: a validation error naming the key
    return text


class Place(_Entry):
    """A point of the local frame [m], with WGS 84 ``lat``/``lon`` [deg] when georeferenced.

    Every coordinate is finite, and ``lat``/``lon`` are on the Earth: a NaN origin would
    otherwise reach the exports (``LatOrigin = nan``) or pyproj (a CRSError).
    """

    model_config = ConfigDict(allow_inf_nan=False)

    north: float
    east: float
    lat: float | None = Field(default=None, ge=-90.0, le=90.0)
    lon: float | None = Field(default=None, ge=-180.0, le=360.0)


class Pose(_Entry):
    """A start or goal pose: ``north``, ``east`` [m], ``heading_rad`` [rad]."""

    north: float
    east: float
    heading_rad: float


class TerrainSummary(_Entry):
    """``terrain``: the terrain's name and the local frame's origin (and grid, map settings)."""

    name: str
    origin: Place


class CircleObstacle(_Entry):
    """A circular keep-out zone: ``center`` and ``radius_m`` [m]."""

    name: str
    shape: Literal["circle"]
    center: Place
    radius_m: float


class PolygonObstacle(_Entry):
    """A polygonal keep-out zone: its ``vertices`` and ``holes`` (rings of free water)."""

    name: str
    shape: Literal["polygon"]
    vertices: list[Place]
    holes: list[list[Place]] = []


class AreaObstacle(_Entry):
    """The operating area, kept in: its ``vertices`` and ``holes`` (rings of no-go islands)."""

    name: str
    shape: Literal["area"]
    vertices: list[Place]
    holes: list[list[Place]] = []


Obstacle = Annotated[CircleObstacle | PolygonObstacle | AreaObstacle, Field(discriminator="shape")]


class FleetSummary(_Entry):
    """``fleet``: safety radius [m], edge model and deconfliction method."""

    safety_radius_m: float
    edge_model: str
    deconfliction_method: str
    max_current_m_s: float | None = None


class VehicleSummary(_Entry):
    """One entry of ``vehicles``: name, type, poses, pre-plan and (after stage 2) timing.

    After deconfliction also ``type_name`` (the name its vehicle file gives the type), the
    vehicle's own ``state_names`` and ``input_names`` (the columns of its rows in
    ``trajectories.csv``) and its ``top_speed_m_s`` [m/s], with which the reader bounds the
    rows' speeds and steps, and its ``battery_capacity_J`` [J] (None: unknown).
    """

    name: str
    type: str
    start: Pose
    goal: Pose
    preplan: dict[str, Any]
    timing: dict[str, Any] | None = None
    type_name: str | None = None
    state_names: tuple[str, ...] | None = None
    input_names: tuple[str, ...] | None = None
    top_speed_m_s: float | None = Field(default=None, gt=0.0)
    battery_capacity_J: float | None = Field(default=None, gt=0.0)


class VehicleOutcome(_Entry):
    """A vehicle's figures in a plan record: energy [J], mean terrain information [-].

    With a known battery capacity ``C``, ``energy_remaining_J`` = ``C − energy_J`` [J] and
    ``energy_remaining_fraction`` = ``(C − energy_J) / C`` [-] (None: capacity unknown).
    """

    energy_J: float
    mean_terrain_information: float | None
    energy_remaining_J: float | None = None
    energy_remaining_fraction: float | None = None


class PlanOutcome(_Entry):
    """A plan's record (``optimization``, ``energy_only``, ``paper``): status and figures.

    A plan whose optimiser failed has only ``plan_status`` (``"FAILED"``) and ``verdict``.
    ``fleet_solve`` is ``"coupled"`` or ``"decomposed"`` (``solver.fleet``; None in folders
    written before it was recorded).
    """

    terrain_weight: float | None = None
    plan_status: str
    verdict: str
    violations: list[Any] | None = None
    status: str | None = None
    message: str | None = None
    fleet_solve: str | None = None
    n_iter: int | None = None
    cost: float | None = None
    history: list[Any] | None = None
    vehicles: dict[str, VehicleOutcome] | None = None
    total_energy_J: float | None = None


class PlanSummary(_Entry):
    """The ``summary.json`` document (module notes); entries in the order they are written.

    ``digest`` maps each data file of the run to the SHA-256 of its content
    (:func:`auvplan.record.files_digest`): the reader refuses files that another run wrote.
    ``created`` is the UTC time the run made its record (ISO 8601; ``None`` in folders written
    before it was recorded).
    """

    auvplan_version: str
    created: Annotated[str, AfterValidator(_iso_time)] | None = None
    mission: str | None
    inputs: dict[str, Any]
    start_time: Annotated[str, AfterValidator(_iso_time)]
    stage: Literal["preplan", "deconflict", "full"]
    terrain: TerrainSummary
    obstacles: list[Obstacle]
    current: dict[str, Any] | None
    fleet: FleetSummary
    solver: dict[str, Any]
    vehicles: list[VehicleSummary]
    wall_time_s: dict[str, float]
    warnings: list[str]
    deconfliction: dict[str, Any] | None = None
    optimization: PlanOutcome | None = None
    energy_only: PlanOutcome | None = None
    paper: PlanOutcome | None = None
    current_comparison: dict[str, Any] | None = None
    digest: dict[str, str] | None = None

    @model_validator(mode="after")
    def _unique_names(self) -> PlanSummary:
        names = [vehicle.name for vehicle in self.vehicles]
        twice = next((name for name in names if names.count(name) > 1), None)
        if twice is not None:
            raise ValueError(f"vehicle name {twice!r} appears twice")
        return self

    @property
    def start(self) -> datetime:
        """UTC time of ``t = 0`` of the plan."""
        return datetime.fromisoformat(self.start_time)

    @property
    def created_at(self) -> datetime | None:
        """UTC time the run made its record, if recorded."""
        return None if self.created is None else datetime.fromisoformat(self.created)

    @property
    def names(self) -> tuple[str, ...]:
        """The vehicles' names, in mission order."""
        return tuple(vehicle.name for vehicle in self.vehicles)

    def outcome(self, label: str) -> PlanOutcome | None:
        """The record of plan ``label`` (a key of :data:`~auvplan.record.files.PLAN_FILES`)."""
        outcome: PlanOutcome | None = getattr(self, PLAN_FILES[label].record)
        return outcome

    def document(self) -> dict[str, Any]:
        """The document as plain JSON values, as ``summary.json`` holds it."""
        return self.model_dump(mode="json", exclude_unset=True)


def parse_summary(document: object, *, source: str) -> PlanSummary:
    """Validate a ``summary.json`` document; ``source`` names it in the error.

    Raises
    ------
    DataFormatError
        If ``document`` is not an object or an entry is missing or of the wrong type; one
        line naming ``source`` and the entry (``vehicles.0.name``).

    Examples
    --------
    >>> parse_summary([], source="summary.json")
    Traceback (most recent call last):
    ...
    auvplan.errors.DataFormatError: summary.json: not a JSON object (a list)
    """
    if not isinstance(document, dict):
        raise DataFormatError(f"{source}: not a JSON object (a {type(document).__name__})")
    try:
        return PlanSummary.model_validate(document)
    except ValidationError as error:
        first = error.errors()[0]
        where = ".".join(str(part) for part in first["loc"]) or "(document)"
        problem = "missing" if first["type"] == "missing" else first["msg"].lower()
        raise DataFormatError(f"{source}: entry {where}: {problem}") from None


__all__ = [
    "AreaObstacle",
    "CircleObstacle",
    "FleetSummary",
    "Obstacle",
    "PlanOutcome",
    "PlanSummary",
    "PolygonObstacle",
    "TerrainSummary",
    "VehicleOutcome",
    "VehicleSummary",
    "parse_summary",
]
