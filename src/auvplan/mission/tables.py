"""The tables of the mission file as pydantic models.

Each key has one home here: its type, default, physical range, unit and TOML name
(:mod:`auvplan.mission.config` assembles the whole mission).
"""

from __future__ import annotations

import dataclasses
import math
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Final, Literal

from pydantic import (
    Discriminator,
    Field,
    SerializerFunctionWrapHandler,
    Strict,
    Tag,
    field_validator,
    model_serializer,
    model_validator,
)

from auvplan.errors import InputError
from auvplan.io.samples import SampleName, sample_path
from auvplan.io.tables import Flag, Integer, Number, TableModel, Text
from auvplan.optimization import ProntoOptions

if TYPE_CHECKING:  # the navigation package (numba kernels) loads only when a run needs it
    from auvplan.navigation import NavigationSettings

Interval = tuple[Number, Number]
BlockSize = Annotated[int, Strict(), Field(ge=1, le=256)]

#: Characters that would break CSV rows or labels in a vehicle or obstacle name.
FORBIDDEN_NAME_CHARACTERS: Final = ",\n\"'"

_SOLVER_DEFAULTS: Final = ProntoOptions()
#: Fleet size from which ``solver.fleet = "auto"`` solves vehicle by vehicle.
DECOMPOSED_FROM: Final = 8
#: Smallest safety radius r_c [m]: two vehicles kept 2 cm apart would already touch (no hull
#: is that small), and the deconfliction's time step, which must move a vehicle less than
#: 2 r_c, would shrink towards nothing.
MIN_SAFETY_RADIUS: Final = 0.01
#: Years a start time may fall in (timestamps stay within numpy's datetime64[ns] range).
START_YEARS: Final = (1900, 2200)


def _unit(unit: str) -> dict[str, Any]:
    return {"unit": unit}


def _check_interval(value: Interval | None, key: str) -> None:
    if value is not None and not value[0] < value[1]:
        raise ValueError(f"{key}: low must be < high, got {list(value)}")


class WindowConfig(TableModel):
    """Crop of the terrain: ``(low, high)`` in metres (north/east) or degrees (lat/lon)."""

    north: Interval | None = Field(None, description="north range", json_schema_extra=_unit("m"))
    east: Interval | None = Field(None, description="east range", json_schema_extra=_unit("m"))
    lat: Interval | None = Field(None, description="latitude range", json_schema_extra=_unit("deg"))
    lon: Interval | None = Field(
        None, description="longitude range", json_schema_extra=_unit("deg")
    )

    @model_validator(mode="after")
    def _consistent(self) -> WindowConfig:
        for key in ("north", "east", "lat", "lon"):
            _check_interval(getattr(self, key), key)
        if (self.north or self.east) and (self.lat or self.lon):
            raise ValueError("use north/east or lat/lon, not both")
        return self

    @property
    def is_geographic(self) -> bool:
        """True when the window is given in lat/lon."""
        return self.lat is not None or self.lon is not None


class TerrainConfig(TableModel):
    """Where the bathymetry comes from: a file (next to the mission), a sample or the bank."""

    file: Path | None = Field(
        None, description="bathymetry file: NetCDF, GeoTIFF, ESRI ASCII or XYZ"
    )
    sample: SampleName | None = Field(
        None, description="a real grid shipped with auvplan: monterey, balanus or lisbon"
    )
    synthetic: Flag = Field(False, description="use the built-in synthetic volcanic bank")
    seed: Integer = Field(7, ge=0, le=2**32 - 1, description="seed of the synthetic bank")
    window: WindowConfig = Field(default_factory=WindowConfig, description="crop of the grid")

    @model_validator(mode="after")
    def _one_source(self) -> TerrainConfig:
        if [self.file is not None, self.sample is not None, self.synthetic].count(True) != 1:
            raise ValueError(
                "give a bathymetry file = '...', a sample = '...' or synthetic = true (one of them)"
            )
        return self

    @property
    def path(self) -> Path | None:
        """The bathymetry file read: ``file``, or the packaged sample's (None: the bank)."""
        return sample_path(self.sample) if self.sample is not None else self.file


class MapsConfig(TableModel):
    """Map parameters (paper eq. 13-15)."""

    exponent: Number = Field(1.0, alias="s", gt=0.0, le=10.0, description="exponent s (eq. 13)")
    block: tuple[BlockSize, BlockSize] = Field(
        (2, 2), description="excitation block (r_n, r_e) (eq. 14)", json_schema_extra=_unit("cells")
    )
    omega: Number = Field(10.0, gt=0.0, le=1e4, description="admissibility shift ω (eq. 15)")
    weight: Number = Field(10.0, alias="w", ge=0.0, le=1e4, description="cost weight w (eq. 15)")


class FleetConfig(TableModel):
    """Fleet-wide timing and safety."""

    horizon: Number | None = Field(
        None, alias="horizon_s", gt=0.0, le=172_800.0, description="common arrival time T",
        json_schema_extra=_unit("s"),
    )  # fmt: skip
    cruise_speed: Number | None = Field(
        None, ge=0.05, le=10.0, description="nominal speed; the horizon is derived from it",
        json_schema_extra=_unit("m/s"),
    )  # fmt: skip
    safety_radius: Number = Field(
        alias="safety_radius_m", ge=MIN_SAFETY_RADIUS, le=1000.0,
        description="r_c; every pair keeps >= 2 r_c", json_schema_extra=_unit("m"),
    )  # fmt: skip

    @model_validator(mode="after")
    def _one_timing(self) -> FleetConfig:
        if (self.horizon is None) == (self.cruise_speed is None):
            raise ValueError("give exactly one of horizon_s and cruise_speed")
        return self


class Position(TableModel):
    """A horizontal position: ``north, east`` [m] in the map frame, or ``lat, lon`` [deg]."""

    north: Number | None = Field(
        None, ge=-1e7, le=1e7, description="north of the map origin", json_schema_extra=_unit("m")
    )
    east: Number | None = Field(
        None, ge=-1e7, le=1e7, description="east of the map origin", json_schema_extra=_unit("m")
    )
    lat: Number | None = Field(
        None, ge=-90.0, le=90.0, description="latitude (WGS 84)", json_schema_extra=_unit("deg")
    )
    lon: Number | None = Field(
        None, ge=-180.0, le=360.0, description="longitude (WGS 84)", json_schema_extra=_unit("deg")
    )

    @model_validator(mode="after")
    def _one_pair(self) -> Position:
        local = (self.north is not None, self.east is not None)
        geographic = (self.lat is not None, self.lon is not None)
        if any(local) == any(geographic):
            raise ValueError("give north and east (m) or lat and lon (deg)")
        if not (all(local) or all(geographic)):
            raise ValueError("both coordinates are required")
        return self

    @property
    def is_geographic(self) -> bool:
        """True when given as latitude/longitude."""
        return self.lat is not None

    @property
    def coordinates(self) -> tuple[float, float]:
        """``(north, east)`` [m], or ``(lat, lon)`` [deg] when :attr:`is_geographic`."""
        pair = (self.lat, self.lon) if self.is_geographic else (self.north, self.east)
        if pair[0] is None or pair[1] is None:  # excluded by the validator
            raise InputError("position: both coordinates are required")
        return pair[0], pair[1]


class GoalPose(Position):
    """A position with a heading (degrees clockwise from north in the file)."""

    heading_deg: Number = Field(
        0.0, ge=-360.0, le=360.0, description="heading, clockwise from north",
        json_schema_extra=_unit("deg"),
    )  # fmt: skip

    @property
    def psi(self) -> float:
        """Heading [rad] reduced to ``(-π, π]``."""
        return math.remainder(math.radians(self.heading_deg), 2.0 * math.pi)


class StartPose(GoalPose):
    """The start pose and surge speed (checked against the vehicle's top speed later)."""

    speed: Number = Field(
        0.0, ge=0.0, le=10.0, description="surge speed", json_schema_extra=_unit("m/s")
    )


def _check_name(name: str) -> None:
    if not name.strip() or any(ch in name for ch in FORBIDDEN_NAME_CHARACTERS):
        raise ValueError(f"{name!r} is not a usable name (no commas, quotes or line breaks)")


class VehicleConfig(TableModel):
    """One vehicle: name, type (packaged type or vehicle-file path), start and goal."""

    name: Text = Field(
        min_length=1, max_length=40, description="unique name (default vehicle1, vehicle2, ...)"
    )
    type: Text = Field("medusa", min_length=1, description="packaged type or vehicle TOML path")
    start: StartPose
    goal: GoalPose

    @model_validator(mode="after")
    def _usable(self) -> VehicleConfig:
        _check_name(self.name)
        return self


def _vertex_kind(value: Any) -> str:
    return "table" if isinstance(value, dict | Position) else "tuple[north, east]"


#: A polygon vertex: ``[north, east]`` [m], or a table ``{ lat = .., lon = .. }`` [deg]
#: (``{ north = .., east = .. }`` too); every vertex of a polygon in the same frame. The
#: tags route a bad vertex's error to its own form (``one_line`` drops the ``tuple[`` tag).
Vertex = Annotated[
    Annotated[tuple[Number, Number], Tag("tuple[north, east]")] | Annotated[Position, Tag("table")],
    Discriminator(_vertex_kind),
]

#: Description of the ``file`` key of ``[[obstacle]]`` and ``[area]``.
_GIS_FILE: Final = (
    "GIS file of polygons (holes kept), relative to the mission: GeoJSON, or with the gis "
    "extra a Shapefile, GeoPackage or KML (any CRS)"
)


class ObstacleConfig(TableModel):
    """A no-go zone: a circle (``center``, ``radius_m``), a ``polygon`` or a GIS ``file``.

    A ``file``'s every polygon and multipolygon part is a zone of its own, labelled
    ``"<name> feature K"`` (``K`` the feature's index in the file, ``K.P`` for part ``P``).
    """

    name: Text | None = Field(None, min_length=1, max_length=40, description="label (unique)")
    center: Position | None = None
    radius: Number | None = Field(
        None,
        alias="radius_m",
        gt=0.0,
        le=1e5,
        description="radius of a circle",
        json_schema_extra=_unit("m"),
    )
    polygon: tuple[Vertex, ...] | None = Field(
        None, description="vertices [north, east] (m) or { lat, lon } (deg)"
    )
    file: Path | None = Field(None, description=_GIS_FILE)
    layer: Text | None = Field(
        None, min_length=1, description="layer of a multi-layer GIS file (default: the first)"
    )

    @property
    def circle(self) -> tuple[Position, float]:
        """``(center, radius [m])`` of a circular obstacle."""
        if self.center is None or self.radius is None:
            raise InputError("obstacle: not a circle")
        return self.center, self.radius

    @model_validator(mode="after")
    def _shape(self) -> ObstacleConfig:
        if self.name is not None:
            _check_name(self.name)
        circle = self.center is not None or self.radius is not None
        if [circle, self.polygon is not None, self.file is not None].count(True) > 1:
            raise ValueError("give center and radius_m, a polygon or a file (one of them)")
        _check_layer(self.file, self.layer)
        if self.polygon is not None:
            _check_polygon(self.polygon)
        elif self.file is None and (self.center is None or self.radius is None):
            raise ValueError("a circle needs center and radius_m (or give a polygon or a file)")
        return self


class AreaConfig(TableModel):
    """The operating area: every vehicle stays inside it, ``r_c`` from its boundary.

    A ``polygon`` or a GIS ``file`` holding one polygon (its holes are islands: no-go).
    """

    polygon: tuple[Vertex, ...] | None = Field(
        None, description="vertices [north, east] (m) or { lat, lon } (deg)"
    )
    file: Path | None = Field(None, description=_GIS_FILE)
    layer: Text | None = Field(
        None, min_length=1, description="layer of a multi-layer GIS file (default: the first)"
    )

    @model_validator(mode="after")
    def _one_source(self) -> AreaConfig:
        if (self.polygon is None) == (self.file is None):
            raise ValueError("give a polygon or a file (one of them)")
        _check_layer(self.file, self.layer)
        if self.polygon is not None:
            _check_polygon(self.polygon)
        return self


def _check_layer(file: Path | None, layer: str | None) -> None:
    if layer is not None and file is None:
        raise ValueError("layer needs a file")


def polygon_frame(vertices: tuple[Vertex, ...]) -> tuple[bool, tuple[tuple[float, float], ...]]:
    """Whether ``vertices`` are geographic, and their ``(north, east)`` or ``(lat, lon)``.

    Raises ValueError when the vertices mix the local and the geographic frame.
    """
    pairs = [
        (False, vertex) if isinstance(vertex, tuple) else (vertex.is_geographic, vertex.coordinates)
        for vertex in vertices
    ]
    frames = {geographic for geographic, _ in pairs}
    if len(frames) > 1:
        raise ValueError("give every vertex as [north, east] or every one as { lat, lon }")
    return frames == {True}, tuple(pair for _, pair in pairs)


def _check_polygon(vertices: tuple[Vertex, ...]) -> None:
    if len(vertices) < 3:
        raise ValueError(f"polygon needs at least 3 vertices, got {len(vertices)}")
    geographic, pairs = polygon_frame(vertices)
    if not geographic:  # lat/lon polygons are checked in the map frame (mission.zones)
        check_simple_polygon(pairs)


def check_simple_polygon(vertices: tuple[tuple[float, float], ...]) -> None:
    """Raise ValueError unless ``[north, east]`` ``vertices`` [m] bound a simple polygon."""
    from shapely import Polygon
    from shapely.validation import explain_validity

    shape = Polygon([(east, north) for north, east in vertices])
    if not shape.is_valid or shape.area <= 0.0:
        reason = explain_validity(shape) if not shape.is_valid else "zero area"
        raise ValueError(f"polygon is not a simple polygon ({reason})")


class CommConfig(TableModel):
    """Two vehicles that must stay within ``max_range_m`` of each other."""

    pair: tuple[Text, Text] = Field(description="the two vehicle names")
    max_range: Number = Field(
        alias="max_range_m", gt=0.0, le=1e6, description="largest allowed distance",
        json_schema_extra=_unit("m"),
    )  # fmt: skip


class WeightsConfig(TableModel):
    """Trade-off multipliers of the optimiser's cost (dimensionless).

    ``terrain`` scales the pull towards the terrain-informed desired trajectory (0 gives the
    energy-only plan), ``energy`` the electrical power, ``terminal`` the arrival stiffness.
    ``information`` [W] rewards the optimiser directly for staying over informative terrain
    (the information map's spline surface, times ``terrain``; 0 leaves it to the desired path).
    """

    terrain: Number = Field(1.0, ge=0.0, le=1e6, description="terrain (desired-path) weight")
    energy: Number = Field(1.0, ge=0.0, le=1e6, description="electrical-energy weight")
    terminal: Number = Field(1.0, gt=0.0, le=1e6, description="arrival-pose weight")
    information: Number = Field(
        0.0, ge=0.0, le=1e4, description="reward for information in the optimiser (x terrain)",
        json_schema_extra=_unit("W"),
    )  # fmt: skip
    navigation: Number = Field(
        0.0, ge=0.0, le=1e6,
        description="price of predicted TAN error in the navigation pre-planner: J per m² of "
        "radial error variance per second flown", json_schema_extra=_unit("W/m²"),
    )  # fmt: skip


class PlannerConfig(TableModel):
    """The A* pre-planner."""

    edge_model: Literal["navigation", "paper", "crossed"] = Field(
        "navigation",
        description="navigation: cheapest path whose predicted TAN error meets [navigation]; "
        "paper: cost of the cell entered; crossed: length x terrain crossed",
    )


class NavigationConfig(TableModel):
    """The vehicles' terrain-aided navigation, one model for the planner and ``evaluate``.

    Defaults: MB-System's terrain-relative navigation (drift 1 % of distance, map variance
    1 m², an update every 3 s) and a DVL of ±0.5 cm/s (:mod:`auvplan.navigation`). The
    planner keeps each vehicle's predicted 1-σ radial error at or below ``max_error_m`` after
    the first ``settle_s`` seconds; without ``max_error_m`` it buys the largest predicted
    error reduction that costs at most ``max_energy_increase`` more energy and cuts the
    predicted RMS error by at least ``min_error_reduction`` (else it flies the energy-only
    path).
    """

    sensor: Literal["altimeter", "multibeam"] = Field(
        "altimeter", description="depth sensor (multibeam: 11 beams over 90°)"
    )
    update_period: Number = Field(
        3.0, alias="update_period_s", ge=0.1, le=600.0, description="time between TAN updates",
        json_schema_extra=_unit("s"),
    )  # fmt: skip
    drift: Number = Field(
        1.0, alias="drift_percent", gt=0.0, le=20.0,
        description="dead-reckoning drift, CEP in % of the distance travelled",
        json_schema_extra=_unit("%"),
    )  # fmt: skip
    velocity_noise: Number = Field(
        0.005, alias="dvl_noise_m_s", ge=0.0, le=1.0, description="white DVL velocity noise",
        json_schema_extra=_unit("m/s"),
    )  # fmt: skip
    initial_sigma: Number = Field(
        7.0, alias="initial_sigma_m", gt=0.0, le=1000.0,
        description="initial position error, standard deviation per axis",
        json_schema_extra=_unit("m"),
    )  # fmt: skip
    map_variance: Number = Field(
        1.0, alias="map_variance_m2", gt=0.0, le=1e4, description="variance of the map's depths",
        json_schema_extra=_unit("m²"),
    )  # fmt: skip
    max_error: Number | None = Field(
        None, alias="max_error_m", gt=0.0, le=1e5,
        description="budget on the predicted 1-σ radial error after settle_s (absent: "
        "automatic)", json_schema_extra=_unit("m"),
    )  # fmt: skip
    settle: Number = Field(
        600.0, alias="settle_s", ge=0.0, le=1e6,
        description="time from the start before the budget applies",
        json_schema_extra=_unit("s"),
    )  # fmt: skip
    max_energy_increase: Number = Field(
        0.10,
        ge=0.0,
        le=10.0,
        description="automatic budget: most extra energy (fraction of the energy-only path's)",
    )
    min_error_reduction: Number = Field(
        0.2,
        ge=0.0,
        lt=1.0,
        description="automatic budget: least cut of the predicted RMS error worth paying for",
    )

    def settings(
        self, *, vehicle_depth: float = 0.0, particles: int = 5000, convergence_updates: int = 200
    ) -> NavigationSettings:
        """The :class:`~auvplan.navigation.NavigationSettings` of this table.

        ``vehicle_depth`` [m] is the plan's depth (the altimeter's range is the seabed depth
        below it); ``particles`` and ``convergence_updates`` are the evaluator's own
        (``evaluate`` options). Raises :class:`~auvplan.errors.InputError` for an invalid value.
        """
        from auvplan.navigation import (
            DeadReckoningModel,
            NavigationSettings,
            ParticleFilterOptions,
            SensorModel,
        )

        sensor = dataclasses.replace(
            SensorModel.named(self.sensor),
            map_variance=self.map_variance,
            vehicle_depth=vehicle_depth,
        )
        return NavigationSettings(
            sensor=sensor,
            motion=DeadReckoningModel(
                drift_fraction=self.drift / 100.0, velocity_noise=self.velocity_noise
            ),
            filter=ParticleFilterOptions(n_particles=particles, initial_sigma=self.initial_sigma),
            update_period=self.update_period,
            convergence_updates=convergence_updates,
        )  # fmt: skip


class DeconflictionConfig(TableModel):
    """Coordination-space deconfliction (see :func:`auvplan.deconfliction.deconflict`)."""

    method: Literal["auto", "astar", "prioritized"] = Field(
        "auto",
        description="auto: exact A* for up to 4 vehicles (coarser A* or prioritized when it "
        "exceeds its budget), else prioritized",
    )
    weight: Number | None = Field(
        None, ge=1.0, le=100.0, description="A* heuristic weight (default sqrt(N))"
    )
    time_step: Number = Field(
        0.5, alias="time_step_s", ge=0.01, le=60.0, description="coordination grid step",
        json_schema_extra=_unit("s"),
    )  # fmt: skip
    coarsening: Integer = Field(
        1, ge=1, le=1000, description="A* searches on a k-times coarser grid"
    )


class SolverConfig(TableModel):
    """Stage-3 settings; defaults are :class:`auvplan.optimization.ProntoOptions`'s own.

    ``dt`` is the control and output interval. ``propeller_order`` is the number of Fourier
    harmonics of the four-quadrant propeller model inside the optimiser (the paper's low-order
    approximation) or ``"full"``. ``kernels`` evaluates each vehicle's stage derivatives with
    compiled kernels (numba, built once per vehicle model and cached on disk); without them
    ``compile`` C-compiles the stacked CasADi functions (cached on disk, needs a C compiler).
    ``fleet`` solves the fleet ``"coupled"`` (Newton on all vehicles at once),
    ``"decomposed"`` (vehicle by vehicle, :mod:`auvplan.mission.decomposition`) or ``"auto"``
    (decomposed from :data:`DECOMPOSED_FROM` vehicles).
    """

    dt: Number = Field(
        0.5, alias="dt_s", ge=0.01, le=10.0, description="control and output interval",
        json_schema_extra=_unit("s"),
    )  # fmt: skip
    tol: Number = Field(_SOLVER_DEFAULTS.tol, gt=0.0, le=1e3, description="stop when -Dh·ζ < tol")
    max_iter: Integer = Field(
        _SOLVER_DEFAULTS.max_iter, ge=1, le=10_000, description="PRONTO iterations, all levels"
    )
    eps_initial: Number = Field(
        _SOLVER_DEFAULTS.eps_initial, gt=0.0, le=1e6, description="first barrier weight ε"
    )
    eps_final: Number = Field(
        _SOLVER_DEFAULTS.eps_final, gt=0.0, le=1e6, description="last barrier weight ε"
    )
    eps_factor: Number = Field(
        _SOLVER_DEFAULTS.eps_factor, gt=0.0, lt=1.0, description="ε reduction per level"
    )
    delta_initial: Number = Field(
        _SOLVER_DEFAULTS.delta_initial, gt=0.0, le=10.0, description="first barrier switch δ"
    )
    propeller_order: Integer | Literal["full"] = Field(
        3, description="propeller harmonics in the optimiser, or 'full'"
    )
    eigenvalue_floor: Number = Field(
        _SOLVER_DEFAULTS.eigenvalue_floor, gt=0.0, le=1e6,
        description="smallest curvature kept by the convexified fallback",
    )  # fmt: skip
    kernels: Flag = Field(
        _SOLVER_DEFAULTS.stage_kernels, description="compiled per-vehicle stage kernels"
    )
    compile: Flag = Field(
        _SOLVER_DEFAULTS.compile_c, description="C-compile the CasADi stage functions"
    )
    fleet: Literal["auto", "coupled", "decomposed"] = Field(
        "auto",
        description="fleet solve: coupled, vehicle by vehicle, or auto (by fleet size)",
    )

    @model_validator(mode="after")
    def _schedule(self) -> SolverConfig:
        if self.eps_final > self.eps_initial:
            raise ValueError(f"eps_final = {self.eps_final:g} exceeds eps_initial")
        if isinstance(self.propeller_order, int) and not 1 <= self.propeller_order <= 64:
            raise ValueError(f"propeller_order: 1 to 64 or 'full', got {self.propeller_order}")
        return self

    def pronto_options(self) -> ProntoOptions:
        """The optimiser's options built from these settings."""
        return ProntoOptions(
            tol=self.tol,
            max_iter=self.max_iter,
            eps_initial=self.eps_initial,
            eps_final=self.eps_final,
            eps_factor=self.eps_factor,
            delta_initial=self.delta_initial,
            eigenvalue_floor=self.eigenvalue_floor,
            stage_kernels=self.kernels,
            compile_c=self.compile,
        )

    def decomposes(self, n_vehicles: int) -> bool:
        """Whether a fleet of ``n_vehicles`` is solved vehicle by vehicle.

        ``"auto"`` decomposes from :data:`DECOMPOSED_FROM` vehicles
        (:mod:`auvplan.mission.decomposition`).
        """
        if self.fleet == "auto":
            return n_vehicles >= DECOMPOSED_FROM
        return self.fleet == "decomposed"

    @property
    def harmonics(self) -> int | None:
        """``propeller_order`` with ``"full"`` as ``None``."""
        return None if self.propeller_order == "full" else self.propeller_order


class CurrentConfig(TableModel):
    """The ocean current: uniform (``north``/``east``) or gridded (``file``); absent = still water.

    Velocities are the direction the water flows **to** (oceanographic convention, CF
    ``eastward_sea_water_velocity``), over ground, in the local frame.
    """

    north: Number | None = Field(
        None, ge=-5.0, le=5.0, description="uniform current, northward component",
        json_schema_extra=_unit("m/s"),
    )  # fmt: skip
    east: Number | None = Field(
        None, ge=-5.0, le=5.0, description="uniform current, eastward component",
        json_schema_extra=_unit("m/s"),
    )  # fmt: skip
    file: Path | None = Field(
        None,
        description="NetCDF current file as an ocean model publishes it: HYCOM, Copernicus "
        "Marine, NOAA RTOFS, ROMS/CROCO or any CF eastward/northward_sea_water_velocity; "
        "linear in depth at depth_m, sliced to the mission's time window",
    )

    @model_validator(mode="after")
    def _one_source(self) -> CurrentConfig:
        if (self.file is None) == (self.north is None and self.east is None):
            raise ValueError("give a current file = '...' or north/east components (one of them)")
        return self


class ExecutionConfig(TableModel):
    """When and at what depth the plan is flown (timestamps and depths of the exports).

    ``start_time`` is an ISO 8601 date and time with its time zone (a TOML offset date-time
    or a string such as ``"2026-05-01T08:00:00Z"``), kept in UTC; the plan's time ``t`` [s] is
    flown at ``start_time + t``. ``depth_m`` is the constant depth of the planar plan;
    ``altitude_m`` instead asks for a constant height above the seabed, flown within each
    vehicle type's climb and dive rates and minimum altitude (``[vertical]`` of its file;
    :mod:`auvplan.mission.depth_profile`); the horizontal plan stays planar (3-DOF).
    ``reserve_fraction`` ``f`` is the share of each battery a plan must leave unused: a
    vehicle whose file gives ``battery_capacity`` ``C`` may use ``E = ∫ P dt ≤ C (1 − f)``
    (:mod:`auvplan.mission.checks`). The default 0.2 keeps a fifth for what the plan does
    not model (battery ageing and cold, currents stronger than planned, a recovery
    transit); vehicles of unknown capacity are not checked.
    """

    start_time: datetime = Field(
        default_factory=lambda: datetime.now(UTC).replace(microsecond=0),
        description="UTC time of t = 0, ISO 8601 with time zone (default: the time of the run)",
    )
    depth: Number = Field(
        0.0, alias="depth_m", ge=0.0, le=11_000.0, description="constant depth of the plan",
        json_schema_extra=_unit("m"),
    )  # fmt: skip
    reserve_fraction: Number = Field(
        0.2, ge=0.0, lt=1.0,
        description="share of each battery_capacity a plan must leave unused",
    )  # fmt: skip
    altitude: Number | None = Field(
        None, alias="altitude_m", gt=0.0, le=11_000.0,
        description="height above the seabed to follow instead of depth_m (terrain following)",
        json_schema_extra=_unit("m"),
    )  # fmt: skip

    @model_validator(mode="after")
    def _one_vertical_mode(self) -> ExecutionConfig:
        if self.altitude is not None and "depth" in self.model_fields_set:
            raise ValueError(
                "give depth_m (constant depth) or altitude_m (above the seabed), not both"
            )
        return self

    @model_serializer(mode="wrap")
    def _without_unused_depth(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """With ``altitude_m`` the document has no ``depth_m`` (they are mutually exclusive)."""
        document: dict[str, Any] = handler(self)
        if self.altitude is not None:
            document.pop("depth_m", None)
            document.pop("depth", None)
        return document

    @field_validator("start_time", mode="before")
    @classmethod
    def _iso_time(cls, value: Any) -> Any:
        if isinstance(value, str):
            try:
                return datetime.fromisoformat(value)
            except ValueError:
                raise ValueError(
                    f"not an ISO 8601 time, got {value!r} (e.g. '2026-05-01T08:00:00Z')"
                ) from None
        if not isinstance(value, datetime):
            raise ValueError(f"an ISO 8601 date and time, got {value!r}")  # noqa: TRY004 (pydantic)
        return value

    @field_validator("start_time", mode="after")
    @classmethod
    def _in_utc(cls, value: datetime) -> datetime:
        if value.tzinfo is None or value.utcoffset() is None:
            raise ValueError(
                f"give a time zone, e.g. {value.isoformat()}Z for UTC, got {value.isoformat()}"
            )
        if not START_YEARS[0] <= value.year <= START_YEARS[1]:
            raise ValueError(f"year {value.year} is outside {START_YEARS[0]}-{START_YEARS[1]}")
        return value.astimezone(UTC)


#: A line of metadata: printable text on one line.
MetadataText = Annotated[str, Strict(), Field(min_length=1, max_length=500, pattern=r"^[^\n\r]*$")]
#: The kinds of creator and publisher ACDD-1.3 names.
PartyType = Literal["person", "group", "institution", "position"]


class MetadataConfig(TableModel):
    """Who made the plan: discovery attributes of ``trajectories.nc`` and ``maps.nc`` (ACDD).

    Each key given becomes the global attribute of the same name (ACDD-1.3 and the NCEI
    trajectory template v2.0 recommend them); the attributes computed from the plan (extent,
    times, id, version) need no key. ``publisher_*`` default to ``creator_*`` (the operator
    publishes their own plan); ``naming_authority`` is the reverse-DNS name of the organisation
    (``"org.example"``) under which the file's ``id`` (``auvplan-`` and a digest of the
    positions) is unique; ``license`` is the terms of use of the plan.
    """

    creator_name: MetadataText | None = Field(None, description="who made the plan")
    creator_email: MetadataText | None = Field(None, description="the creator's e-mail address")
    creator_url: MetadataText | None = Field(None, description="the creator's web address")
    creator_type: PartyType | None = Field(None, description="what the creator is")
    institution: MetadataText | None = Field(None, description="the creator's institution")
    project: MetadataText | None = Field(None, description="project the plan is made for")
    program: MetadataText | None = Field(None, description="programme the project is part of")
    publisher_name: MetadataText | None = Field(
        None, description="who distributes the plan (default: creator_name)"
    )
    publisher_email: MetadataText | None = Field(
        None, description="the publisher's e-mail address (default: creator_email)"
    )
    publisher_url: MetadataText | None = Field(
        None, description="the publisher's web address (default: creator_url)"
    )
    license: MetadataText | None = Field(None, description="terms of use of the plan")
    naming_authority: MetadataText | None = Field(
        None, description="reverse-DNS name of the organisation that issues the file's id"
    )

    @model_validator(mode="before")
    @classmethod
    def _publisher_is_the_creator(cls, data: Any) -> Any:
        """Each ``publisher_*`` not given is the ``creator_*`` of the same part, if given."""
        if not isinstance(data, dict):
            return data
        defaults = {
            f"publisher_{part}": data[f"creator_{part}"]
            for part in ("name", "email", "url")
            if data.get(f"creator_{part}") is not None
        }
        return {**defaults, **{key: value for key, value in data.items() if value is not None}}

    def attributes(self) -> dict[str, str]:
        """The global attributes: each key given (or defaulted), by its name."""
        return {key: value for key, value in self.model_dump().items() if value is not None}
