"""Stage 2 (SPEC §2): the common horizon, coordination-space time laws, desired states.

The horizon policy: with ``fleet.horizon_s`` the nominal speeds are ``L_i / T``; when waiting
makes the makespan exceed ``T`` the speeds are raised by the ratio (at most three times) as
long as they stay within ``SPEED_MARGIN`` of each vehicle's top speed. With
``fleet.cruise_speed`` ``T`` is the makespan at that speed, rounded up to the solver interval.
Every vehicle arrives at ``T`` (:func:`auvplan.deconfliction.retime_for_arrival`). The desired
states on the solver grid come from :func:`auvplan.vehicle.reference_states`.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Final

import numpy as np

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
from auvplan.mission.config import DeconflictionConfig, FleetConfig
from auvplan.mission.current import (
    check_crossable,
    mean_ground_speed,
    path_ground_speeds,
    segment_times,
)
from auvplan.mission.fleet import FleetLayout
from auvplan.ocean import CurrentField, through_water
from auvplan.planning import path_length
from auvplan.vehicle import (
    VehicleModel,
    max_surge_acceleration,
    minimum_useful_speed,
    reference_states,
    top_speed,
    turning_radius,
)

logger = logging.getLogger(__name__)

#: Fraction of a vehicle's top speed that the mean speed along its path may use.
SPEED_MARGIN: Final = 0.85
#: Speed-raising rounds when deconfliction overruns a fixed horizon.
HORIZON_ATTEMPTS: Final = 4
#: Rounds of limits and speeds in a time-varying current (:func:`speeds_in_current`).
LIMIT_ROUNDS: Final = 4
#: Fraction of the steady turn rate on the tightest turning radius that the desired heading
#: uses to turn from the start heading and onto the goal heading.
TURN_RATE_FRACTION: Final = 0.5


@dataclass(frozen=True)
class DeconflictStage:
    """Stage 2: horizon, coordination-space time laws and the desired trajectories.

    ``desired_states`` holds one ``(n_t, n_x_i)`` array per vehicle of ``layout`` on ``time``
    (the solver grid of interval ``dt`` [s]).
    """

    layout: FleetLayout
    horizon: float
    dt: float
    cruise_speeds: FloatArray
    problem: CoordinationProblem
    coordination: CoordinationResult
    time: FloatArray
    desired_states: tuple[FloatArray, ...]


def solver_steps(horizon: float, dt: float) -> int:
    """The number of solver steps of interval ``dt`` [s] in the horizon ``horizon`` [s].

    Raises
    ------
    InputError
        When ``horizon / dt`` is not an integer.
    """
    n_steps = round(horizon / dt)
    if n_steps < 1 or not math.isclose(n_steps * dt, horizon, rel_tol=1e-9):
        raise InputError(f"solver.dt_s = {dt:g} s does not divide the horizon {horizon:g} s")
    return n_steps


def _nominal_speeds(
    fleet: FleetConfig,
    lengths: FloatArray,
    limits: FloatArray,
    names: tuple[str, ...],
    cruise: FloatArray | None = None,
) -> tuple[FloatArray, float]:
    """Speeds [m/s] and horizon [s] (NaN when derived later) before deconfliction.

    ``cruise``: in a current, the ground speeds at ``fleet.cruise_speed`` through the water
    (NaN where it cannot be held); they are capped at ``limits``.
    """
    if fleet.horizon is not None:
        horizon, speeds = fleet.horizon, lengths / fleet.horizon
    elif cruise is not None:
        return np.fmin(limits, cruise), float("nan")
    else:
        assert fleet.cruise_speed is not None
        horizon, speeds = float("nan"), np.full(len(lengths), fleet.cruise_speed)
    too_fast = np.flatnonzero(speeds > limits)
    if too_fast.size:
        i = int(too_fast[0])
        what = (
            f"horizon_s = {horizon:g} s is too short"
            if fleet.horizon is not None
            else f"cruise_speed = {fleet.cruise_speed:g} m/s is too fast"
        )
        raise InfeasibleError(
            f"{what} for vehicle {names[i]}: its {lengths[i]:.0f} m path needs "
            f">= {lengths[i] / limits[i]:.0f} s at {limits[i]:.2f} m/s ({SPEED_MARGIN:.0%} of top "
            "speed)"
        )
    return speeds, horizon


def run_deconfliction(
    layout: FleetLayout,
    paths: tuple[FloatArray, ...],
    start_headings: FloatArray,
    goal_headings: FloatArray,
    *,
    fleet: FleetConfig,
    settings: DeconflictionConfig,
    dt: float,
    current: CurrentField | None = None,
) -> DeconflictStage:
    """Stage 2: choose the horizon, deconflict in the coordination space, sample the timing.

    Parameters
    ----------
    layout : FleetLayout
        The vehicles.
    paths : tuple of ndarray of shape (n_i, 2)
        Smoothed pre-planned paths, north/east [m].
    start_headings, goal_headings : ndarray of shape (n_vehicles,)
        Start and goal headings [rad]; the desired headings turn from and onto them
        (:func:`desired_states`).
    fleet, settings : FleetConfig, DeconflictionConfig
        Timing, safety radius and coordination-space settings.
    dt : float
        Solver (control) interval [s].
    current : CurrentField, optional
        The ocean current (None: still water); speeds and their limits are then ground
        speeds along each path in the current when the vehicle passes
        (:func:`speeds_in_current`).
    """
    names = layout.names
    lengths = np.array([path_length(path) for path in paths])
    limits, slowest, cruise = speed_range(layout, paths, lengths, fleet=fleet, current=current)
    speeds, horizon = _nominal_speeds(fleet, lengths, limits, names, cruise)
    for _attempt in range(HORIZON_ATTEMPTS):
        problem = coordination_problem(
            layout, paths, speeds, slowest, fleet=fleet, settings=settings
        )
        coordination = deconflict(
            problem,
            method=settings.method,
            weight=settings.weight,
            coarsening=settings.coarsening,
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
    solver_steps(horizon, dt)  # refused before the retiming when dt does not divide it
    coordination = retime_for_arrival(coordination, problem, horizon)
    stage = sampled_stage(
        layout, problem, coordination, horizon, dt, (start_headings, goal_headings), current
    )
    logger.info(
        "deconfliction (%s%s): horizon %.1f s, delays %s s, min separation %.2f m",
        coordination.method,
        f", {coordination.fallback}" if coordination.fallback else "",
        horizon,
        ", ".join(f"{delay:.1f}" for delay in np.round(coordination.delays, 1) + 0.0),  # no -0.0
        coordination.certificate.min_separation,
    )
    return stage


def speed_range(
    layout: FleetLayout,
    paths: tuple[FloatArray, ...],
    lengths: FloatArray,
    *,
    fleet: FleetConfig,
    current: CurrentField | None,
) -> tuple[FloatArray, FloatArray, FloatArray | None]:
    """Each vehicle's speed limit and slowest useful speed [m/s] on its path, and cruise speed.

    In still water the limit is :data:`SPEED_MARGIN` times the top speed and the slowest
    speed :func:`~auvplan.vehicle.minimum_useful_speed`, and there is no cruise ground speed
    (None); in a current they are ground speeds along the paths of lengths ``lengths`` [m]
    (:func:`speeds_in_current`).
    """
    limits = np.array([SPEED_MARGIN * top_speed(model) for model in layout.models])
    slowest = np.array([minimum_useful_speed(model) for model in layout.models])
    if current is None:
        return limits, slowest, None
    return speeds_in_current(fleet, layout.names, paths, lengths, (limits, slowest), current)


def coordination_problem(
    layout: FleetLayout,
    paths: tuple[FloatArray, ...],
    speeds: FloatArray,
    slowest: FloatArray,
    *,
    fleet: FleetConfig,
    settings: DeconflictionConfig,
) -> CoordinationProblem:
    """Stage 2's coordination problem: ``paths`` flown at nominal ``speeds`` [m/s].

    The minimum speeds are ``min(slowest, speeds)`` [m/s] (``slowest`` of
    :func:`speed_range`), the acceleration bounds the vehicles' surge accelerations [m/s²]
    (:func:`~auvplan.vehicle.max_surge_acceleration`).
    """
    return CoordinationProblem(
        paths=paths,
        safety_radius=fleet.safety_radius,
        cruise_speeds=speeds,
        time_step=settings.time_step,
        names=layout.names,
        min_speeds=np.minimum(slowest, speeds),
        max_accelerations=np.array([max_surge_acceleration(model) for model in layout.models]),
    )


def sampled_stage(
    layout: FleetLayout,
    problem: CoordinationProblem,
    coordination: CoordinationResult,
    horizon: float,
    dt: float,
    end_headings: tuple[FloatArray, FloatArray],
    current: CurrentField | None,
) -> DeconflictStage:
    """Stage 2 of a retimed schedule: its desired states on the solver grid ``k dt`` [s].

    ``coordination`` arrives at ``horizon`` [s] (:func:`auvplan.deconfliction.
    retime_for_arrival`); ``end_headings`` and ``current`` as for :func:`desired_states`.
    """
    time = dt * np.arange(solver_steps(horizon, dt) + 1, dtype=np.float64)
    desired = desired_states(layout, problem, coordination, time, end_headings, current)
    return DeconflictStage(
        layout, horizon, dt, problem.cruise_speeds, problem, coordination, time, desired
    )


def speeds_in_current(
    fleet: FleetConfig,
    names: tuple[str, ...],
    paths: tuple[FloatArray, ...],
    lengths: FloatArray,
    through_water: tuple[FloatArray, FloatArray],
    current: CurrentField,
) -> tuple[FloatArray, FloatArray, FloatArray | None]:
    """Ground-speed limits, and cruise ground speeds, in a current that changes in time.

    The limits depend on when each vehicle passes, which depends on its speed: with
    ``fleet.horizon_s`` the nominal speed ``L_i / T`` fixes the passage times; with
    ``fleet.cruise_speed`` the vehicle passes at that speed through the water
    (:func:`~auvplan.mission.current.mean_ground_speed`) or, where that is above the limit, at
    the limit, so limits and speeds are iterated (:data:`LIMIT_ROUNDS`) until they agree to
    0.1 %. ``lengths`` [m] are the paths' lengths, ``through_water`` the fastest and slowest
    speeds [m/s] through the water. Returns the upper and lower limits [m/s] of
    :func:`ground_speed_limits` and the cruise ground speeds (None with a fixed horizon).
    """
    fastest, slowest = through_water
    if fleet.horizon is not None:
        return (
            *ground_speed_limits(names, paths, fastest, slowest, current, lengths / fleet.horizon),
            None,
        )
    assert fleet.cruise_speed is not None
    cruise = np.array([mean_ground_speed(path, fleet.cruise_speed, current) for path in paths])
    speeds = np.where(np.isfinite(cruise), cruise, fastest)
    for _round in range(LIMIT_ROUNDS):
        upper, lower = ground_speed_limits(names, paths, fastest, slowest, current, speeds)
        held = np.fmin(upper, cruise)
        if np.allclose(held, speeds, rtol=1e-3, atol=0.0):
            break
        speeds = held
    return upper, lower, cruise


def ground_speed_limits(
    names: tuple[str, ...],
    paths: tuple[FloatArray, ...],
    fastest: FloatArray,
    slowest: FloatArray,
    current: CurrentField,
    speeds: FloatArray,
) -> tuple[FloatArray, FloatArray]:
    """Ground-speed range [m/s] of each vehicle on its path from its through-water range.

    The current is taken when the vehicle passes at its ground speed ``speeds`` [m/s]
    (:func:`~auvplan.mission.current.segment_times`). The upper limit is the lowest ground
    speed along the path at the fastest through-water speed (so it can be held everywhere),
    the lower one the lowest at the slowest speed (kept >= 1 % of the upper one).

    Raises
    ------
    InfeasibleError
        If the current holds a vehicle off or back on its path (:func:`check_crossable`).
    """
    upper, lower = [], []
    for name, path, top, low, speed in zip(names, paths, fastest, slowest, speeds, strict=True):
        times = segment_times(path, float(speed))
        upper.append(np.min(check_crossable(name, path, float(top), current, times), initial=top))
        lower.append(
            np.nanmin(path_ground_speeds(path, float(low), current, times)[0], initial=low)
        )
    high = np.array(upper)
    return high, np.clip(lower, 0.01 * high, high)


def desired_states(
    layout: FleetLayout,
    problem: CoordinationProblem,
    coordination: CoordinationResult,
    time: FloatArray,
    end_headings: tuple[FloatArray, FloatArray],
    current: CurrentField | None = None,
) -> tuple[FloatArray, ...]:
    """Each vehicle's reference state along its timed path, on ``time``.

    In a current the surge is the speed through the water and the heading crabs into the
    current (:func:`auvplan.ocean.through_water`); where the vehicle would drift with the water
    (under 1 mm/s through it) the path's heading is kept. ``end_headings`` (start and goal
    headings [rad] per vehicle): the heading turns from the start heading and onto the goal
    heading at a rate the vehicle can fly (:func:`turn_in_and_out`).
    """
    positions = timed_positions(coordination, problem, time)
    headings = timed_headings(coordination, problem, time)
    desired = []
    for i, model in enumerate(layout.models):
        velocity = np.gradient(positions[i], time, axis=0)
        speed = np.hypot(*velocity.T)
        path_heading = headings[i]
        if current is not None:
            drift = np.column_stack(current.velocity(positions[i][:, 0], positions[i][:, 1], time))
            speed, crab = through_water(velocity, drift)
            path_heading = np.where(speed > 1e-3, crab, path_heading)
        ends = (float(end_headings[0][i]), float(end_headings[1][i]))
        psi = turn_in_and_out(np.unwrap(path_heading), time, ends, speed, model)
        pose = np.column_stack([positions[i], psi])
        desired.append(reference_states(model, pose, speed, np.gradient(psi, time)))
    return tuple(desired)


def turn_in_and_out(
    psi: FloatArray,
    time: FloatArray,
    ends: tuple[float, float],
    speed: FloatArray,
    model: VehicleModel,
) -> FloatArray:
    """Headings [rad] ``psi`` blended from the start heading and onto the goal heading.

    ``ψ_d(t) = ψ(t) + w_0(t) Δ_0 + w_T(t) Δ_T`` with ``Δ_0 = ψ_0 - ψ(0)`` and
    ``Δ_T = ψ_goal - ψ(T)`` (each wrapped into ``(-π, π]``) and half-cosine weights falling
    from 1 at ``t = 0`` over ``τ_0`` and rising to 1 at ``T`` over ``τ_T``. A half-cosine turn
    of ``Δ`` has peak rate ``π |Δ| / (2 τ)``; ``τ`` makes it ``TURN_RATE_FRACTION`` of the
    steady rate ``U / R`` at that end's speed ``U`` (at least the minimum useful speed) on the
    vehicle's turning radius ``R``, capped at a third of the horizon each. The result starts
    at the start heading (unwrapped next to it) and ends at the goal heading.
    """
    start, goal = ends
    psi = psi + 2 * np.pi * np.round((start - psi[0]) / (2 * np.pi))
    radius = turning_radius(model)
    floor = minimum_useful_speed(model)
    elapsed = time - time[0]
    horizon = float(elapsed[-1])
    for offset, end_speed, age in (
        (_wrapped(start - psi[0]), speed[0], elapsed),
        (_wrapped(goal - psi[-1]), speed[-1], horizon - elapsed),
    ):
        rate = TURN_RATE_FRACTION * max(float(end_speed), floor) / radius
        tau = min(0.5 * np.pi * abs(offset) / rate, horizon / 3.0)
        if tau > 0.0:
            psi = psi + offset * 0.5 * (1.0 + np.cos(np.pi * np.minimum(age / tau, 1.0)))
    return psi


def _wrapped(angle: float) -> float:
    """``angle`` [rad] wrapped into ``(-π, π]``."""
    return float(np.pi - (np.pi - angle) % (2 * np.pi))
