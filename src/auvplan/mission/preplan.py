"""Stage 1 (SPEC §1): terrain, maps (eq. 13-15), resolved poses, one smoothed A* route each."""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Final

import numpy as np

from auvplan._typing import BoolArray, FloatArray
from auvplan.deconfliction import check_endpoint_clearance
from auvplan.errors import InfeasibleError, InputError
from auvplan.io.bathymetry import read_bathymetry
from auvplan.mission.comm_routes import comm_corridor, comm_margin
from auvplan.mission.config import (
    CommConfig,
    MapsConfig,
    MissionConfig,
    PlannerConfig,
    TerrainConfig,
)
from auvplan.mission.current import cell_currents, current_move_factor, load_current
from auvplan.mission.models import vehicle_model
from auvplan.mission.navigation import NavigationChoice, VehicleNavigation, vehicle_navigation
from auvplan.mission.progress import ProgressReporter, no_progress
from auvplan.mission.zones import resolve_obstacles, resolve_position
from auvplan.navigation.depth import depth_at
from auvplan.ocean import CurrentField
from auvplan.planning import (
    CircleObstacle,
    EdgeModel,
    Obstacle,
    Route,
    blocked_cells,
    blocked_lookup,
    plan_route,
    resample_at_spacing,
    resample_polyline,
    skirt_discs,
    smooth_path,
)
from auvplan.planning.belief import BeliefModel
from auvplan.terrain import BathymetryGrid, MapParameters, TerrainMaps, compute_terrain_maps
from auvplan.terrain.synthetic import synthetic_bank
from auvplan.vehicle import optimal_cruise_speed, turning_radius

logger = logging.getLogger(__name__)

#: Distance from a right-angle corner to the arc of radius ``R`` that rounds it, per unit
#: ``R``: ``√2 − 1`` (a grid route turns by 90° in two 45° steps a cell or two apart).
CORNER_CUT: Final = math.sqrt(2.0) - 1.0
#: Radius of the disc about another vehicle's goal that a path skirts, per ``2 r_c`` (10 %
#: over the deconfliction grid's largest margin, 5 % of ``2 r_c``, plus the chords' sagitta).
GOAL_SKIRT: Final = 1.2


@dataclass(frozen=True)
class PreplanStage:
    """Stage 1: terrain, maps, resolved poses and one A* route per vehicle.

    ``starts`` and ``goals`` have shape ``(n_vehicles, 3)``: north, east [m], psi [rad];
    ``start_speeds`` [m/s]. ``paths`` are the smoothed routes (``(n_i, 2)`` north/east [m]);
    ``obstacle_names`` label ``obstacles``; ``current`` is the ocean current (None: still
    water); ``navigation`` says how each route was chosen for navigation (None: the paper's
    or the crossed edge model).
    """

    bathymetry: BathymetryGrid
    maps: TerrainMaps
    names: tuple[str, ...]
    starts: FloatArray
    start_speeds: FloatArray
    goals: FloatArray
    obstacles: tuple[Obstacle, ...]
    obstacle_names: tuple[str, ...]
    routes: tuple[Route, ...]
    paths: tuple[FloatArray, ...]
    current: CurrentField | None = None
    navigation: tuple[NavigationChoice, ...] | None = None


def load_terrain(terrain: TerrainConfig) -> BathymetryGrid:
    """The mission's bathymetry: a file (any supported format), a sample or the synthetic bank."""
    window = terrain.window
    return read_terrain(
        terrain.path,
        seed=terrain.seed,
        window_north=window.north,
        window_east=window.east,
        window_lat=window.lat,
        window_lon=window.lon,
    )


def read_terrain(
    file: str | Path | None,
    *,
    seed: int = 7,
    window_north: tuple[float, float] | None = None,
    window_east: tuple[float, float] | None = None,
    window_lat: tuple[float, float] | None = None,
    window_lon: tuple[float, float] | None = None,
) -> BathymetryGrid:
    """A bathymetry file (any format of :func:`~auvplan.io.bathymetry.read_bathymetry`) or the bank.

    Parameters
    ----------
    file : str, Path or None
        The bathymetry file; None for the synthetic bank
        (:func:`~auvplan.terrain.synthetic.synthetic_bank`).
    seed : int
        Seed of the synthetic bank (unused for a file).
    window_north, window_east : (float, float), optional
        Crop to these north and east ranges [m].
    window_lat, window_lon : (float, float), optional
        Crop to these latitude and longitude ranges [deg] (files with a geographic reference).

    Raises
    ------
    InputError
        If the synthetic bank is cropped in lat/lon, or a window leaves no cell.
    DataFormatError
        If the file cannot be read (:func:`~auvplan.io.bathymetry.read_bathymetry`).
    """
    if file is None:
        if window_lat is not None or window_lon is not None:
            raise InputError(
                "the synthetic bank has no geographic reference: crop it in north/east, not lat/lon"
            )
        grid = synthetic_bank(seed=seed)
        return grid.window(window_north, window_east) if window_north or window_east else grid
    return read_bathymetry(
        file,
        window_north=window_north,
        window_east=window_east,
        window_lat=window_lat,
        window_lon=window_lon,
    )


def compute_maps(bathymetry: BathymetryGrid, maps: MapsConfig) -> TerrainMaps:
    """The information, excitation and cost maps of eq. 13-15."""
    parameters = MapParameters(
        exponent=maps.exponent, block=maps.block, omega=maps.omega, weight=maps.weight
    )
    return compute_terrain_maps(bathymetry, parameters)


#: A goal closer than this [m] to its vehicle's start is that start: the path between them has
#: no direction to smooth, to leave the start along or to time (a mission moves every vehicle).
MIN_TRAVEL: Final = 1e-3


def check_goals_leave_starts(names: tuple[str, ...], starts: FloatArray, goals: FloatArray) -> None:
    """Raise InputError naming a vehicle whose goal lies within :data:`MIN_TRAVEL` of its start.

    ``starts`` and ``goals`` have shape ``(n_vehicles, >= 2)``: north/east [m] first.
    """
    for name, start, goal in zip(names, starts, goals, strict=True):
        distance = float(np.hypot(*(goal[:2] - start[:2])))
        if distance < MIN_TRAVEL:
            raise InputError(
                f"{name}: goal ({goal[0]:g}, {goal[1]:g}) m is {distance:g} m from the start "
                f"({start[0]:g}, {start[1]:g}) m; give a goal at least {MIN_TRAVEL * 1e3:g} mm "
                "away from the start"
            )


def check_depth_above_seabed(
    depth: float, bathymetry: BathymetryGrid, names: tuple[str, ...], paths: tuple[FloatArray, ...]
) -> None:
    """Raise InputError unless the plan's constant ``depth`` [m] is above every path's seabed.

    ``paths`` are the smoothed paths, each of shape ``(n_points, 2)``: north/east [m]. The
    seabed is the bilinear depth of ``bathymetry`` (:func:`~auvplan.navigation.depth.depth_at`)
    at the path's points; the message names the vehicle and place of the shallowest seabed
    along the paths, the deepest along them and over the map, and the largest usable depth.
    """
    if depth <= 0.0:
        return  # at the surface: above every water cell
    seabeds = [depth_at(bathymetry, path[:, 0], path[:, 1]) for path in paths]
    shallowest = [float(np.nanmin(seabed)) for seabed in seabeds]
    index = int(np.argmin(shallowest))
    if shallowest[index] > depth:
        return
    point = paths[index][int(np.nanargmin(seabeds[index]))]
    deepest = max(float(np.nanmax(seabed)) for seabed in seabeds)
    raise InputError(
        f"mission.depth_m = {depth:g} m is not above the seabed along {names[index]}'s path "
        f"(seabed {shallowest[index]:.1f} m deep at north {point[0]:.0f} m, east "
        f"{point[1]:.0f} m; the deepest seabed is {deepest:.1f} m along the paths and "
        f"{float(np.nanmax(bathymetry.depth)):.1f} m over the map): give depth_m < "
        f"{math.floor(10.0 * shallowest[index]) / 10.0:g} m"
    )


def check_seabed_clearance(
    min_altitudes: tuple[float, ...],
    bathymetry: BathymetryGrid,
    names: tuple[str, ...],
    paths: tuple[FloatArray, ...],
) -> None:
    """Raise InputError where a path's seabed is shallower than its vehicle's minimum altitude.

    For ``[mission] altitude_m`` plans: vehicle ``i`` stays at least ``min_altitudes[i]`` [m]
    (its ``[vertical] min_altitude``) above the seabed and never above the surface, which is
    impossible where the seabed (the bilinear depth of ``bathymetry`` at the points of
    ``paths[i]``, each ``(n_points, 2)`` north/east [m]) is shallower than that.
    """
    for name, path, clearance in zip(names, paths, min_altitudes, strict=True):
        seabed = depth_at(bathymetry, path[:, 0], path[:, 1])
        if not np.nanmin(seabed) < clearance:
            continue
        point = path[int(np.nanargmin(seabed))]
        raise InputError(
            f"{name}'s path crosses a seabed {float(np.nanmin(seabed)):.1f} m deep at north "
            f"{point[0]:.0f} m, east {point[1]:.0f} m, shallower than its vehicle's "
            f"[vertical] min_altitude = {clearance:g} m: move its start or goal, add an "
            "obstacle over the shoal, or use a vehicle file with a smaller min_altitude"
        )


def check_communication_ranges(
    comms: tuple[CommConfig, ...], names: tuple[str, ...], starts: FloatArray, goals: FloatArray
) -> None:
    """A pair that starts or ends out of its communication range can never satisfy it."""
    for comm in comms:
        i, j = names.index(comm.pair[0]), names.index(comm.pair[1])
        for what, points in (("start", starts), ("goal", goals)):
            distance = float(np.hypot(*(points[i, :2] - points[j, :2])))
            if distance > comm.max_range:
                raise InfeasibleError(
                    f"vehicles {comm.pair[0]} and {comm.pair[1]} {what} {distance:.0f} m apart, "
                    f"beyond their communication range max_range_m = {comm.max_range:g} m"
                )


def goal_keep_outs(
    starts: FloatArray, goals: FloatArray, index: int, clearance: float, cell: float
) -> tuple[CircleObstacle, ...]:
    """Discs around the other vehicles' goals that vehicle ``index``'s route keeps out of.

    A vehicle parked at its goal cannot be passed within ``2 r_c`` by any schedule, so each
    route avoids the others' goals by ``2 r_c`` plus a cell (A* blocks ``radius + clearance``
    with ``clearance = r_c``). Discs that would cover the vehicle's own start or goal are left
    out (then only timing can help, and deconfliction says so).
    """
    radius = clearance + cell
    own = np.array([starts[index, :2], goals[index, :2]])
    return tuple(
        CircleObstacle(float(goal[0]), float(goal[1]), radius)
        for other, goal in enumerate(goals[:, :2])
        if other != index and np.min(np.hypot(*(own - goal).T)) > radius + clearance + cell
    )


def courses_over_ground(
    starts: FloatArray, speeds: FloatArray, current: CurrentField | None
) -> FloatArray:
    """Course over ground [rad] of each start pose ``(north, east, ψ)`` at its surge [m/s].

    In still water the heading; in a current the direction of ``u (cos ψ, sin ψ) + v_c`` at
    ``t = 0`` (the heading where that is under 1 mm/s).

    Examples
    --------
    >>> from auvplan.ocean import UniformCurrent
    >>> pose = np.array([[0.0, 0.0, 0.0]])
    >>> float(np.degrees(courses_over_ground(pose, np.array([0.5]), UniformCurrent(0.0, 0.5))[0]))
    45.0
    """
    if current is None:
        return starts[:, 2].copy()
    v_n, v_e = current.velocity(starts[:, 0], starts[:, 1], np.zeros(len(starts)))
    north = speeds * np.cos(starts[:, 2]) + v_n
    east = speeds * np.sin(starts[:, 2]) + v_e
    return np.where(np.hypot(north, east) > 1e-3, np.arctan2(east, north), starts[:, 2])


def _lead_in(
    points: FloatArray,
    heading: float,
    radius: float,
    spacing: float,
    is_blocked: Callable[[FloatArray, FloatArray], BoolArray],
) -> tuple[FloatArray, FloatArray]:
    """The route polyline split into a turn from the start ``heading`` [rad] and the rest.

    For a vehicle that turns no tighter than ``radius`` [m]: the start pose is the
    optimiser's fixed initial state, so a path that leaves it at an angle asks a
    rudder-steered vehicle for a turn it cannot make (a REMUS 100 turns on 44 m), and the
    projection saturates the rudder. A route point ``2 R`` or more from the start (else its
    end) is reached the Dubins way, a turn of radius ``R`` towards it from the start pose and
    the tangent on to it (:func:`turn_towards`; turning away from it, the long way round,
    where the short way is blocked), and the route points before it are dropped: the first
    such point whose way crosses no blocked cell (``is_blocked``). Returns the
    turn's points and the polyline from its last point on (the tangent and the rest of the
    route), to be smoothed on its own so that the path leaves along the heading. No turn
    (only the start point) where every way is blocked, and for a vehicle whose turns are
    shorter than the path's sample ``spacing`` [m].
    """
    unchanged = points[:1], points
    if radius < spacing or len(points) < 2:
        return unchanged
    far = np.flatnonzero(np.hypot(*(points[1:] - points[0]).T) >= 2.0 * radius) + 1
    for join in far if far.size else [len(points) - 1]:
        for the_long_way in (False, True):
            turn = turn_towards(points[0], heading, points[join], radius, spacing, the_long_way)
            if turn is None:
                continue
            way = resample_polyline(np.vstack([turn, points[join : join + 1]]), 0.5 * spacing)
            if not np.any(is_blocked(way[:, 0], way[:, 1])):
                return turn, np.vstack([turn[-1:], points[join:]])
    return unchanged


def turn_towards(
    start: FloatArray,
    heading: float,
    target: FloatArray,
    radius: float,
    spacing: float,
    the_long_way: bool = False,
) -> FloatArray | None:
    """Points [m] of the turn of ``radius`` from ``start`` (heading ``ψ_0`` [rad]) to ``target``.

    The turn is to the side of ``target`` (to the other side ``the_long_way``; centre
    ``c = p_0 + s R (−sin ψ_0, cos ψ_0)``, ``s = +1`` to the right, heading from north
    clockwise) and ends where the heading points
    at it, the tangent point: with ``v = target − c``, ``d = |v|`` and ``L = √(d² − R²)``
    the tangent's length, the heading there is ``ψ* = ∠v + s atan2(R, L)``. Returns the arc
    sampled at most ``spacing`` apart, from ``start`` (exactly) to the tangent point, or
    ``None`` when ``target`` lies within the circle (``d ≤ R``: no tangent).

    Examples
    --------
    >>> turn = turn_towards(np.zeros(2), 0.0, np.array([10.0, 20.0]), 10.0, 1.0)
    >>> np.round(turn[-1], 6).tolist()  # a quarter circle to the right, then due east
    [10.0, 10.0]
    """
    right = np.array([-np.sin(heading), np.cos(heading)])
    offset = target - start
    side = (1.0 if right @ offset >= 0.0 else -1.0) * (-1.0 if the_long_way else 1.0)
    centre = start + side * radius * right
    v = target - centre
    distance = float(np.hypot(*v))
    if distance <= radius:
        return None
    tangent = np.arctan2(v[1], v[0]) + side * np.arctan2(radius, np.sqrt(distance**2 - radius**2))
    turned = (side * (tangent - heading)) % (2.0 * np.pi)
    n_steps = max(1, math.ceil(turned * radius / spacing))
    psi = heading + side * turned * np.linspace(0.0, 1.0, n_steps + 1)
    arc = centre - side * radius * np.column_stack([-np.sin(psi), np.cos(psi)])
    arc[0] = start  # exactly (the optimiser's initial state)
    return arc


def _skirt_goals(
    path: FloatArray,
    goals: FloatArray,
    index: int,
    clearance: float,
    cell: float,
    is_blocked: Callable[[FloatArray, FloatArray], BoolArray],
) -> FloatArray:
    """``path`` of vehicle ``index`` detoured along the rims of the other goals' discs.

    The discs have radius :data:`GOAL_SKIRT` ``× 2 r_c`` (``2 r_c = 2 · clearance``), shrunk
    where the vehicle's own start or goal is nearer; a repaired path is resampled every
    ``min(cell / 4, r_c / 2)`` so that its chords stay outside too (:func:`skirt_discs`).
    """
    own = np.array([path[0], path[-1]])
    others = np.array([goal[:2] for other, goal in enumerate(goals) if other != index])
    if len(others) == 0:
        return path
    nearest = np.min(np.hypot(*(own[:, None, :] - others[None, :, :]).transpose(2, 0, 1)), axis=0)
    radii = np.minimum(GOAL_SKIRT * 2.0 * clearance, (1.0 - 1e-6) * nearest)
    skirted = skirt_discs(path, others, radii, is_blocked=is_blocked)
    if skirted is path:
        return path
    return resample_polyline(skirted, min(0.25 * cell, 0.5 * clearance))


def _with_discs(
    is_blocked: Callable[[FloatArray, FloatArray], BoolArray],
    discs: tuple[CircleObstacle, ...],
    radius: float,
) -> Callable[[FloatArray, FloatArray], BoolArray]:
    """``is_blocked`` that also blocks points within ``radius`` [m] of the discs' centres."""
    if not discs:
        return is_blocked
    centres = np.array([(disc.north, disc.east) for disc in discs])

    def blocked(north: FloatArray, east: FloatArray) -> BoolArray:
        near = np.hypot(north[..., None] - centres[:, 0], east[..., None] - centres[:, 1])
        inside: BoolArray = np.any(near < radius, axis=-1)
        return is_blocked(north, east) | inside

    return blocked


def _straight_clear(
    start: FloatArray,
    goal: FloatArray,
    spacing: float,
    is_blocked: Callable[[FloatArray, FloatArray], BoolArray],
) -> bool:
    """Whether the straight line from ``start`` to ``goal`` [m] crosses no blocked point.

    The line is sampled every ``spacing`` [m].
    """
    n = max(2, math.ceil(float(np.hypot(*(goal - start))) / spacing) + 1)
    line = start[None, :] + np.linspace(0.0, 1.0, n)[:, None] * (goal - start)[None, :]
    return not bool(np.any(is_blocked(line[:, 0], line[:, 1])))


def plan_routes(
    maps: TerrainMaps,
    names: tuple[str, ...],
    starts: FloatArray,
    goals: FloatArray,
    obstacles: tuple[Obstacle, ...],
    *,
    obstacle_names: tuple[str, ...] = (),
    clearance: float,
    planner: PlannerConfig,
    turning_radii: FloatArray | None = None,
    start_courses: FloatArray | None = None,
    current: CurrentField | None = None,
    water_speeds: FloatArray | None = None,
    navigation: tuple[VehicleNavigation, ...] | None = None,
    comms: tuple[CommConfig, ...] = (),
    progress: ProgressReporter = no_progress,
) -> tuple[tuple[Route, ...], tuple[FloatArray, ...], tuple[NavigationChoice, ...] | None]:
    """One A* route per vehicle on the shifted cost map, and its smoothed curve.

    The curve stays within half a cell of the route, or within the corner cut
    :data:`CORNER_CUT` ``× R`` of a vehicle that turns no tighter than ``R``
    (``turning_radii`` [m]; e.g. a torpedo AUV's rudder turn), whichever is wider, so that
    the right-angle turns of the grid route are rounded to the vehicle's turning radius, and
    leaves the start along ``start_courses`` [rad] (default: the start headings).
    In a ``current``, each move weighs the time it takes at the vehicle's speed through the
    water (``water_speeds`` [m/s]; :func:`~auvplan.mission.current.current_move_factor`), so
    routes ride favourable water and avoid moves the current bars.
    ``progress`` is told of each vehicle's search (stage ``"A*"``, one unit per vehicle).
    ``obstacle_names`` label ``obstacles`` in the errors of a start or goal they cover.
    """
    geometry = maps.cost_geometry
    cell = min(geometry.spacing_north, geometry.spacing_east)
    blocked = blocked_cells(maps.shifted_cost, geometry, obstacles=obstacles, clearance=clearance)
    is_blocked = blocked_lookup(geometry, blocked)
    courses = starts[:, 2] if start_courses is None else start_courses
    velocity = None if current is None else cell_currents(geometry, current)
    cost = maps.shifted_cost
    if navigation is not None:  # length is the energy proxy
        cost = np.where(np.isfinite(cost), 1.0, np.nan)
    edge_model = EdgeModel.CROSSED if navigation is not None else EdgeModel(planner.edge_model)
    routes, choices = [], []
    paths: list[FloatArray] = []
    with progress("A*", total=len(names)) as advance:
        for index, name in enumerate(names):
            factor = (
                None
                if velocity is None or water_speeds is None
                else current_move_factor(geometry, velocity, float(water_speeds[index]))
            )

            # whether the energy-only plan can fly the straight line (the navigation's energy base)
            clear = navigation is not None and _straight_clear(
                starts[index, :2], goals[index, :2], 0.25 * cell, is_blocked
            )

            def search(
                extra: tuple[Obstacle, ...],
                index: int = index,
                name: str = name,
                factor: FloatArray | None = factor,
                clear: bool = clear,
            ) -> tuple[Route, NavigationChoice | None]:
                def one(belief: BeliefModel | None, bottleneck: bool = False) -> Route:
                    return plan_route(
                        cost,
                        geometry,
                        (float(starts[index, 0]), float(starts[index, 1])),
                        (float(goals[index, 0]), float(goals[index, 1])),
                        obstacles=obstacles + extra,
                        obstacle_names=obstacle_names,
                        clearance=clearance,
                        edge_model=edge_model,
                        move_factor=factor,
                        name=name,
                        belief=belief,
                        bottleneck=bottleneck,
                    )

                if navigation is None:
                    return one(None), None
                return navigation[index].route(one, clear)

            radius = 0.0 if turning_radii is None else float(turning_radii[index])
            deviation = max(0.5 * cell, CORNER_CUT * radius)
            corridor = comm_corridor(
                index, names, comms, paths, starts, goals,
                geometry=geometry, clearance=clearance, deviation=deviation,
            )  # fmt: skip
            # the keep-outs may close every way (then timing must do it), and so may a corridor
            keep_outs = goal_keep_outs(starts, goals, index, clearance, cell)
            attempts = list(dict.fromkeys(
                [(keep_outs, corridor), ((), corridor), (keep_outs, ()), ((), ())]
            ))  # fmt: skip
            for number, (keep_out, within) in enumerate(attempts, start=1):
                try:
                    route, choice = search(keep_out + within)
                    break
                except InfeasibleError:
                    if number == len(attempts):
                        raise
            if corridor and not within:
                logger.warning(
                    "%s: no route stays %.0f m inside the communication range of its "
                    "partner's path; routed regardless, the optimiser may not keep them in range",
                    name, comm_margin(clearance, deviation),
                )  # fmt: skip
            routes.append(route)
            if choice is not None:
                logger.info(
                    "navigation %s: %s route, predicted error RMS %.1f m, peak %.1f m "
                    "(shortest route: %.1f m, %.1f m), energy %+.1f %%",
                    name, "budget" if choice.budget_m is not None else "energy-only",
                    choice.rms_m, choice.peak_m, choice.energy_only_rms_m,
                    choice.energy_only_peak_m, 100.0 * choice.energy_increase,
                )  # fmt: skip
            choices.append(choice)
            # near the route, never through a no-go cell nor within 2 r_c of a kept-out goal
            keep_off = 2.0 * clearance + 0.25 * cell
            kept_out = _with_discs(is_blocked, keep_out, keep_off)
            # the turn from the start keeps 2 r_c from the others' starts where it can (each
            # vehicle is at its start at t = 0: a turn swinging past another's may have no
            # schedule), else it may pass them (timing may still separate the vehicles)
            other_starts = tuple(
                CircleObstacle(float(north), float(east), clearance)
                for other, (north, east) in enumerate(starts[:, :2])
                if other != index
            )
            for checker in (
                _with_discs(kept_out, other_starts, keep_off),
                kept_out,
            ):
                turn, rest = _lead_in(
                    route.points, float(courses[index]), radius, 0.25 * cell, checker
                )
                if len(turn) > 1:
                    break
            path = smooth_path(
                rest, spacing=0.25 * cell, max_deviation=deviation, is_blocked=kept_out
            )
            if len(turn) > 1:  # the turn and the smoothed rest, sampled alike
                path = resample_at_spacing(np.vstack([turn[:-1], path]), 0.25 * cell)
            paths.append(_skirt_goals(path, goals, index, clearance, cell, is_blocked))
            logger.info(
                "A* %s: %d cells, cost %.1f, %d expanded", name, len(route.cells), route.cost,
                route.n_expanded,
            )  # fmt: skip
            advance(name)
    navigated = tuple(c for c in choices if c is not None)
    return tuple(routes), tuple(paths), navigated if navigation is not None else None


def run_preplan(config: MissionConfig, *, progress: ProgressReporter = no_progress) -> PreplanStage:
    """Stage 1: load terrain, compute the maps, resolve poses, plan and smooth A* routes.

    ``progress`` is told of each vehicle's A* search (:func:`plan_routes`).
    """
    bathymetry = load_terrain(config.terrain)
    maps = compute_maps(bathymetry, config.maps)
    current = load_current(config, bathymetry)
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
        [(*resolve_position(v.start, bathymetry, f"vehicle {v.name} start"), v.start.psi)
         for v in config.vehicles]
    )  # fmt: skip
    goals = np.array(
        [(*resolve_position(v.goal, bathymetry, f"vehicle {v.name} goal"), v.goal.psi)
         for v in config.vehicles]
    )  # fmt: skip
    check_goals_leave_starts(names, starts, goals)
    check_endpoint_clearance(names, starts[:, :2], goals[:, :2], 2.0 * config.fleet.safety_radius)
    check_communication_ranges(config.comms, names, starts, goals)
    obstacles, obstacle_names = resolve_obstacles(config, bathymetry)
    models = [vehicle_model(v.type, config.solver.harmonics) for v in config.vehicles]
    start_speeds = np.array([v.start.speed for v in config.vehicles])
    cruise = config.fleet.cruise_speed
    navigation = None
    if config.planner.edge_model == "navigation":
        navigation = vehicle_navigation(
            maps, config.navigation, names, models, np.hypot(*(goals[:, :2] - starts[:, :2]).T),
            horizon=config.fleet.horizon, cruise_speed=cruise, vehicle_depth=config.mission.depth,
            weight=config.weights.navigation, altitude=config.mission.altitude,
        )  # fmt: skip
    routes, paths, choices = plan_routes(
        maps, names, starts, goals, obstacles, obstacle_names=obstacle_names,
        clearance=config.fleet.safety_radius, planner=config.planner,
        turning_radii=np.array([turning_radius(model) for model in models]),
        start_courses=courses_over_ground(starts, start_speeds, current),
        current=current,
        navigation=navigation,
        comms=config.comms,
        water_speeds=None if current is None else np.array(
            [cruise if cruise is not None else optimal_cruise_speed(model).speed
             for model in models]
        ),
        progress=progress,
    )  # fmt: skip
    if config.mission.altitude is None:
        check_depth_above_seabed(config.mission.depth, bathymetry, names, paths)
    else:
        clearances = tuple(model.vehicle.depth_limits.min_altitude for model in models)
        check_seabed_clearance(clearances, bathymetry, names, paths)
    return PreplanStage(
        bathymetry=bathymetry,
        maps=maps,
        names=names,
        starts=starts,
        start_speeds=start_speeds,
        goals=goals,
        obstacles=obstacles,
        obstacle_names=obstacle_names,
        routes=routes,
        paths=paths,
        current=current,
        navigation=choices,
    )
