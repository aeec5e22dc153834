"""Independent checks of a ``plan`` output folder, not trusting the solver's own report.

:func:`check` reads only ``trajectories.csv``, ``summary.json`` (goals resolved to the local
frame, safety radius, solver settings, status) and the mission file (obstacles and their GIS
files, the operating area, communication pairs; ``maps.nc`` only for the projection when an
obstacle is in lat/lon or a GIS file), and checks:

(a) **constraints between samples**: positions interpolated by a cubic spline per coordinate
    on a grid ``refinement`` times finer than the plan's; every pair keeps ``>= 2 r_c``, every
    vehicle keeps ``>= r_c`` from every obstacle's edge and inside the operating area's, every
    communication pair stays within its range;
(b) **dynamics**: the per-step defect of the samples against an independent plain-numpy
    model of each vehicle's own type, integrated with the input held
    (:mod:`auvplan.scenarios._model`, read by :mod:`auvplan.scenarios._vehicle_file`), in
    the mission's true current field when it has a ``[current]``;
(c) **arrival**: the distance of each vehicle's last sample from its goal;
(d) **state limits**: each vehicle's own actuator limits, ``|n_<thruster>| <= n_max`` and
    ``|delta_<surface>| <= delta_max``, at every sample including the last. With the input
    held, ``ṅ = w_c tanh(c)`` has one sign over a step, so the samples bound the whole step.

A mixed fleet's ``trajectories.csv`` has empty cells for states a vehicle does not have; each
vehicle is read by its own model's state and input names.
"""

from __future__ import annotations

import json
import tomllib
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from datetime import datetime
from pathlib import Path
from typing import Any, Final

import numpy as np
import shapely
from scipy.interpolate import CubicSpline

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.io.currents import read_current
from auvplan.io.results import read_trajectories_csv
from auvplan.io.zones import read_zones
from auvplan.ocean import CurrentField, UniformCurrent
from auvplan.record.files import MAIN_PLAN, MAPS_FILE, MISSION_FILE, PLAN_FILES, SUMMARY_FILE
from auvplan.record.labels import AREA_NAME, Pair
from auvplan.scenarios._model import ReferenceModel, step_defects
from auvplan.scenarios._vehicle_file import read_reference_model
from auvplan.terrain.projection import LocalProjection

#: Largest per-step position defect [m] accepted (issue 11: 10 mm).
DEFECT_TOLERANCE_M: Final = 0.01
#: Largest distance [m] of the last sample from the goal accepted.
ARRIVAL_TOLERANCE_M: Final = 1.0
#: Slack [m] on geometric constraints, for rounding in the CSV only.
GEOMETRY_SLACK_M: Final = 1e-6
#: Relative slack on state limits, for rounding in the CSV only.
LIMIT_SLACK: Final = 1e-9
FAILURE_KINDS: Final = ("separation", "obstacle", "comm", "defect", "arrival", "state_limit")


@dataclass(frozen=True)
class CheckFailure:
    """One violated check: ``kind`` (one of :data:`FAILURE_KINDS`) and a one-line message."""

    kind: str
    message: str


@dataclass(frozen=True)
class CheckReport:
    """Result of :func:`check`; distances in metres, pair labels ``"a / b"``.

    ``min_obstacle_clearance_m`` is the smallest distance to each obstacle's edge
    (``"a / obstacle k"``); ``max_state_defect`` the largest absolute defect per state (units
    of ``trajectories.csv``); ``max_limit_fraction`` the largest ``|x| / limit`` of each
    vehicle's limited states (1 at the limit); ``status`` the plan's status in ``summary.json``
    (``plan_status``: CONVERGED only when the planner's own between-sample checks pass too).
    """

    status: str
    separation_limit_m: float
    min_separation_m: dict[str, float]
    min_obstacle_clearance_m: dict[str, float]
    max_comm_distance_m: dict[str, float]
    max_position_defect_m: dict[str, float]
    max_state_defect: dict[str, dict[str, float]]
    max_limit_fraction: dict[str, dict[str, float]]
    arrival_error_m: dict[str, float]
    failures: tuple[CheckFailure, ...]

    @property
    def passed(self) -> bool:
        """True when every check holds (whatever the optimiser's status)."""
        return not self.failures

    @property
    def success(self) -> bool:
        """A converged plan that passes every check."""
        return self.passed and self.status == "CONVERGED"

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-able values."""
        return {**asdict(self), "passed": self.passed, "success": self.success}


def read_trajectories(
    path: Path, models: Mapping[str, ReferenceModel]
) -> dict[str, tuple[FloatArray, FloatArray, FloatArray]]:
    """``trajectories.csv`` as ``{vehicle: (time (n_t,), states (n_t, n_x), inputs (n_t-1, n_u))}``.

    Each vehicle's columns are those of its own model (``models[vehicle]``).

    Raises
    ------
    DataFormatError
        If the file is missing or malformed, or a vehicle lacks a column or a value of its
        model's states and inputs.
    """
    if not path.is_file():
        raise DataFormatError(f"{path} not found (did the plan reach the optimiser?)")
    result = {}
    for name, columns in read_trajectories_csv(path).items():
        model = models[name]
        wanted = (*model.state_names, *model.input_names)
        missing = [c for c in wanted if c not in columns or np.isnan(columns[c]).any()]
        if missing:
            raise DataFormatError(f"{path}: vehicle {name!r} has no values of {', '.join(missing)}")
        table = np.column_stack([columns[c] for c in ("t", *wanted)])
        n_x = len(model.state_names)
        result[name] = (table[:, 0], table[:, 1 : 1 + n_x], table[:-1, 1 + n_x :])
    return result


def check(
    output_dir: Path | str,
    *,
    mission: Path | str | None = None,
    refinement: int = 10,
    defect_tolerance_m: float = DEFECT_TOLERANCE_M,
    arrival_tolerance_m: float = ARRIVAL_TOLERANCE_M,
) -> CheckReport:
    """Check a ``plan`` output folder independently of the solver (module docstring).

    Parameters
    ----------
    output_dir : Path or str
        Folder written by ``auvplan plan`` (``summary.json``, ``trajectories.csv``).
    mission : Path or str, optional
        The mission file; default: the folder's own ``mission.toml`` (whose files are the
        folder's, :mod:`auvplan.mission.carry`).
    refinement : int
        Interpolation points per plan step for the constraint checks.
    defect_tolerance_m, arrival_tolerance_m : float
        Largest per-step position defect and arrival error [m] accepted.

    Returns
    -------
    CheckReport

    Raises
    ------
    DataFormatError
        A file is missing or malformed.
    InputError
        No mission file is known.
    """
    output_dir = Path(output_dir)
    summary = json.loads((output_dir / SUMMARY_FILE).read_text(encoding="utf-8"))
    if "optimization" not in summary:
        raise DataFormatError(f"{output_dir}/summary.json has no optimisation result")
    mission_path = Path(mission) if mission is not None else output_dir / MISSION_FILE
    if not mission_path.is_file():
        raise InputError(f"mission file {mission_path} not found; pass it")
    document = tomllib.loads(mission_path.read_text(encoding="utf-8"))
    vehicles = {vehicle["name"]: vehicle for vehicle in summary["vehicles"]}
    order = summary["solver"].get("propeller_order")
    models = {
        name: read_reference_model(
            vehicle["type"],
            propeller_order=order,
            base_dirs=(mission_path.parent, output_dir, Path()),
        )
        for name, vehicle in vehicles.items()
    }
    tracks = read_trajectories(output_dir / PLAN_FILES[MAIN_PLAN].csv, models)
    names = list(tracks)
    failures: list[CheckFailure] = []

    time = tracks[names[0]][0]
    fine_time = np.linspace(time[0], time[-1], refinement * (time.size - 1) + 1)
    fine = {
        name: CubicSpline(t, states[:, :2], axis=0)(fine_time)
        for name, (t, states, _) in tracks.items()
    }
    radius = float(summary["fleet"]["safety_radius_m"])
    separations = _pair_distances(fine, names)
    min_separation = {pair: float(d.min()) for pair, d in separations.items()}
    for pair, distance in min_separation.items():
        if distance < 2.0 * radius - GEOMETRY_SLACK_M:
            failures.append(
                CheckFailure(
                    "separation", f"{pair} {distance:.3f} m apart < 2 r_c = {2 * radius:g} m"
                )
            )
    clearances = _obstacle_clearances(fine, document, output_dir, mission_path.parent)
    for label, clearance in clearances.items():
        if clearance < radius - GEOMETRY_SLACK_M:
            failures.append(
                CheckFailure(
                    "obstacle", f"{label}: {clearance:.3f} m from its edge < r_c = {radius:g} m"
                )
            )
    comm_distances = {}
    for comm in document.get("comm", []):
        pair = str(Pair(*comm["pair"]))
        farthest = float(np.max(np.hypot(*(fine[comm["pair"][0]] - fine[comm["pair"][1]]).T)))
        comm_distances[pair] = farthest
        if farthest > float(comm["max_range_m"]) + GEOMETRY_SLACK_M:
            failures.append(
                CheckFailure(
                    "comm",
                    f"{pair} {farthest:.1f} m apart > max_range_m = {comm['max_range_m']:g} m",
                )
            )

    current = _current(document, mission_path.parent, summary, output_dir)
    position_defects, state_defects, arrival, fractions = {}, {}, {}, {}
    for name, (t, states, inputs) in tracks.items():
        model = models[name]
        defects = step_defects(model, t, states, inputs, current)
        position_defects[name] = float(np.max(np.hypot(defects[:, 0], defects[:, 1]), initial=0.0))
        state_defects[name] = dict(
            zip(
                model.state_names,
                np.max(np.abs(defects), axis=0, initial=0.0).tolist(),
                strict=True,
            )
        )
        fractions[name] = _limit_fractions(model, states)
        failures += [
            CheckFailure(
                "state_limit",
                f"{name}: |{state}| reaches {fraction:.4g} x its limit {model.limits[state]:g}",
            )
            for state, fraction in fractions[name].items()
            if fraction > 1.0 + LIMIT_SLACK
        ]
        if position_defects[name] > defect_tolerance_m:
            step = int(np.argmax(np.hypot(defects[:, 0], defects[:, 1])))
            failures.append(
                CheckFailure(
                    "defect",
                    f"{name}: position defect {position_defects[name]:.4g} m at t = {t[step]:g} s "
                    f"> {defect_tolerance_m:g} m",
                )
            )
        goal = vehicles[name]["goal"]
        arrival[name] = float(np.hypot(states[-1, 0] - goal["north"], states[-1, 1] - goal["east"]))
        if arrival[name] > arrival_tolerance_m:
            failures.append(
                CheckFailure(
                    "arrival",
                    f"{name}: {arrival[name]:.3f} m from its goal > {arrival_tolerance_m:g} m",
                )
            )
    return CheckReport(
        status=str(summary["optimization"].get("plan_status", summary["optimization"]["status"])),
        separation_limit_m=2.0 * radius,
        min_separation_m=min_separation,
        min_obstacle_clearance_m=clearances,
        max_comm_distance_m=comm_distances,
        max_position_defect_m=position_defects,
        max_state_defect=state_defects,
        max_limit_fraction=fractions,
        arrival_error_m=arrival,
        failures=tuple(failures),
    )


def _current(
    document: Mapping[str, Any], base_dir: Path, summary: Mapping[str, Any], output_dir: Path
) -> CurrentField | None:
    """The mission's true current (``[current]``; a file on the frame of ``maps.nc``)."""
    table = document.get("current")
    if table is None:
        return None
    if "file" not in table:
        return UniformCurrent(float(table.get("north", 0.0)), float(table.get("east", 0.0)))
    from auvplan.io.bathymetry import read_bathymetry

    grid = read_bathymetry(output_dir / MAPS_FILE)
    execution = document.get("mission", {})
    start = execution.get("start_time")
    return read_current(
        base_dir / table["file"],
        projection=grid.projection,
        extent=(
            (float(grid.geometry.north[0]), float(grid.geometry.north[-1])),
            (float(grid.geometry.east[0]), float(grid.geometry.east[-1])),
        ),
        start_time=None if start is None else datetime.fromisoformat(summary["start_time"]),
        depth=float(execution.get("depth_m", 0.0)),
    )


def _limit_fractions(model: ReferenceModel, states: FloatArray) -> dict[str, float]:
    """Largest ``|x| / limit`` over every sample (the last included) of each limited state."""
    return {
        state: float(np.max(np.abs(states[:, model.state_names.index(state)])) / limit)
        for state, limit in model.limits.items()
    }


def _pair_distances(fine: Mapping[str, FloatArray], names: list[str]) -> dict[str, FloatArray]:
    return {
        str(Pair(a, b)): np.hypot(*(fine[a] - fine[b]).T)
        for i, a in enumerate(names)
        for b in names[i + 1 :]
    }


def _obstacle_clearances(
    fine: Mapping[str, FloatArray], document: Mapping[str, Any], output_dir: Path, mission_dir: Path
) -> dict[str, float]:
    """Smallest signed distance [m] of each vehicle to each obstacle's edge (< 0 inside).

    A GIS ``file`` gives one zone per polygon (``"a / obstacle k feature K"``); the operating
    area counts from inside its boundary (``"a / operating area"``, < 0 outside it).
    Polygons are shapely's in ``(north, east)``, holes included.
    """
    zones: list[tuple[str, Any]] = []  # a shapely polygon, or a circle (centre, radius)
    for k, obstacle in enumerate(document.get("obstacle", [])):
        if "center" in obstacle:
            circle = (_local(obstacle["center"], output_dir), float(obstacle["radius_m"]))
            zones.append((f"obstacle {k}", circle))
        else:
            zones += [
                (f"obstacle {k}{label}", shape)
                for label, shape in _polygons(obstacle, output_dir, mission_dir)
            ]
    if "area" in document:
        ((_, area),) = _polygons(document["area"], output_dir, mission_dir)
        zones.append((AREA_NAME, area))
    clearances = {}
    for label, zone in zones:
        for name, track in fine.items():
            if isinstance(zone, tuple):
                signed = np.hypot(*(track - zone[0]).T) - zone[1]
            else:
                points = shapely.points(track)
                distance = shapely.distance(zone.boundary, points)
                signed = np.where(shapely.contains(zone, points), -distance, distance)
            sign = -1.0 if label == AREA_NAME else 1.0  # the area is kept in
            clearances[f"{name} / {label}"] = float(np.min(sign * signed))
    return clearances


def _polygons(
    table: Mapping[str, Any], output_dir: Path, mission_dir: Path
) -> list[tuple[str, Any]]:
    """The polygons of an ``[[obstacle]]`` or ``[area]`` table, each with a label suffix.

    A ``polygon``'s vertices are ``[north, east]`` pairs or positions (:func:`_local`); a
    ``file`` (relative to ``mission_dir``) is read by :func:`~auvplan.io.zones.read_zones`.
    """
    if "polygon" in table:
        vertices = [
            _local(v, output_dir) if isinstance(v, Mapping) else (float(v[0]), float(v[1]))
            for v in table["polygon"]
        ]
        return [("", shapely.Polygon(vertices))]
    zones = read_zones(
        mission_dir / table["file"], _projection(output_dir), layer=table.get("layer")
    )
    return [(f" {zone.label}", shapely.Polygon(zone.exterior, zone.holes)) for zone in zones]


def _projection(output_dir: Path) -> LocalProjection:
    """The local frame of the folder's ``maps.nc`` (refused when it has none)."""
    from auvplan.io.bathymetry import read_bathymetry

    projection = read_bathymetry(output_dir / MAPS_FILE).projection
    if projection is None:
        raise DataFormatError(f"{output_dir}/maps.nc has no projection for lat/lon obstacles")
    return projection


def _local(position: Mapping[str, float], output_dir: Path) -> tuple[float, float]:
    """``(north, east)`` [m] of a mission position; lat/lon via the projection in ``maps.nc``."""
    if "north" in position:
        return float(position["north"]), float(position["east"])
    north, east = _projection(output_dir).to_local(
        np.array([position["lat"]]), np.array([position["lon"]])
    )
    return float(north[0]), float(east[0])
