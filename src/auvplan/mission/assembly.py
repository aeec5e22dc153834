"""Stage-3 problem assembly: the stacked fleet problem PRONTO solves, and its initial guess."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.mission.config import CommConfig, WeightsConfig
from auvplan.mission.fleet import (
    FleetLayout,
    FleetLimits,
    FleetProblemFunctions,
    FleetWeights,
    build_fleet_functions,
    current_parameters,
    regulator_weights,
)
from auvplan.mission.preplan import PreplanStage
from auvplan.mission.reward import InformationReward, information_reward
from auvplan.mission.timing import DeconflictStage
from auvplan.ocean import CurrentField
from auvplan.optimization import PathConstraint, Trajectory, TrajectoryProblem
from auvplan.planning import CircleObstacle
from auvplan.vehicle import headings, reference_states, regulator_floor, stable_rk4_step

#: Half-width of a budget route's corridor in cells of the cost grid (:func:`navigation_corridors`).
CORRIDOR_CELLS: Final = 2.0
#: Largest working memory [bytes] the optimiser may need before the mission is refused.
MEMORY_BUDGET: Final = 16 * 2**30
#: Dense arrays of size ``(n_x + n_u)²`` the optimiser keeps per solver step (Jacobians,
#: Hessian blocks, gains, Riccati matrices), with a safety factor.
ARRAYS_PER_STEP: Final = 16


@dataclass(frozen=True)
class FleetParts:
    """What the fleet problem was built from.

    Goal poses ``(n_vehicles, 3)``, weights, limits, the information reward's weight [W] and
    whether the stage parameters carry a current; a vehicle's own problem is built from them
    alike (:mod:`auvplan.mission.decomposition`).
    """

    goals: FloatArray
    weights: FleetWeights
    limits: FleetLimits
    reward_weight: float
    has_current: bool


@dataclass(frozen=True)
class AssembledProblem:
    """The fleet problem: CasADi functions, the :class:`TrajectoryProblem` and the guess."""

    functions: FleetProblemFunctions
    problem: TrajectoryProblem
    guess: Trajectory
    parts: FleetParts


@dataclass(frozen=True)
class WarmStart:
    """Where stage 3 starts instead of the mission's start poses and desired trajectories.

    ``initial_state`` ``(n_x,)`` is the stacked state ``x_0`` (a replan: each vehicle's state
    at the replanning time); ``guess`` the curve PRONTO projects from it, or None for the
    desired trajectories with zero inputs (:func:`assemble_problem`); ``delta`` the barrier's
    switching point ``δ`` the guess was optimal for (None: the solver's ``delta_initial``).
    """

    initial_state: FloatArray
    guess: Trajectory | None = None
    delta: float | None = None


def check_optimizer_memory(layout: FleetLayout, n_steps: int, *, decomposed: bool = False) -> None:
    """Refuse a problem whose optimiser would need more than ``MEMORY_BUDGET`` bytes.

    Checked when stage 3 is assembled, before anything large is allocated (the earlier
    stages need no such memory: ``--stage deconflict`` runs any fleet). The coupled solve
    keeps ``ARRAYS_PER_STEP`` dense ``(n_x + n_u)²`` blocks per step; the ``decomposed`` one
    keeps them for one vehicle at a time, plus the fleet's stacked regulator gains
    ``(n_u, n_x)`` per step.

    Raises
    ------
    InputError
        When the optimiser would need more than ``MEMORY_BUDGET``; names the keys to change.
    """
    if decomposed:
        size = max(model.n_x + model.n_u for model in layout.models)
        needed = float(n_steps) * 8 * (ARRAYS_PER_STEP * size * size + layout.n_u * layout.n_x)
    else:
        size = layout.n_x + layout.n_u
        needed = float(n_steps) * ARRAYS_PER_STEP * size * size * 8
    if needed > MEMORY_BUDGET:
        raise InputError(
            f"{n_steps} solver steps x {layout.n_vehicles} vehicles need ~{needed / 2**30:.0f} GiB "
            f"(budget {MEMORY_BUDGET / 2**30:.0f} GiB); use a larger solver.dt_s or a shorter "
            "horizon"
        )


def integration_substeps(layout: FleetLayout, dt: float) -> int:
    """RK4 substeps per control interval: each substep within every vehicle's stable step.

    ``dt`` is the control and output interval; the integrator step ``dt / m`` is derived from
    the vehicles' fastest modes (:func:`auvplan.vehicle.stable_rk4_step`), so the discrete
    model damps what the vehicle damps, whatever ``dt`` the user chose.
    """
    stable = min(stable_rk4_step(model) for model in layout.models)
    return max(1, math.ceil(dt / stable - 1e-9))


def start_states(layout: FleetLayout, preplan: PreplanStage) -> FloatArray:
    """Stacked initial state: each start pose in steady straight motion at its start speed."""
    return np.concatenate(
        [
            reference_states(
                model, preplan.starts[i], np.array([preplan.start_speeds[i]]), np.zeros(1)
            )[0]
            for i, model in enumerate(layout.models)
        ]
    )


def goal_poses(
    layout: FleetLayout, goals: FloatArray, desired: tuple[FloatArray, ...]
) -> FloatArray:
    """Goals with headings unwrapped next to each desired trajectory's arrival heading."""
    goals = goals.copy()
    arrival = np.array([headings(model, desired[i][-1]) for i, model in enumerate(layout.models)])
    goals[:, 2] += 2 * np.pi * np.round((arrival - goals[:, 2]) / (2 * np.pi))
    return goals


def separation_margin(
    safety_radius: float, dt: float, desired: tuple[FloatArray, ...], layout: FleetLayout
) -> float:
    """Margin [m] on ``2 r_c`` for constraints imposed at the solver nodes only.

    Two vehicles closing at relative speed ``w`` that are ``D`` apart at two consecutive nodes
    come at most ``(w dt)² / (8 D)`` closer in between (straight-line relative motion); ``w``
    is bounded by 1.5 x twice the fastest desired speed. At least 1 % of ``2 r_c`` is kept.
    """
    separation = 2.0 * safety_radius
    fastest = max(
        float(np.max(d[:, m.index("u")])) for d, m in zip(desired, layout.models, strict=True)
    )
    dip = (3.0 * fastest * dt) ** 2 / (8.0 * separation)
    return max(dip, 0.01 * separation)


def stage_parameters(
    layout: FleetLayout,
    desired: tuple[FloatArray, ...],
    time: FloatArray,
    current: CurrentField | None,
) -> FloatArray:
    """Stacked per-stage parameters ``(N, n_p)``: each vehicle's desired state (and current model).

    Vehicle ``i`` holds :meth:`FleetLayout.parameter_slice`: its desired state ``x_d,k`` and,
    in a current, ``v_c,k`` and ``G_k`` at the desired position at ``t_k``
    (:func:`auvplan.mission.fleet.current_parameters`).
    """
    if current is None:
        return np.ascontiguousarray(layout.stack(desired)[:-1])
    return np.ascontiguousarray(
        np.concatenate(
            [
                np.hstack([d[:-1], current_parameters(model, d[:-1], time[:-1], current)])
                for d, model in zip(desired, layout.models, strict=True)
            ],
            axis=1,
        )
    )


def navigation_corridors(preplan: PreplanStage) -> tuple[float, ...]:
    """Per vehicle the corridor half-width [m] around its desired trajectory (``inf``: none).

    A route chosen to meet an explicit navigation budget (``[navigation] max_error_m``) is
    certified by the belief-space search on the cost grid, cell by cell: the optimised plan
    keeps within :data:`CORRIDOR_CELLS` cells of it at every solver node (a hockey-stick
    barrier, inactive inside), so it flies over the seabed the certificate counted on; the
    closed-loop replay then checks the budget itself (:mod:`auvplan.mission.checks`).
    Automatic routes and the paper's have no corridor.
    """
    choices = preplan.navigation or ()
    geometry = preplan.maps.cost_geometry
    width = CORRIDOR_CELLS * max(geometry.spacing_north, geometry.spacing_east)
    return tuple(
        width if choice.mode == "budget" and choice.tracked else math.inf for choice in choices
    )


def fleet_limits(
    layout: FleetLayout,
    preplan: PreplanStage,
    deconfliction: DeconflictStage,
    *,
    safety_radius: float,
    comms: tuple[CommConfig, ...],
) -> FleetLimits:
    """Separation, obstacles, communication pairs and corridors of the fleet problem."""
    circles = [
        (obstacle, name)
        for obstacle, name in zip(preplan.obstacles, preplan.obstacle_names, strict=True)
        if isinstance(obstacle, CircleObstacle)
    ]
    desired = deconfliction.desired_states
    return FleetLimits(
        safety_radius=safety_radius,
        separation_margin=separation_margin(safety_radius, deconfliction.dt, desired, layout),
        obstacles=np.array([(o.north, o.east, o.radius) for o, _ in circles]).reshape(-1, 3),
        obstacle_names=tuple(name for _, name in circles),
        comm_pairs=tuple(
            (layout.names.index(comm.pair[0]), layout.names.index(comm.pair[1]), comm.max_range)
            for comm in comms
        ),
        corridors=navigation_corridors(preplan),
    )


def fleet_problem(
    layout: FleetLayout,
    functions: FleetProblemFunctions,
    reward: InformationReward | None,
    *,
    initial_state: FloatArray,
    dt: float,
    stage_parameters: FloatArray,
    n_substeps: int,
) -> TrajectoryProblem:
    """The :class:`TrajectoryProblem` of ``functions``, one stage per row of ``stage_parameters``.

    ``dt`` [s] is the control interval, ``n_substeps`` the RK4 substeps per interval.
    """
    return TrajectoryProblem(
        dynamics=functions.dynamics,
        running_cost=functions.running_cost,
        terminal_cost=functions.terminal_cost,
        initial_state=initial_state,
        dt=dt,
        n_steps=stage_parameters.shape[0],
        stage_parameters=stage_parameters,
        constraints=tuple(
            PathConstraint(block.function, kind=block.kind, name=block.name)
            for block in functions.constraints
        ),
        regulator_Q=np.diag(layout.per_state(regulator_weights, 1.0)),
        regulator_R=np.eye(layout.n_u),
        n_substeps=n_substeps,
        regulator_floor=layout.per_state(regulator_floor, 0.0),
        blocks=functions.blocks,
        node_costs=() if reward is None else (reward,),
    )


def assemble_problem(
    layout: FleetLayout,
    preplan: PreplanStage,
    deconfliction: DeconflictStage,
    *,
    weights: WeightsConfig,
    terrain_weight: float,
    safety_radius: float,
    comms: tuple[CommConfig, ...],
    current: CurrentField | None = None,
    warm_start: WarmStart | None = None,
    decomposed: bool = False,
) -> AssembledProblem:
    """The stacked fleet problem for PRONTO (and the IPOPT reference), with its initial guess.

    ``terrain_weight`` overrides ``weights.terrain`` (0 for the energy-only comparison); a
    navigation-aware route that buys no navigation (the shortest route) and has nothing to go
    around is not tracked: its vehicle's plan is the energy-optimal one. The
    guess is the desired trajectory with zero inputs; PRONTO projects it onto the dynamics.
    ``current`` (None: still water) enters each stage linearised about the desired position.
    ``warm_start`` replaces the initial state (:func:`start_states`) and, when it has one, the
    guess. ``decomposed``: the problem is solved vehicle by vehicle
    (:mod:`auvplan.mission.decomposition`), which needs memory for one vehicle at a time.

    Raises
    ------
    InputError
        When the optimiser would need too much memory (:func:`check_optimizer_memory`).
    """
    check_optimizer_memory(layout, deconfliction.time.size - 1, decomposed=decomposed)
    desired = deconfliction.desired_states
    limits = fleet_limits(layout, preplan, deconfliction, safety_radius=safety_radius, comms=comms)
    fleet_weights = FleetWeights(
        terrain=terrain_weight,
        energy=weights.energy,
        terminal=weights.terminal,
        tracked=tuple(choice.tracked for choice in preplan.navigation or ()),
    )
    goals = goal_poses(layout, preplan.goals, desired)
    has_current = current is not None
    functions = build_fleet_functions(layout, goals, fleet_weights, limits, has_current=has_current)
    reward_weight = terrain_weight * weights.information
    problem = fleet_problem(
        layout,
        functions,
        information_reward(layout, preplan.maps, reward_weight),
        initial_state=start_states(layout, preplan)
        if warm_start is None
        else warm_start.initial_state,
        dt=deconfliction.dt,
        stage_parameters=stage_parameters(layout, desired, deconfliction.time, current),
        n_substeps=integration_substeps(layout, deconfliction.dt),
    )
    guess = Trajectory(
        states=layout.stack(desired), inputs=np.zeros((deconfliction.time.size - 1, layout.n_u))
    )
    if warm_start is not None and warm_start.guess is not None:
        guess = warm_start.guess
    return AssembledProblem(
        functions,
        problem,
        guess,
        FleetParts(goals, fleet_weights, limits, reward_weight, has_current),
    )
