"""The mission file (TOML): dataclasses, parsing and validation (SPEC §8).

This is the "friendly shell": degrees, user defaults and key checking happen here and nowhere
else; everything returned is in SI units and radians. Every problem a user can cause raises
:class:`~auvplan.errors.InputError` with one line naming the key (``vehicle[2].start.north``)
and the offending value. Checks that need the terrain (poses on land, outside the map) or the
vehicle model (horizon too short) are made by :mod:`auvplan.mission.pipeline`.

Mission keys (all tables optional except ``[fleet]`` and at least one ``[[vehicle]]``)::

    [terrain]      file | synthetic, seed, window = {north|east|lat|lon = [a, b]}
    [maps]         s, block = [r_n, r_e], omega, w
    [fleet]        horizon_s | cruise_speed, safety_radius_m
    [[vehicle]]    name, type, start = {north, east | lat, lon, heading_deg, speed},
                   goal = {north, east | lat, lon, heading_deg}
    [[obstacle]]   center = {north, east | lat, lon}, radius_m   |   polygon = [[n, e], ...]
    [[comm]]       pair = [name, name], max_range_m
    [weights]      terrain, energy, terminal
    [planner]      edge_model = "paper" | "crossed"
    [deconfliction] method = "auto" | "astar" | "prioritized", weight, time_step_s, coarsening
    [solver]       dt_s, tol, max_iter, eps_initial, eps_final, eps_factor, delta_initial,
                   propeller_order, eigenvalue_floor, compile
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final, TypeVar

from auvplan.errors import DataFormatError, InputError

T = TypeVar("T")

EDGE_MODELS: Final = ("paper", "crossed")
DECONFLICTION_METHODS: Final = ("auto", "astar", "prioritized")
#: Fleets up to this size use the coordination-space A* under ``method = "auto"``.
AUTO_ASTAR_MAX_VEHICLES: Final = 4
#: Default propeller harmonics in the optimiser (see ``auvplan vehicle --orders``): order 3
#: keeps steady cruise power within 2.5 % and bollard thrust within 4 % of the full series.
DEFAULT_PROPELLER_ORDER: Final = 3


@dataclass(frozen=True)
class Position:
    """A horizontal position, either local or geographic (resolved against the terrain later).

    Exactly one of ``(north, east)`` [m] and ``(lat, lon)`` [deg] is set.
    """

    north: float | None = None
    east: float | None = None
    lat: float | None = None
    lon: float | None = None

    @property
    def is_geographic(self) -> bool:
        """True when given as latitude/longitude."""
        return self.lat is not None


@dataclass(frozen=True)
class Pose:
    """A position with heading ``psi`` [rad, clockwise from north] and surge ``speed`` [m/s]."""

    position: Position
    psi: float = 0.0
    speed: float = 0.0


@dataclass(frozen=True)
class TerrainConfig:
    """Where the bathymetry comes from.

    ``file`` is resolved relative to the mission file. ``window_*`` are ``(low, high)`` pairs in
    metres (north/east) or degrees (lat/lon).
    """

    file: Path | None = None
    synthetic: bool = False
    seed: int = 7
    window_north: tuple[float, float] | None = None
    window_east: tuple[float, float] | None = None
    window_lat: tuple[float, float] | None = None
    window_lon: tuple[float, float] | None = None


@dataclass(frozen=True)
class MapsConfig:
    """Map parameters (paper eq. 13-15): exponent ``s``, block ``(r_n, r_e)``, ``omega``, ``w``."""

    exponent: float = 1.0
    block: tuple[int, int] = (2, 2)
    omega: float = 10.0
    weight: float = 10.0


@dataclass(frozen=True)
class FleetConfig:
    """Fleet-wide timing: horizon ``T`` [s] or cruise speed [m/s]; safety radius ``r_c`` [m]."""

    horizon: float | None
    cruise_speed: float | None
    safety_radius: float


@dataclass(frozen=True)
class VehicleConfig:
    """One vehicle: ``name``, ``type`` (packaged type name or vehicle-file path), start, goal."""

    name: str
    type: str
    start: Pose
    goal: Pose


@dataclass(frozen=True)
class ObstacleConfig:
    """A circular (``center``, ``radius`` [m]) or polygonal (``polygon`` vertices) obstacle."""

    center: Position | None = None
    radius: float = 0.0
    polygon: tuple[tuple[float, float], ...] | None = None


@dataclass(frozen=True)
class CommConfig:
    """Two vehicles that must stay within ``max_range`` [m] of each other."""

    pair: tuple[str, str]
    max_range: float


@dataclass(frozen=True)
class WeightsConfig:
    """Trade-off weights of the optimiser's running cost (dimensionless multipliers).

    ``terrain`` scales the pull towards the terrain-informed desired trajectory (0 gives the
    energy-only plan), ``energy`` the electrical power, ``terminal`` the stiffness of the
    arrival cost.
    """

    terrain: float = 1.0
    energy: float = 1.0
    terminal: float = 1.0


@dataclass(frozen=True)
class DeconflictionConfig:
    """Coordination-space deconfliction settings.

    ``method``: ``"astar"`` (the paper's weighted A* on the N-D coordination grid),
    ``"prioritized"`` (scales to 16+ vehicles) or ``"auto"`` (A* up to
    ``AUTO_ASTAR_MAX_VEHICLES`` vehicles). ``weight``: A* heuristic weight (None: the paper's
    sqrt(N); 1 gives the grid optimum). ``time_step`` [s] of the grid, and ``coarsening``: the
    A* searches at ``coarsening * time_step`` and returns the law on the fine grid.
    """

    method: str = "auto"
    weight: float | None = None
    time_step: float = 0.5
    coarsening: int = 1

    def method_for(self, n_vehicles: int) -> str:
        """The method actually used for a fleet of ``n_vehicles``."""
        if self.method != "auto":
            return self.method
        return "astar" if n_vehicles <= AUTO_ASTAR_MAX_VEHICLES else "prioritized"


@dataclass(frozen=True)
class SolverConfig:
    """PRONTO settings: grid step ``dt`` [s], tolerance, iterations and barrier schedule.

    ``eigenvalue_floor`` is the smallest curvature kept per stage when PRONTO falls back to
    its convexified model (cost units; 1e-2 suits costs in joules). ``propeller_order`` is
    the number of Fourier harmonics of the four-quadrant propeller
    model inside the optimiser (the paper's low-order approximation, its ref. [14]); ``None``
    uses the full series. Plans are simulated, checked and reported with the same model.
    ``compile`` generates C for the stage functions and builds it with the system compiler,
    cached on disk (``$AUVPLAN_CACHE_DIR`` or ``~/.cache/auvplan``): the first run of a mission
    pays the compilation (~25 s for the demo), later runs of it are ~2.5x faster.
    """

    dt: float = 0.5
    tol: float = 1e-6
    max_iter: int = 100
    eps_initial: float = 1.0
    eps_final: float = 1e-4
    eps_factor: float = 0.1
    delta_initial: float = 0.5
    propeller_order: int | None = DEFAULT_PROPELLER_ORDER
    eigenvalue_floor: float = 1e-2
    compile: bool = False


@dataclass(frozen=True)
class MissionConfig:
    """A validated mission (SI units, radians). Built by :func:`load_mission`."""

    terrain: TerrainConfig
    maps: MapsConfig
    fleet: FleetConfig
    vehicles: tuple[VehicleConfig, ...]
    obstacles: tuple[ObstacleConfig, ...] = ()
    comms: tuple[CommConfig, ...] = ()
    weights: WeightsConfig = field(default_factory=WeightsConfig)
    edge_model: str = "paper"
    deconfliction: DeconflictionConfig = field(default_factory=DeconflictionConfig)
    solver: SolverConfig = field(default_factory=SolverConfig)
    source: Path | None = None

    def vehicle_index(self, name: str) -> int:
        """Index of the vehicle called ``name``."""
        for index, vehicle in enumerate(self.vehicles):
            if vehicle.name == name:
                return index
        raise InputError(f"no vehicle named {name!r}")


def load_mission(path: Path | str) -> MissionConfig:
    """Read and validate a mission TOML file.

    Raises
    ------
    DataFormatError
        The file is missing or is not valid TOML.
    InputError
        A key is unknown, missing, of the wrong type or out of range (the message names it).
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise DataFormatError(f"mission file not found: {path}") from None
    except (OSError, UnicodeDecodeError) as error:
        raise DataFormatError(f"cannot read mission file {path}: {error}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise DataFormatError(f"{path.name}: not valid TOML ({error})") from None
    return parse_mission(data, base_dir=path.parent, source=path)


def parse_mission(
    data: Mapping[str, Any], *, base_dir: Path = Path(), source: Path | None = None
) -> MissionConfig:
    """Validate an already-parsed TOML document (see :func:`load_mission`)."""
    root = _Table(data, "mission")
    root.only(
        "terrain",
        "maps",
        "fleet",
        "vehicle",
        "obstacle",
        "comm",
        "weights",
        "planner",
        "deconfliction",
        "solver",
    )
    terrain = _parse_terrain(root.table("terrain"), base_dir)
    maps = _parse_maps(root.table("maps"))
    fleet = _parse_fleet(root.table("fleet", required=True))
    vehicles = tuple(
        _parse_vehicle(table, index) for index, table in enumerate(root.array("vehicle"))
    )
    if not vehicles:
        raise InputError("mission has no [[vehicle]]: at least one is required")
    names = [vehicle.name for vehicle in vehicles]
    duplicates = sorted({name for name in names if names.count(name) > 1})
    if duplicates:
        raise InputError(f"vehicle names must be unique, repeated: {', '.join(duplicates)}")
    obstacles = tuple(
        _parse_obstacle(table, index) for index, table in enumerate(root.array("obstacle"))
    )
    comms = tuple(
        _parse_comm(table, index, names) for index, table in enumerate(root.array("comm"))
    )
    weights_table = root.table("weights")
    weights_table.only("terrain", "energy", "terminal")
    weights = WeightsConfig(
        terrain=weights_table.number("terrain", 1.0, minimum=0.0),
        energy=weights_table.number("energy", 1.0, minimum=0.0),
        terminal=weights_table.number("terminal", 1.0, minimum=0.0, strict=True),
    )
    planner = root.table("planner")
    planner.only("edge_model")
    edge_model = planner.choice("edge_model", EDGE_MODELS, "paper")
    return MissionConfig(
        terrain=terrain,
        maps=maps,
        fleet=fleet,
        vehicles=vehicles,
        obstacles=obstacles,
        comms=comms,
        weights=weights,
        edge_model=edge_model,
        deconfliction=_parse_deconfliction(root.table("deconfliction")),
        solver=_parse_solver(root.table("solver")),
        source=source,
    )


def _parse_terrain(table: _Table, base_dir: Path) -> TerrainConfig:
    table.only("file", "synthetic", "seed", "window")
    file = table.string("file", None)
    synthetic = table.boolean("synthetic", file is None)
    if file is not None and synthetic:
        raise InputError("terrain: give either file or synthetic = true, not both")
    if file is None and not synthetic:
        raise InputError("terrain: give a bathymetry file or synthetic = true")
    seed = table.integer("seed", 7, minimum=0)
    window = table.table("window")
    window.only("north", "east", "lat", "lon")
    windows = {key: window.interval(key) for key in ("north", "east", "lat", "lon")}
    if (windows["north"] or windows["east"]) and (windows["lat"] or windows["lon"]):
        raise InputError("terrain.window: use north/east or lat/lon, not both")
    path = None if file is None else (base_dir / Path(file).expanduser())
    return TerrainConfig(
        file=path,
        synthetic=synthetic,
        seed=seed,
        window_north=windows["north"],
        window_east=windows["east"],
        window_lat=windows["lat"],
        window_lon=windows["lon"],
    )


def _parse_maps(table: _Table) -> MapsConfig:
    table.only("s", "block", "omega", "w")
    block = table.integer_pair("block", (2, 2), minimum=1)
    return MapsConfig(
        exponent=table.number("s", 1.0, minimum=0.0, strict=True),
        block=block,
        omega=table.number("omega", 10.0, minimum=0.0, strict=True),
        weight=table.number("w", 10.0, minimum=0.0),
    )


def _parse_fleet(table: _Table) -> FleetConfig:
    table.only("horizon_s", "cruise_speed", "safety_radius_m")
    horizon = table.number("horizon_s", None, minimum=0.0, strict=True)
    cruise = table.number("cruise_speed", None, minimum=0.0, strict=True)
    if (horizon is None) == (cruise is None):
        raise InputError("fleet: give exactly one of horizon_s and cruise_speed")
    radius = table.number("safety_radius_m", None, minimum=0.0, strict=True)
    if radius is None:
        raise InputError("fleet.safety_radius_m is required")
    return FleetConfig(horizon=horizon, cruise_speed=cruise, safety_radius=radius)


def _parse_position(table: _Table, *, extra: tuple[str, ...] = ()) -> Position:
    table.only("north", "east", "lat", "lon", *extra)
    local = table.has("north") or table.has("east")
    geographic = table.has("lat") or table.has("lon")
    if local == geographic:
        raise InputError(f"{table.path}: give north and east (m) or lat and lon (deg)")
    if local:
        return Position(north=table.number("north", None), east=table.number("east", None))
    lat = table.number("lat", None, minimum=-90.0, maximum=90.0)
    lon = table.number("lon", None, minimum=-180.0, maximum=360.0)
    return Position(lat=lat, lon=lon)


def _parse_pose(table: _Table, *, with_speed: bool) -> Pose:
    extra = ("heading_deg", "speed") if with_speed else ("heading_deg",)
    position = _parse_position(table, extra=extra)
    if position.north is None and position.lat is None:
        raise InputError(f"{table.path}: position missing")
    if (position.north is None) != (position.east is None) or (position.lat is None) != (
        position.lon is None
    ):
        raise InputError(f"{table.path}: both coordinates are required")
    heading = table.number("heading_deg", 0.0)
    speed = table.number("speed", 0.0, minimum=0.0) if with_speed else 0.0
    return Pose(position=position, psi=math.radians(heading), speed=speed)


def _parse_vehicle(table: _Table, index: int) -> VehicleConfig:
    table.only("name", "type", "start", "goal")
    name = table.string("name", f"vehicle{index + 1}")
    if not name or any(ch in name for ch in ",\n\"'"):
        raise InputError(f"{table.path}.name: {name!r} is not a usable name")
    return VehicleConfig(
        name=name,
        type=table.string("type", "medusa"),
        start=_parse_pose(table.table("start", required=True), with_speed=True),
        goal=_parse_pose(table.table("goal", required=True), with_speed=False),
    )


def _parse_obstacle(table: _Table, index: int) -> ObstacleConfig:
    table.only("center", "radius_m", "polygon")
    if table.has("polygon"):
        if table.has("center") or table.has("radius_m"):
            raise InputError(f"{table.path}: give center and radius_m, or polygon, not both")
        vertices = table.point_list("polygon")
        if len(vertices) < 3:
            raise InputError(f"{table.path}.polygon: needs at least 3 [north, east] vertices")
        return ObstacleConfig(polygon=vertices)
    center = _parse_position(table.table("center", required=True))
    radius = table.number("radius_m", None, minimum=0.0, strict=True)
    if radius is None:
        raise InputError(f"obstacle[{index}].radius_m is required")
    return ObstacleConfig(center=center, radius=radius)


def _parse_comm(table: _Table, index: int, names: list[str]) -> CommConfig:
    table.only("pair", "max_range_m")
    pair = table.value("pair", list)
    if pair is None or len(pair) != 2 or not all(isinstance(name, str) for name in pair):
        raise InputError(f"comm[{index}].pair: expected two vehicle names, got {pair!r}")
    for name in pair:
        if name not in names:
            raise InputError(f"comm[{index}].pair: no vehicle named {name!r}")
    if pair[0] == pair[1]:
        raise InputError(f"comm[{index}].pair: a vehicle cannot pair with itself ({pair[0]!r})")
    max_range = table.number("max_range_m", None, minimum=0.0, strict=True)
    if max_range is None:
        raise InputError(f"comm[{index}].max_range_m is required")
    return CommConfig(pair=(pair[0], pair[1]), max_range=max_range)


def _parse_deconfliction(table: _Table) -> DeconflictionConfig:
    table.only("method", "weight", "time_step_s", "coarsening")
    return DeconflictionConfig(
        method=table.choice("method", DECONFLICTION_METHODS, "auto"),
        weight=table.number("weight", None, minimum=1.0),
        time_step=table.number("time_step_s", 0.5, minimum=0.0, strict=True),
        coarsening=table.integer("coarsening", 1, minimum=1),
    )


def _propeller_order(table: _Table) -> int | None:
    """``solver.propeller_order``: a positive integer or ``"full"``."""
    if table.data.get("propeller_order") == "full":
        return None
    return table.integer("propeller_order", DEFAULT_PROPELLER_ORDER, minimum=1)


def _parse_solver(table: _Table) -> SolverConfig:
    table.only(
        "dt_s", "tol", "max_iter", "eps_initial", "eps_final", "eps_factor", "delta_initial",
        "propeller_order", "eigenvalue_floor", "compile",
    )  # fmt: skip
    config = SolverConfig(
        dt=table.number("dt_s", 0.5, minimum=0.0, strict=True),
        tol=table.number("tol", 1e-6, minimum=0.0, strict=True),
        max_iter=table.integer("max_iter", 100, minimum=1),
        eps_initial=table.number("eps_initial", 1.0, minimum=0.0, strict=True),
        eps_final=table.number("eps_final", 1e-4, minimum=0.0, strict=True),
        eps_factor=table.number("eps_factor", 0.1, minimum=0.0, maximum=1.0, strict=True),
        delta_initial=table.number("delta_initial", 0.5, minimum=0.0, strict=True),
        propeller_order=_propeller_order(table),
        eigenvalue_floor=table.number("eigenvalue_floor", 1e-2, minimum=0.0, strict=True),
        compile=table.boolean("compile", False),
    )
    if config.eps_final > config.eps_initial:
        raise InputError(
            f"solver: eps_final = {config.eps_final:g} exceeds eps_initial = {config.eps_initial:g}"
        )
    if config.eps_factor >= 1.0:
        raise InputError(f"solver.eps_factor must be < 1, got {config.eps_factor:g}")
    return config


class _Table:
    """A TOML table with its dotted path, for typed look-ups with precise error messages."""

    def __init__(self, data: Any, path: str) -> None:
        if not isinstance(data, Mapping):
            raise InputError(f"{path}: expected a table, got {type(data).__name__}")
        self.data: Mapping[str, Any] = data
        self.path = path

    def _key(self, key: str) -> str:
        return key if self.path == "mission" else f"{self.path}.{key}"

    def only(self, *allowed: str) -> None:
        unknown = sorted(set(self.data) - set(allowed))
        if unknown:
            raise InputError(
                f"unknown key {self._key(unknown[0])!r} (allowed here: {', '.join(allowed)})"
            )

    def has(self, key: str) -> bool:
        return key in self.data

    def table(self, key: str, *, required: bool = False) -> _Table:
        if key not in self.data:
            if required:
                raise InputError(f"{self._key(key)} is required")
            return _Table({}, self._key(key))
        return _Table(self.data[key], self._key(key))

    def array(self, key: str) -> list[_Table]:
        items = self.data.get(key, [])
        if not isinstance(items, list):
            raise InputError(f"{self._key(key)}: expected [[{key}]] tables")
        return [_Table(item, f"{key}[{index}]") for index, item in enumerate(items)]

    def value(self, key: str, kind: type[T]) -> T | None:
        if key not in self.data:
            return None
        value = self.data[key]
        if not isinstance(value, kind):
            raise InputError(
                f"{self._key(key)}: expected {kind.__name__}, got {type(value).__name__} {value!r}"
            )
        return value

    def string(self, key: str, default: str | None) -> Any:
        value = self.value(key, str)
        return default if value is None else value

    def boolean(self, key: str, default: bool) -> bool:
        value = self.value(key, bool)
        return default if value is None else value

    def number(
        self,
        key: str,
        default: float | None,
        *,
        minimum: float | None = None,
        maximum: float | None = None,
        strict: bool = False,
    ) -> Any:
        if key not in self.data:
            return default
        value = self.data[key]
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise InputError(f"{self._key(key)}: expected a number, got {value!r}")
        return self._check_range(key, float(value), minimum, maximum, strict=strict)

    def integer(self, key: str, default: int, *, minimum: int | None = None) -> int:
        value = self.value(key, int)
        if value is None:
            return default
        if isinstance(value, bool):
            raise InputError(f"{self._key(key)}: expected an integer, got {value!r}")
        return int(self._check_range(key, value, minimum, None, strict=False))

    def _check_range(
        self, key: str, value: float, minimum: float | None, maximum: float | None, *, strict: bool
    ) -> float:
        if not math.isfinite(value):
            raise InputError(f"{self._key(key)}: must be finite, got {value!r}")
        if minimum is not None and (value <= minimum if strict else value < minimum):
            relation = ">" if strict else ">="
            raise InputError(f"{self._key(key)}: must be {relation} {minimum:g}, got {value:g}")
        if maximum is not None and value > maximum:
            raise InputError(f"{self._key(key)}: must be <= {maximum:g}, got {value:g}")
        return value

    def choice(self, key: str, choices: tuple[str, ...], default: str) -> str:
        value = self.string(key, default)
        if value not in choices:
            raise InputError(f"{self._key(key)}: {value!r} is not one of {', '.join(choices)}")
        return str(value)

    def interval(self, key: str) -> tuple[float, float] | None:
        value = self.value(key, list)
        if value is None:
            return None
        if len(value) != 2 or not all(_is_number(item) for item in value):
            raise InputError(f"{self._key(key)}: expected [low, high], got {value!r}")
        low, high = float(value[0]), float(value[1])
        if not low < high:
            raise InputError(f"{self._key(key)}: low must be < high, got {value!r}")
        return (low, high)

    def integer_pair(self, key: str, default: tuple[int, int], *, minimum: int) -> tuple[int, int]:
        value = self.value(key, list)
        if value is None:
            return default
        if len(value) != 2 or not all(
            isinstance(item, int) and not isinstance(item, bool) and item >= minimum
            for item in value
        ):
            raise InputError(f"{self._key(key)}: expected two integers >= {minimum}, got {value!r}")
        return (int(value[0]), int(value[1]))

    def point_list(self, key: str) -> tuple[tuple[float, float], ...]:
        value = self.value(key, list)
        if value is None or not all(
            isinstance(item, list) and len(item) == 2 and all(_is_number(v) for v in item)
            for item in value
        ):
            raise InputError(f"{self._key(key)}: expected a list of [north, east] pairs")
        return tuple((float(item[0]), float(item[1])) for item in value)


def _is_number(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
