"""The end-to-end pipeline (SPEC §1-§5): maps and A*, deconfliction, projection, PRONTO.

:func:`run_mission` runs the stages in order and stops after the one requested:

1. ``preplan`` — terrain, maps (eq. 13-15), one A* path per vehicle, smoothed;
2. ``deconflict`` — a common horizon ``T``, time laws in the coordination space, and the
   desired trajectories (pose, surge speed, trim propeller speeds) on the solver's grid;
3. ``full`` — the fleet problem (:mod:`auvplan.mission.fleet`) solved by PRONTO with the
   barrier continuation, starting from the projection of the desired trajectories onto the
   dynamics; optionally again with the terrain weight set to zero (energy-only comparison).

Every user-caused failure raises an :class:`~auvplan.errors.AuvplanError` with one line that
names the vehicle or key.
"""

from __future__ import annotations

import logging
import math
import time as wallclock
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import Enum
from functools import cache
from typing import Any, Final

import numpy as np
from scipy.interpolate import RegularGridInterpolator

from auvplan._typing import FloatArray
from auvplan.deconfliction import (
    CoordinationProblem,
    CoordinationResult,
    deconflict,
    retime_for_arrival,
    timed_headings,
    timed_positions,
)
from auvplan.errors import InfeasibleError, InputError
from auvplan.io.bathymetry import read_bathymetry
from auvplan.io.vehicles import load_vehicle
from auvplan.mission.config import MissionConfig, Position
from auvplan.mission.fleet import FleetProblemFunctions, build_fleet_functions
from auvplan.mission.verify import replay_closed_loop
from auvplan.optimization import (
    PathConstraint,
    ProntoOptions,
    ProntoResult,
    Trajectory,
    TrajectoryProblem,
    solve_pronto,
)
from auvplan.planning import (
    CircleObstacle,
    EdgeModel,
    PolygonObstacle,
    Route,
    blocked_cells,
    blocked_lookup,
    distance_to_obstacle,
    path_length,
    plan_route,
    smooth_path,
)
from auvplan.terrain import BathymetryGrid, MapParameters, TerrainMaps, compute_terrain_maps
from auvplan.terrain.synthetic import synthetic_bank
from auvplan.vehicle import VehicleModel, build_vehicle_model
from auvplan.vehicle.trim import top_speed, trim_surge

logger = logging.getLogger(__name__)

#: Fraction of a vehicle's top speed that the mean speed along its path may use.
SPEED_MARGIN: Final = 0.85
#: Refinement of the solver grid for the certified-separation resimulation.
CHECK_REFINEMENT: Final = 10
#: Samples of the steady-surge trim table (propeller speed against surge speed).
TRIM_SAMPLES: Final = 40


class Stage(Enum):
    """Where :func:`run_mission` stops."""

    PREPLAN = "preplan"
    DECONFLICT = "deconflict"
    FULL = "full"


@dataclass(frozen=True)
class PreplanStage:
    """Stage 1: terrain, maps, resolved poses and one A* route per vehicle.

    ``starts`` and ``goals`` have shape ``(n_vehicles, 3)``: north, east [m], psi [rad];
    ``start_speeds`` [m/s]. ``paths`` are the smoothed routes (``(n_i, 2)`` north/east [m]).
    """

    bathymetry: BathymetryGrid
    maps: TerrainMaps
    names: tuple[str, ...]
    starts: FloatArray
    start_speeds: FloatArray
    goals: FloatArray
    obstacles: tuple[CircleObstacle | PolygonObstacle, ...]
    routes: tuple[Route, ...]
    paths: tuple[FloatArray, ...]


@dataclass(frozen=True)
class DeconflictStage:
    """Stage 2: horizon, coordination-space time laws and the desired trajectories.

    ``desired_states`` has shape ``(n_vehicles, n_t, 8)`` on ``time`` (the solver grid).
    """

    horizon: float
    cruise_speeds: FloatArray
    problem: CoordinationProblem
    coordination: CoordinationResult
    time: FloatArray
    desired_states: FloatArray


@dataclass(frozen=True)
class OptimizedPlan:
    """Stage 3 for one weighting: the PRONTO result and the fleet's trajectories.

    ``states`` ``(n_vehicles, n_t, 8)``, ``inputs`` ``(n_vehicles, n_t - 1, 2)``, ``power``
    ``(n_vehicles, n_t)`` [W], ``energy`` ``(n_vehicles,)`` [J] = trapezoidal ∫ power dt,
    ``arrival_error`` ``(n_vehicles,)`` [m], ``terrain_information`` ``(n_vehicles,)`` mean
    information-map value along the trajectory; ``separations[name][other]`` the minimum
    distance [m] to each other vehicle (centre to centre) and obstacle (to its edge; polygons
    are enforced by the pre-planner and only checked here),
    when the plan is flown with its tracking regulator on a grid ``CHECK_REFINEMENT`` times
    finer than the solver's (:func:`auvplan.mission.verify.replay_closed_loop`), whose time
    series are ``fine_distances`` (labels ``"a / b"``) on ``fine_time``; ``tracking_error``
    ``(n_vehicles,)`` is that replay's largest distance [m] from the plan at the solver nodes.
    """

    result: ProntoResult
    terrain_weight: float
    states: FloatArray
    inputs: FloatArray
    power: FloatArray
    energy: FloatArray
    arrival_error: FloatArray
    terrain_information: FloatArray
    separations: dict[str, dict[str, float]]
    fine_time: FloatArray
    fine_distances: dict[str, FloatArray]
    tracking_error: FloatArray


@dataclass(frozen=True)
class MissionResult:
    """Everything a mission run produced; ``timings`` holds wall seconds per stage."""

    config: MissionConfig
    stage: Stage
    preplan: PreplanStage
    deconfliction: DeconflictStage | None = None
    plan: OptimizedPlan | None = None
    energy_only: OptimizedPlan | None = None
    timings: dict[str, float] = field(default_factory=dict)


def run_mission(
    config: MissionConfig,
    *,
    stage: Stage = Stage.FULL,
    compare_energy_only: bool = False,
    callback: Callable[[Any], None] | None = None,
) -> MissionResult:
    """Run the pipeline on a validated mission up to ``stage``.

    Parameters
    ----------
    config : MissionConfig
        From :func:`auvplan.mission.load_mission`.
    stage : Stage
        Last stage to run.
    compare_energy_only : bool
        Also optimise with the terrain weight set to 0 (the paper's energy-only reference).
    callback : callable, optional
        Passed to :func:`auvplan.optimization.solve_pronto` (per-iteration records).
    """
    timings: dict[str, float] = {}
    started = wallclock.perf_counter()
    preplan = run_preplan(config)
    timings["preplan"] = wallclock.perf_counter() - started
    if stage is Stage.PREPLAN:
        return MissionResult(config, stage, preplan, timings=timings)

    started = wallclock.perf_counter()
    models = _vehicle_models(config)
    deconfliction = run_deconfliction(config, preplan, models)
    timings["deconflict"] = wallclock.perf_counter() - started
    if stage is Stage.DECONFLICT:
        return MissionResult(config, stage, preplan, deconfliction, timings=timings)

    started = wallclock.perf_counter()
    plan = run_optimization(
        config, preplan, deconfliction, models, config.weights.terrain, callback=callback
    )
    timings["optimize"] = wallclock.perf_counter() - started
    energy_only = None
    if compare_energy_only:
        started = wallclock.perf_counter()
        energy_only = run_optimization(
            config, preplan, deconfliction, models, 0.0, callback=callback
        )
        timings["optimize_energy_only"] = wallclock.perf_counter() - started
    return MissionResult(config, stage, preplan, deconfliction, plan, energy_only, timings=timings)


# --------------------------------------------------------------------------- stage 1


def load_terrain(config: MissionConfig) -> BathymetryGrid:
    """The mission's bathymetry: a file (any supported format) or the synthetic bank."""
    terrain = config.terrain
    if terrain.synthetic:
        grid = synthetic_bank(seed=terrain.seed)
        if terrain.window_lat or terrain.window_lon:
            raise InputError("terrain.window: the synthetic bank has no lat/lon; use north/east")
        if terrain.window_north or terrain.window_east:
            grid = grid.window(terrain.window_north, terrain.window_east)
        return grid
    assert terrain.file is not None  # guaranteed by the config parser
    return read_bathymetry(
        terrain.file,
        window_north=terrain.window_north,
        window_east=terrain.window_east,
        window_lat=terrain.window_lat,
        window_lon=terrain.window_lon,
    )


def _resolve(position: Position, grid: BathymetryGrid, what: str) -> tuple[float, float]:
    if not position.is_geographic:
        assert position.north is not None
        assert position.east is not None
        return position.north, position.east
    if grid.projection is None:
        raise InputError(f"{what} is given in lat/lon but the terrain has no geographic reference")
    north, east = grid.projection.to_local(np.array([position.lat]), np.array([position.lon]))
    return float(north[0]), float(east[0])


def run_preplan(config: MissionConfig) -> PreplanStage:
    """Stage 1: load terrain, compute the maps, resolve poses, plan and smooth A* routes."""
    bathymetry = load_terrain(config)
    maps_config = config.maps
    maps = compute_terrain_maps(
        bathymetry,
        MapParameters(
            exponent=maps_config.exponent,
            block=maps_config.block,
            omega=maps_config.omega,
            weight=maps_config.weight,
        ),
    )
    logger.info(
        "terrain: %s, %d x %d cells of %.1f x %.1f m; cost grid %d x %d",
        bathymetry.name,
        *bathymetry.geometry.shape,
        bathymetry.geometry.spacing_north,
        bathymetry.geometry.spacing_east,
        *maps.cost_geometry.shape,
    )
    names = tuple(vehicle.name for vehicle in config.vehicles)
    starts = np.array(
        [
            (*_resolve(v.start.position, bathymetry, f"vehicle {v.name} start"), v.start.psi)
            for v in config.vehicles
        ]
    )
    goals = np.array(
        [
            (*_resolve(v.goal.position, bathymetry, f"vehicle {v.name} goal"), v.goal.psi)
            for v in config.vehicles
        ]
    )
    _check_pairwise_clearance(names, starts, goals, config.fleet.safety_radius)
    _check_communication_ranges(config, starts, goals)
    obstacles = _obstacles(config, bathymetry)
    routes = []
    paths = []
    for index, name in enumerate(names):
        route = plan_route(
            maps.shifted_cost,
            maps.cost_geometry,
            (float(starts[index, 0]), float(starts[index, 1])),
            (float(goals[index, 0]), float(goals[index, 1])),
            obstacles=obstacles,
            clearance=config.fleet.safety_radius,
            edge_model=EdgeModel(config.edge_model),
            name=name,
        )
        routes.append(route)
        paths.append(_smooth(route, maps, obstacles, config.fleet.safety_radius))
        logger.info(
            "A* %s: %d cells, cost %.1f, %d expanded", name, len(route.cells), route.cost,
            route.n_expanded,
        )  # fmt: skip
    return PreplanStage(
        bathymetry=bathymetry,
        maps=maps,
        names=names,
        starts=starts,
        start_speeds=np.array([v.start.speed for v in config.vehicles]),
        goals=goals,
        obstacles=obstacles,
        routes=tuple(routes),
        paths=tuple(paths),
    )


def _smooth(
    route: Route,
    maps: TerrainMaps,
    obstacles: tuple[CircleObstacle | PolygonObstacle, ...],
    clearance: float,
) -> FloatArray:
    """The route as a smooth curve within half a cell of it, never through no-go cells."""
    geometry = maps.cost_geometry
    cell = min(geometry.spacing_north, geometry.spacing_east)
    blocked = blocked_cells(maps.shifted_cost, geometry, obstacles=obstacles, clearance=clearance)
    return smooth_path(
        route.points,
        spacing=0.25 * cell,
        max_deviation=0.5 * cell,
        is_blocked=blocked_lookup(geometry, blocked),
    )


def _check_pairwise_clearance(
    names: tuple[str, ...], starts: FloatArray, goals: FloatArray, safety_radius: float
) -> None:
    limit = 2.0 * safety_radius
    for what, points in (("start", starts), ("goal", goals)):
        for i in range(len(names)):
            for j in range(i + 1, len(names)):
                distance = float(np.hypot(*(points[i, :2] - points[j, :2])))
                if distance < limit:
                    raise InfeasibleError(
                        f"vehicles {names[i]} and {names[j]} {what} {distance:.1f} m apart, "
                        f"closer than 2 r_c = {limit:g} m"
                    )


def _check_communication_ranges(
    config: MissionConfig, starts: FloatArray, goals: FloatArray
) -> None:
    """A pair that starts or ends out of its communication range can never satisfy it."""
    for comm in config.comms:
        i, j = config.vehicle_index(comm.pair[0]), config.vehicle_index(comm.pair[1])
        for what, points in (("start", starts), ("goal", goals)):
            distance = float(np.hypot(*(points[i, :2] - points[j, :2])))
            if distance > comm.max_range:
                raise InfeasibleError(
                    f"vehicles {comm.pair[0]} and {comm.pair[1]} {what} {distance:.0f} m apart, "
                    f"beyond their communication range max_range_m = {comm.max_range:g} m"
                )


def _obstacles(
    config: MissionConfig, grid: BathymetryGrid
) -> tuple[CircleObstacle | PolygonObstacle, ...]:
    obstacles: list[CircleObstacle | PolygonObstacle] = []
    for index, obstacle in enumerate(config.obstacles):
        if obstacle.polygon is not None:
            obstacles.append(PolygonObstacle(np.array(obstacle.polygon, dtype=np.float64)))
        else:
            assert obstacle.center is not None
            north, east = _resolve(obstacle.center, grid, f"obstacle[{index}] center")
            obstacles.append(CircleObstacle(north, east, obstacle.radius))
    return tuple(obstacles)


# --------------------------------------------------------------------------- stage 2


def _vehicle_models(config: MissionConfig) -> tuple[VehicleModel, ...]:
    order = config.solver.propeller_order
    return tuple(_model_for_type(vehicle.type, order) for vehicle in config.vehicles)


@cache
def _model_for_type(vehicle_type: str, propeller_order: int | None) -> VehicleModel:
    params = load_vehicle(vehicle_type)
    if propeller_order is not None:
        propeller_order = min(propeller_order, params.propeller.max_order)
    return build_vehicle_model(params, propeller_order=propeller_order)


@cache
def _trim_table(model: VehicleModel) -> tuple[FloatArray, FloatArray]:
    """Steady-surge propeller speed [rev/s] against surge speed [m/s], 0 … top speed."""
    speeds = np.linspace(0.0, top_speed(model), TRIM_SAMPLES)
    revolutions = np.array([trim_surge(model, float(speed)).n for speed in speeds])
    return speeds, revolutions


def run_deconfliction(
    config: MissionConfig, preplan: PreplanStage, models: tuple[VehicleModel, ...]
) -> DeconflictStage:
    """Stage 2: choose the horizon, deconflict in the coordination space, sample the timing.

    With ``fleet.horizon_s`` the nominal speeds are ``L_i / T``; when waiting makes the
    makespan exceed ``T`` the speeds are raised by the ratio (at most three times) as long as
    they stay within ``SPEED_MARGIN`` of each vehicle's top speed. With ``fleet.cruise_speed``
    ``T`` is the makespan at that speed, rounded up to the solver step. Every vehicle arrives
    at ``T`` (:func:`auvplan.deconfliction.retime_for_arrival`).
    """
    fleet = config.fleet
    lengths = np.array([path_length(path) for path in preplan.paths])
    limits = np.array([SPEED_MARGIN * top_speed(model) for model in models])
    dt = config.solver.dt
    if fleet.horizon is not None:
        horizon = fleet.horizon
        speeds = lengths / horizon
    else:
        assert fleet.cruise_speed is not None
        speeds = np.full(len(lengths), fleet.cruise_speed)
        horizon = float("nan")
    too_fast = np.flatnonzero(speeds > limits)
    if too_fast.size:
        i = int(too_fast[0])
        needed = lengths[i] / limits[i]
        what = (
            f"horizon_s = {horizon:g} s is too short"
            if fleet.horizon is not None
            else f"cruise_speed = {fleet.cruise_speed:g} m/s is too fast"
        )
        raise InfeasibleError(
            f"{what} for vehicle {preplan.names[i]}: its {lengths[i]:.0f} m path needs "
            f">= {needed:.0f} s at {limits[i]:.2f} m/s ({SPEED_MARGIN:.0%} of top speed)"
        )
    for _attempt in range(4):
        problem = CoordinationProblem(
            paths=preplan.paths,
            safety_radius=fleet.safety_radius,
            cruise_speeds=speeds,
            time_step=config.deconfliction.time_step,
            names=preplan.names,
        )
        coordination = deconflict(
            problem,
            method=config.deconfliction.method_for(len(lengths)),
            weight=config.deconfliction.weight,
            coarsening=config.deconfliction.coarsening,
        )
        makespan = float(np.max(coordination.arrival_times))
        if fleet.horizon is None:
            horizon = dt * math.ceil(makespan / dt - 1e-9)
            break
        if makespan <= horizon + 1e-9:
            break
        speeds = speeds * (makespan / horizon) * 1.02
        if np.any(speeds > limits):
            raise InfeasibleError(
                f"horizon_s = {horizon:g} s is too short: deconfliction needs {makespan:.0f} s "
                "within the vehicles' speed limits"
            )
    else:
        raise InfeasibleError(f"horizon_s = {horizon:g} s is too short after deconfliction")
    coordination = retime_for_arrival(coordination, problem, horizon)
    n_steps = round(horizon / dt)
    if not math.isclose(n_steps * dt, horizon, rel_tol=1e-9):
        raise InputError(f"solver.dt_s = {dt:g} s does not divide the horizon {horizon:g} s")
    time = dt * np.arange(n_steps + 1, dtype=np.float64)
    desired = _desired_states(problem, coordination, models, time, preplan)
    logger.info(
        "deconfliction (%s): horizon %.1f s, delays %s s, min separation %.2f m",
        coordination.method,
        horizon,
        np.array2string(np.asarray(coordination.delays), precision=1),
        coordination.certificate.min_separation,
    )
    return DeconflictStage(horizon, speeds, problem, coordination, time, desired)


def _desired_states(
    problem: CoordinationProblem,
    coordination: CoordinationResult,
    models: tuple[VehicleModel, ...],
    time: FloatArray,
    preplan: PreplanStage,
) -> FloatArray:
    """Desired state ``(north, east, psi, u, 0, r, n, n)`` per vehicle on ``time``."""
    positions = timed_positions(coordination, problem, time)
    headings = timed_headings(coordination, problem, time)
    n_vehicles = positions.shape[0]
    desired = np.zeros((n_vehicles, time.size, 8))
    for i in range(n_vehicles):
        desired[i, :, 0:2] = positions[i]
        psi = np.unwrap(headings[i])
        # keep the first desired heading within pi of the start heading
        psi += 2 * np.pi * np.round((preplan.starts[i, 2] - psi[0]) / (2 * np.pi))
        desired[i, :, 2] = psi
        speed = np.hypot(*np.gradient(positions[i], time, axis=0).T)
        desired[i, :, 3] = speed
        desired[i, :, 5] = np.gradient(psi, time)
        speeds, revolutions = _trim_table(models[i])
        desired[i, :, 6] = desired[i, :, 7] = np.interp(speed, speeds, revolutions)
    return desired


# --------------------------------------------------------------------------- stage 3


def _start_states(preplan: PreplanStage, models: tuple[VehicleModel, ...]) -> FloatArray:
    states = np.zeros((len(models), 8))
    for i, model in enumerate(models):
        speeds, revolutions = _trim_table(model)
        speed = preplan.start_speeds[i]
        n0 = float(np.interp(speed, speeds, revolutions))
        states[i] = (*preplan.starts[i], speed, 0.0, 0.0, n0, n0)
    return states


def _goal_poses(preplan: PreplanStage, desired: FloatArray) -> FloatArray:
    """Goals with headings unwrapped next to each desired trajectory's arrival heading."""
    goals = preplan.goals.copy()
    arrival = desired[:, -1, 2]
    goals[:, 2] += 2 * np.pi * np.round((arrival - goals[:, 2]) / (2 * np.pi))
    return goals


def _separation_margin(config: MissionConfig, desired: FloatArray) -> float:
    """Margin [m] on ``2 r_c`` for constraints imposed at the solver nodes only.

    Two vehicles closing at relative speed ``w`` that are ``D`` apart at two consecutive nodes
    come at most ``(w dt)² / (8 D)`` closer in between (straight-line relative motion); ``w``
    is bounded by 1.5 x twice the fastest desired speed. At least 1 % of ``2 r_c`` is kept.
    """
    separation = 2.0 * config.fleet.safety_radius
    relative_speed = 3.0 * float(np.max(desired[:, :, 3]))
    dip = (relative_speed * config.solver.dt) ** 2 / (8.0 * separation)
    return max(dip, 0.01 * separation)


def build_trajectory_problem(
    config: MissionConfig,
    preplan: PreplanStage,
    deconfliction: DeconflictStage,
    models: tuple[VehicleModel, ...],
    terrain_weight: float,
) -> tuple[TrajectoryProblem, FleetProblemFunctions]:
    """The stacked fleet problem for PRONTO (and the IPOPT reference)."""
    desired = deconfliction.desired_states
    names = list(preplan.names)
    circles = np.array(
        [(o.north, o.east, o.radius) for o in preplan.obstacles if isinstance(o, CircleObstacle)]
    ).reshape(-1, 3)
    comm_pairs = [
        (config.vehicle_index(a), config.vehicle_index(b), comm.max_range)
        for comm in config.comms
        for a, b in [comm.pair]
    ]
    functions = build_fleet_functions(
        [model.dynamics for model in models],
        [model.power for model in models],
        names,
        _goal_poses(preplan, desired),
        safety_radius=config.fleet.safety_radius,
        separation_margin=_separation_margin(config, desired),
        max_propeller_speeds=np.array([model.params.n_max for model in models]),
        obstacles=circles,
        comm_pairs=comm_pairs,
        terrain_weight=terrain_weight,
        energy_weight=config.weights.energy,
        terminal_weight=config.weights.terminal,
    )
    n_vehicles = len(models)
    x0 = _start_states(preplan, models).reshape(-1)
    stage_parameters = desired[:, :-1, :].transpose(1, 0, 2).reshape(-1, 8 * n_vehicles)
    regulator_q = np.tile([1.0, 1.0, 10.0, 10.0, 1.0, 10.0, 1e-3, 1e-3], n_vehicles)
    problem = TrajectoryProblem(
        dynamics=functions.dynamics,
        running_cost=functions.running_cost,
        terminal_cost=functions.terminal_cost,
        initial_state=x0,
        dt=config.solver.dt,
        n_steps=deconfliction.time.size - 1,
        stage_parameters=np.ascontiguousarray(stage_parameters),
        constraints=tuple(
            PathConstraint(block.function, kind=block.kind, name=block.name)
            for block in functions.constraints
        ),
        regulator_Q=np.diag(regulator_q),
        regulator_R=np.eye(2 * n_vehicles),
    )
    return problem, functions


def _initial_guess(deconfliction: DeconflictStage, n_vehicles: int) -> Trajectory:
    desired = deconfliction.desired_states
    states = desired.transpose(1, 0, 2).reshape(desired.shape[1], -1)
    inputs = np.zeros((desired.shape[1] - 1, 2 * n_vehicles))
    return Trajectory(states=np.ascontiguousarray(states), inputs=inputs)


def run_optimization(
    config: MissionConfig,
    preplan: PreplanStage,
    deconfliction: DeconflictStage,
    models: tuple[VehicleModel, ...],
    terrain_weight: float,
    *,
    callback: Callable[[Any], None] | None = None,
) -> OptimizedPlan:
    """Stage 3: PRONTO with barrier continuation from the projected desired trajectories."""
    problem, functions = build_trajectory_problem(
        config, preplan, deconfliction, models, terrain_weight
    )
    solver = config.solver
    options = ProntoOptions(
        tol=solver.tol,
        max_iter=solver.max_iter,
        eps_initial=solver.eps_initial,
        eps_final=solver.eps_final,
        eps_factor=solver.eps_factor,
        delta_initial=solver.delta_initial,
        eigenvalue_floor=solver.eigenvalue_floor,
        compile_c=solver.compile,
    )
    n_vehicles = len(models)
    result = solve_pronto(
        problem, _initial_guess(deconfliction, n_vehicles), options=options, callback=callback
    )
    logger.info(
        "PRONTO (terrain weight %g): %s after %d iterations, cost %.1f",
        terrain_weight,
        result.status.name,
        result.n_iter,
        result.cost,
    )
    return _evaluate_plan(preplan, deconfliction, models, functions, result, terrain_weight)


def _evaluate_plan(
    preplan: PreplanStage,
    deconfliction: DeconflictStage,
    models: tuple[VehicleModel, ...],
    functions: FleetProblemFunctions,
    result: ProntoResult,
    terrain_weight: float,
) -> OptimizedPlan:
    n_vehicles = len(models)
    time = deconfliction.time
    flat_states = result.trajectory.states
    flat_inputs = result.trajectory.inputs
    states = flat_states.reshape(time.size, n_vehicles, 8).transpose(1, 0, 2)
    inputs = flat_inputs.reshape(time.size - 1, n_vehicles, 2).transpose(1, 0, 2)
    held = np.vstack([flat_inputs, flat_inputs[-1:]])
    power_map = functions.power.map(time.size)
    power = np.asarray(power_map(flat_states.T, held.T)).reshape(n_vehicles, time.size)
    energy = np.asarray(np.trapezoid(power, time, axis=1), dtype=np.float64)
    arrival = np.hypot(*(states[:, -1, :2] - preplan.goals[:, :2]).T)
    information = _information_along(preplan.maps, states)

    dt = float(time[1] - time[0])
    gains = result.regulator_gains
    flown = np.stack(
        [
            replay_closed_loop(
                model,
                states[i],
                inputs[i],
                gains[:, 2 * i : 2 * i + 2, 8 * i : 8 * i + 8],
                dt,
                refinement=CHECK_REFINEMENT,
            )
            for i, model in enumerate(models)
        ]
    )
    fine_time = dt / CHECK_REFINEMENT * np.arange(flown.shape[1], dtype=np.float64)
    fine_positions = flown[:, :, :2]
    tracking_error = np.max(
        np.hypot(*(flown[:, ::CHECK_REFINEMENT, :2] - states[:, :, :2]).transpose(2, 0, 1)),
        axis=1,
    )
    fine_distances: dict[str, FloatArray] = {}
    separations: dict[str, dict[str, float]] = {name: {} for name in preplan.names}
    names = preplan.names
    for i in range(n_vehicles):
        for j in range(i + 1, n_vehicles):
            distance = np.hypot(*(fine_positions[i] - fine_positions[j]).T)
            fine_distances[f"{names[i]} / {names[j]}"] = distance
            separations[names[i]][names[j]] = separations[names[j]][names[i]] = float(
                np.min(distance)
            )
        for k, obstacle in enumerate(preplan.obstacles):
            distance = distance_to_obstacle(obstacle, *fine_positions[i].T)
            fine_distances[f"{names[i]} / obstacle {k}"] = distance
            separations[names[i]][f"obstacle {k}"] = float(np.min(distance))
    return OptimizedPlan(
        result=result,
        terrain_weight=terrain_weight,
        states=states,
        inputs=inputs,
        power=power,
        energy=energy,
        arrival_error=arrival,
        terrain_information=information,
        separations=separations,
        fine_time=fine_time,
        fine_distances=fine_distances,
        tracking_error=tracking_error,
    )


def _information_along(maps: TerrainMaps, states: FloatArray) -> FloatArray:
    """Mean information-map value (eq. 13, fine grid) along each trajectory."""
    geometry = maps.bathymetry.geometry
    field = np.nan_to_num(maps.information, nan=0.0)
    interpolator = RegularGridInterpolator(
        (geometry.north, geometry.east), field, bounds_error=False, fill_value=0.0
    )
    return np.array([float(np.mean(interpolator(track[:, :2]))) for track in states])
