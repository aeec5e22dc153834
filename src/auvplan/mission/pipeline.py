"""The end-to-end pipeline (SPEC §1-§5), as a table of contents of the paper's stages.

:func:`run_mission` runs the stages in order and stops after the one requested:

1. ``preplan`` (:mod:`~auvplan.mission.preplan`) — terrain, maps (eq. 13-15), one A* path
   per vehicle, smoothed;
2. ``deconflict`` (:mod:`~auvplan.mission.timing`) — a common horizon ``T``, time laws in the
   coordination space, and the desired trajectories on the solver's grid;
3. ``full`` — the fleet problem (:mod:`~auvplan.mission.assembly`) solved by PRONTO with the
   barrier continuation from the projection of the desired trajectories, then evaluated
   (:mod:`~auvplan.mission.evaluation`); optionally again with the terrain weight set to zero
   (the paper's energy-only comparison).

Every user-caused failure raises an :class:`~auvplan.errors.AuvplanError` with one line that
names the vehicle or key.
"""

from __future__ import annotations

import dataclasses
import logging
import time as wallclock
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import Enum
from typing import Any

from auvplan.errors import InputError, SolverError
from auvplan.mission.assembly import WarmStart, assemble_problem
from auvplan.mission.config import MissionConfig
from auvplan.mission.decomposition import solve_decomposed
from auvplan.mission.evaluation import OptimizedPlan, evaluate_plan
from auvplan.mission.fleet import FleetLayout
from auvplan.mission.models import vehicle_model
from auvplan.mission.preplan import PreplanStage, run_preplan
from auvplan.mission.progress import ProgressReporter, no_progress, with_checkpoints
from auvplan.mission.still_water import CurrentComparison, compare_with_still_water
from auvplan.mission.timing import DeconflictStage, run_deconfliction
from auvplan.optimization import solve_pronto
from auvplan.vehicle import top_speed

logger = logging.getLogger(__name__)


class Stage(Enum):
    """Where :func:`run_mission` stops."""

    PREPLAN = "preplan"
    DECONFLICT = "deconflict"
    FULL = "full"


@dataclass(frozen=True)
class MissionResult:
    """Everything a mission run produced; ``timings`` holds wall seconds per stage.

    ``failure`` names why stage 3 produced no plan at all (the optimiser failed before its
    first iterate); the earlier stages' results are kept so that they can be written.
    ``paper`` is the same mission planned on the paper's information-map routes
    (``planner.edge_model = "paper"``), for comparison with navigation-aware routes.
    """

    config: MissionConfig
    stage: Stage
    preplan: PreplanStage
    deconfliction: DeconflictStage | None = None
    plan: OptimizedPlan | None = None
    energy_only: OptimizedPlan | None = None
    timings: dict[str, float] = field(default_factory=dict)
    failure: str | None = None
    current_comparison: CurrentComparison | None = None
    paper: MissionResult | None = None

    @property
    def paper_plan(self) -> OptimizedPlan | None:
        """The optimised plan of :attr:`paper`, if it was planned and optimised."""
        return None if self.paper is None else self.paper.plan

    @property
    def problem(self) -> str | None:
        """The first reason this run is not a usable plan, in one line; None if it is.

        None when the plan converged with every constraint met between samples, and the
        comparison plans (energy-only, the paper's) did too; before stage 3, when every
        route meets its navigation budget. Otherwise the line names the plan, its status and
        what to change, e.g. ``"plan FAILED: ..."`` or ``"paper's plan MAX_ITER: ..."``.
        """
        if self.failure is not None:
            return f"plan FAILED: {self.failure}"
        if self.plan is None:  # stopped before stage 3: the routes' navigation budgets
            for choice in self.preplan.navigation or ():
                if not choice.budget_met:
                    return f"plan NAVIGATION_BUDGET: {choice.message}"
        comparisons = (("energy-only plan", self.energy_only), ("paper's plan", self.paper_plan))
        for label, plan in (("plan", self.plan), *comparisons):
            if plan is not None and not plan.verdict.success:
                return f"{label} {plan.verdict.status.name}: {plan.verdict.message}"
        return None


def run_mission(
    config: MissionConfig,
    *,
    stage: Stage = Stage.FULL,
    compare_energy_only: bool = False,
    compare_no_current: bool = False,
    compare_paper: bool = False,
    callback: Callable[[Any], None] | None = None,
    progress: ProgressReporter = no_progress,
    before_optimization: Callable[[], None] | None = None,
    jobs: int = 1,
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
    compare_no_current : bool
        With a ``[current]``: also plan as if in still water and fly both plans in the current
        (:mod:`auvplan.mission.still_water`).
    compare_paper : bool
        With navigation-aware routes (``planner.edge_model = "navigation"``): also plan the
        mission on the paper's information-map routes (``MissionResult.paper``).
    callback : callable, optional
        Passed to :func:`auvplan.optimization.solve_pronto` (per-iteration records).
    progress : ProgressReporter
        Told of each stage (by its ``timings`` name) and of each vehicle's A* search
        (:mod:`auvplan.mission.progress`).
    before_optimization : callable, optional
        Called once when stage 3 is about to start (after stage 2), e.g. to wait for the
        optimiser's kernels compiled in another process (:mod:`auvplan.api.companion`).
    jobs : int
        Processes stage 3 may use (1 or 2): a second process solves vehicles of a decomposed
        fleet, else a second thread evaluates half the stages.
    """
    timings: dict[str, float] = {}
    progress = with_checkpoints(progress)

    def timed(name: str, work: Callable[[], Any]) -> Any:
        return timed_stage(progress, timings, name, work)

    preplan = timed("preplan", lambda: run_preplan(config, progress=progress))
    if stage is Stage.PREPLAN:
        return MissionResult(config, stage, preplan, timings=timings)

    layout = timed("models", lambda: fleet_layout(config))
    deconfliction = timed(
        "deconflict",
        lambda: run_deconfliction(
            layout,
            preplan.paths,
            preplan.starts[:, 2],
            preplan.goals[:, 2],
            fleet=config.fleet,
            settings=config.deconfliction,
            dt=config.solver.dt,
            current=preplan.current,
        ),
    )
    if stage is Stage.DECONFLICT:
        return MissionResult(config, stage, preplan, deconfliction, timings=timings)

    def optimize(terrain_weight: float) -> OptimizedPlan:
        return run_optimization(
            config, layout, preplan, deconfliction, terrain_weight,
            callback=callback, jobs=jobs, progress=progress,
        )  # fmt: skip

    if before_optimization is not None:
        before_optimization()
    try:
        plan = timed("optimize", lambda: optimize(config.weights.terrain))
        energy_only = None
        if compare_energy_only:
            energy_only = timed("optimize_energy_only", lambda: optimize(0.0))
    except SolverError as error:
        failure = f"the optimiser failed: {error}; try a smaller solver.dt_s or a longer horizon"
        return MissionResult(
            config, stage, preplan, deconfliction, timings=timings, failure=failure
        )
    comparison = None
    if compare_no_current and preplan.current is not None:
        comparison = timed(
            "compare_no_current",
            lambda: _compare_no_current(config, layout, preplan, plan, callback=callback),
        )
    paper = None
    if compare_paper and config.planner.edge_model == "navigation":
        routes = config.planner.model_copy(update={"edge_model": "paper"})
        paper = timed(
            "compare_paper",
            lambda: run_mission(config.model_copy(update={"planner": routes}), callback=callback),
        )
    return MissionResult(
        config, stage, preplan, deconfliction, plan, energy_only, timings=timings,
        current_comparison=comparison, paper=paper,
    )  # fmt: skip


def timed_stage(
    progress: ProgressReporter, timings: dict[str, float], name: str, work: Callable[[], Any]
) -> Any:
    """Run ``work`` as the stage ``name`` of ``progress``; its wall seconds go to ``timings``."""
    started = wallclock.perf_counter()
    with progress(name):
        value = work()
    timings[name] = wallclock.perf_counter() - started
    return value


def _compare_no_current(
    config: MissionConfig,
    layout: FleetLayout,
    preplan: PreplanStage,
    plan: OptimizedPlan,
    *,
    callback: Callable[[Any], None] | None,
) -> CurrentComparison | None:
    """The still-water plan of the mission flown in its current (None if it found no plan)."""
    assert preplan.current is not None
    still = run_mission(config.model_copy(update={"current": None}), callback=callback)
    if still.plan is None:
        return None
    return compare_with_still_water(
        plan, still.plan, layout, preplan.goals, config.solver.dt, preplan.current
    )


def fleet_layout(config: MissionConfig) -> FleetLayout:
    """The vehicles' models with the optimiser's propeller order, stacked in mission order.

    Raises
    ------
    InputError
        If a start speed exceeds its vehicle's top speed.
    """
    order = config.solver.harmonics
    models = tuple(vehicle_model(vehicle.type, order) for vehicle in config.vehicles)
    for index, (vehicle, model) in enumerate(zip(config.vehicles, models, strict=True)):
        fastest = top_speed(model)
        if vehicle.start.speed > fastest:
            raise InputError(
                f"vehicle[{index}].start.speed = {vehicle.start.speed:g} m/s exceeds the "
                f"top speed of {vehicle.name} ({vehicle.type}), {fastest:.2f} m/s"
            )
    return FleetLayout(names=tuple(vehicle.name for vehicle in config.vehicles), models=models)


def run_optimization(
    config: MissionConfig,
    layout: FleetLayout,
    preplan: PreplanStage,
    deconfliction: DeconflictStage,
    terrain_weight: float,
    *,
    callback: Callable[[Any], None] | None = None,
    warm_start: WarmStart | None = None,
    jobs: int = 1,
    progress: ProgressReporter = no_progress,
) -> OptimizedPlan:
    """Stage 3: PRONTO with barrier continuation from the projected desired trajectories.

    A ``warm_start`` with a guess (a replan: the old plan from the replanning time) starts at
    the guess's ``δ`` and at the barrier level before the last: the guess solved the last
    level for other starts, and a vehicle moved off its plan can leave it infeasible (4 × 1 h
    MEDUSAs, one moved 30 m: scaled slack −0.05). One level up the barrier re-centres it; at
    the last level its iterates hug the constraint it crossed (``δ`` shrank to 2e-9, 12
    iterations against 8, ``benchmarks/bench_replan.py``). ``config.solver.fleet`` chooses
    the coupled solve (its stage evaluations on ``jobs`` threads) or the vehicle-by-vehicle one
    (:mod:`auvplan.mission.decomposition`, with ``jobs`` processes, its sweeps told to
    ``progress``).
    """
    decomposed = config.solver.decomposes(layout.n_vehicles)
    assembled = assemble_problem(
        layout, preplan, deconfliction,
        weights=config.weights, terrain_weight=terrain_weight,
        safety_radius=config.fleet.safety_radius, comms=config.comms, current=preplan.current,
        warm_start=warm_start, decomposed=decomposed,
    )  # fmt: skip
    options = config.solver.pronto_options()
    if not decomposed:  # the companion process idles in stage 3: its core takes half the stages
        options = dataclasses.replace(options, n_threads=jobs)
    if warm_start is not None and warm_start.guess is not None:
        delta = options.delta_initial if warm_start.delta is None else warm_start.delta
        levels = options.epsilon_levels()
        options = dataclasses.replace(
            options, eps_initial=levels[-min(2, len(levels))], delta_initial=delta
        )
    if decomposed:
        result = solve_decomposed(
            assembled, preplan, options, callback=callback, jobs=jobs, progress=progress
        )
    else:
        result = solve_pronto(
            assembled.problem, assembled.guess, options=options, callback=callback
        )
    logger.info(
        "PRONTO (terrain weight %g): %s after %d iterations, cost %.1f",
        terrain_weight,
        result.status.name,
        result.n_iter,
        result.cost,
    )
    return evaluate_plan(
        config,
        preplan,
        deconfliction.time,
        deconfliction.dt,
        assembled.problem,
        assembled.functions,
        result,
        terrain_weight,
        fleet_solve="decomposed" if decomposed else "coupled",
    )
