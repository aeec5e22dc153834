r"""Stage 3 for large fleets: each vehicle's problem solved in turn against the others' plans.

The fleet objective (:mod:`auvplan.mission.fleet`) is a sum of each vehicle's own terms and
of pair terms,

.. math::

    h(x) = \sum_i h_i(x_i) + \sum_{i<j} h_{ij}(x_i, x_j),

``h_i`` a vehicle's energy, tracking, terminal cost and own barriers (obstacles, state limits,
corridor), ``h_ij`` the barrier of a pair's separation (hockey stick) or communication range.
Block-coordinate descent (Gauss–Seidel over the vehicles) minimises ``h`` over one ``x_i``
with the others held: vehicle ``i``'s problem is ``h_i + Σ_j h_ij(·, x_j)``, the others'
positions entering as stage parameters (:class:`auvplan.mission.fleet.FleetLimits`). Every
solve lowers ``h`` (the terms it leaves out do not depend on ``x_i``), so the sweeps descend.
They stop after a sweep in which no vehicle's problem took a step: every problem was then
converged at its first direction against the others' final plans, and the gradient of ``h``,
whose blocks are the vehicles' own gradients, is below the tolerance block by block. Each
vehicle is then optimal given the others; where two vehicles' separation is active, a joint
move that neither makes alone may still lower ``h``, which Newton on the whole fleet
(:func:`auvplan.optimization.solve_pronto`) would find: the objectives differ by 1e-8 to
1e-5 on the reliability family and up to 1.2e-4 on 16 MEDUSAs crossing (README).

The first sweep runs each vehicle through the whole barrier continuation, against the others'
latest plans (their desired trajectories until they are solved); later sweeps run the last
level, and only for the vehicles one of whose neighbours moved since their last solve.

A separation enters vehicle ``i``'s problem at stage ``k`` only for the others within
:func:`neighbour_reach` of it there (the nearest first; the rest of its neighbour slots are
parked far away, where the barrier is exactly zero): beyond it the barrier composed with the
hockey stick, ``−log tanh(s) ≈ 2 e^{−2s}``, is below ``1e-9`` of ``ε dt``. A vehicle's problem
has one vehicle's size whatever the fleet, so memory and work per vehicle-stage are flat in
the fleet size. The plan is then judged on the whole fleet's problem like a coupled one: its
cost and smallest slack on every pair, and the closed-loop replay between samples
(:mod:`auvplan.mission.evaluation`).
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time
from collections.abc import Callable
from contextlib import nullcontext
from dataclasses import dataclass, field
from typing import Final, Self

import numpy as np

from auvplan._typing import FloatArray, IntArray
from auvplan._worker import WorkerLost, WorkerProcess
from auvplan.errors import SolverError
from auvplan.mission.assembly import AssembledProblem, fleet_problem
from auvplan.mission.fleet import FleetLayout, FleetWeights, build_fleet_functions
from auvplan.mission.preplan import PreplanStage
from auvplan.mission.progress import ProgressReporter, no_progress
from auvplan.mission.reward import information_reward
from auvplan.optimization import (
    ModelCache,
    ProntoIteration,
    ProntoOptions,
    ProntoResult,
    ProntoStatus,
    Trajectory,
    TrajectoryProblem,
    build_model,
    project_guess,
    solve_pronto,
)
from auvplan.optimization.pronto import final_result
from auvplan.vehicle import positions

__all__ = ["MAX_SWEEPS", "neighbour_reach", "solve_decomposed"]

logger = logging.getLogger(__name__)

#: Sweeps after the first before the solve stops with ``MAX_ITER``.
MAX_SWEEPS: Final = 30
#: Scaled slack ``s = d²/d_s² − 1`` of a separation beyond which it is left out (see module).
NEGLIGIBLE_SLACK: Final = 10.0
#: How far [m] a vehicle may move in one solve beyond the reach of its neighbours' barriers.
MOVE_ALLOWANCE: Final = 30.0
#: Offset [m] of a parked neighbour slot from the vehicle's own desired position.
PARKED: Final = 1.0e6


def neighbour_reach(separation: float) -> float:
    """Distance [m] within which another vehicle enters a vehicle's problem.

    ``separation`` is ``2 r_c + margin`` [m]; the reach is where the separation's scaled
    slack is :data:`NEGLIGIBLE_SLACK`, plus :data:`MOVE_ALLOWANCE`.
    """
    return separation * math.sqrt(1.0 + NEGLIGIBLE_SLACK) + MOVE_ALLOWANCE


@dataclass
class _Vehicle:
    """One vehicle's problem and its latest solution (private)."""

    index: int
    template: TrajectoryProblem
    slots: int
    partners: tuple[int, ...]
    cache: ModelCache
    trajectory: Trajectory
    delta: float
    result: ProntoResult | None = None
    steps: int = 0
    solved_at: int = -1
    moved_at: int = -1
    neighbours: frozenset[int] = frozenset()


@dataclass
class _Fleet:
    """The vehicles' problems, built once per neighbour count (private)."""

    assembled: AssembledProblem
    layout: FleetLayout
    preplan: PreplanStage
    reach: float

    def own_problem(self, index: int, slots: int) -> tuple[TrajectoryProblem, tuple[int, ...]]:
        """Vehicle ``index``'s problem with ``slots`` neighbour slots, and its comm partners."""
        layout, parts = self.layout, self.assembled.parts
        limits = parts.limits
        own = FleetLayout((layout.names[index],), (layout.models[index],))
        partners = [(j if i == index else i, d) for i, j, d in limits.comm_pairs if index in (i, j)]
        own_limits = dataclasses.replace(
            limits,
            comm_pairs=(),
            corridors=limits.corridors[index : index + 1],
            neighbours=slots,
            neighbour_ranges=tuple(d for _, d in partners),
        )
        weights = parts.weights
        own_weights = FleetWeights(
            weights.terrain, weights.energy, weights.terminal, weights.tracked[index : index + 1]
        )
        problem = self.assembled.problem
        functions = build_fleet_functions(
            own,
            parts.goals[index : index + 1],
            own_weights,
            own_limits,
            has_current=parts.has_current,
        )
        template = fleet_problem(
            own,
            functions,
            information_reward(own, self.preplan.maps, parts.reward_weight),
            initial_state=problem.initial_state[layout.state_slice(index)],
            dt=problem.dt,
            stage_parameters=self.parameters(index, slots, [j for j, _ in partners]),
            n_substeps=problem.n_substeps,
        )
        return template, tuple(j for j, _ in partners)

    def parameters(
        self,
        index: int,
        slots: int,
        partners: list[int],
        where: FloatArray | None = None,
        nearest: tuple[IntArray, FloatArray] | None = None,
    ) -> FloatArray:
        """Vehicle ``index``'s stage parameters: its own, then ``slots`` neighbours, partners.

        ``where`` ``(n_vehicles, N + 1, 2)`` holds every vehicle's positions (None: all
        slots parked) and ``nearest`` their ranking around the vehicle
        (:func:`_nearest_within`): at each stage the slots hold the nearest others within
        the reach.
        """
        layout, has_current = self.layout, self.assembled.parts.has_current
        own = self.assembled.problem.parameters[
            :, layout.parameter_slice(index, has_current=has_current)
        ]
        desired = own[:, [layout.models[index].index(name) for name in ("north", "east")]]
        n_stages = own.shape[0]
        slotted = np.repeat((desired + PARKED)[:, None, :], slots, axis=1)
        if where is not None and nearest is not None and slots:
            others, rank = nearest
            stage, column = np.nonzero(rank < slots)
            slotted[stage, rank[stage, column].astype(np.int64)] = where[others[column], stage]
        ranged = (
            np.stack([where[j, :n_stages] for j in partners], axis=1)
            if where is not None and partners
            else np.repeat(desired[:, None, :], len(partners), axis=1)
        )
        return np.ascontiguousarray(
            np.hstack([own, slotted.reshape(n_stages, -1), ranged.reshape(n_stages, -1)])
        )


def _nearest_within(where: FloatArray, index: int, reach: float) -> tuple[IntArray, FloatArray]:
    """The others of ``index`` and, per stage, each one's rank by distance (``inf`` beyond reach).

    Returns ``others`` ``(n_others,)`` and ``rank`` ``(N, n_others)`` over the stages ``0..N-1``.
    """
    others, distance = _distances(where, index)
    rank = np.argsort(np.argsort(distance, axis=1), axis=1).astype(np.float64)
    rank[distance > reach] = np.inf
    return others, rank


def _distances(where: FloatArray, index: int) -> tuple[IntArray, FloatArray]:
    """The others of ``index`` and their distances [m] from it ``(N, n_others)``, stages < N."""
    n_stages = where.shape[1] - 1
    others = np.array([j for j in range(where.shape[0]) if j != index], dtype=np.int64)
    distance = np.linalg.norm(where[others, :n_stages] - where[index, :n_stages], axis=-1).T
    return others, distance


def _fleet_positions(layout: FleetLayout, vehicles: list[_Vehicle]) -> FloatArray:
    """Every vehicle's positions ``(n_vehicles, N + 1, 2)`` along its latest trajectory."""
    return np.stack([positions(layout.models[v.index], v.trajectory.states) for v in vehicles])


def solve_decomposed(
    assembled: AssembledProblem,
    preplan: PreplanStage,
    options: ProntoOptions,
    *,
    callback: Callable[[ProntoIteration], None] | None = None,
    jobs: int = 1,
    progress: ProgressReporter = no_progress,
) -> ProntoResult:
    """Solve the fleet problem vehicle by vehicle (module docstring); the fleet's result.

    ``assembled`` is the whole fleet's problem (:func:`auvplan.mission.assembly.
    assemble_problem`) and its guess; ``options`` those of the first sweep (a replan's start
    at a later barrier level and ``δ`` included). The result is that of the whole problem:
    stacked trajectory, cost and smallest slack on every pair, the vehicles' regulator gains
    block by block, the vehicles' iterations one solve after another in ``history`` (given
    to ``callback`` after each solve; ``StopIteration`` from it stops with ``MAX_ITER``).
    With ``jobs = 2`` a second process solves, beside each vehicle, the next one due that is
    not its neighbour: the two problems share no term, so the sweep is the same descent.
    ``progress`` is told of each sweep (``"sweep k"``) and of each vehicle in it, solved or
    left as it was.
    """
    start = time.perf_counter()
    layout = assembled.functions.layout
    limits = assembled.parts.limits
    fleet = _Fleet(
        assembled,
        layout,
        preplan,
        neighbour_reach(2 * limits.safety_radius + limits.separation_margin),
    )
    vehicles = []
    for i in range(layout.n_vehicles):
        template, partners = fleet.own_problem(i, 0)
        guess = Trajectory(
            assembled.guess.states[:, layout.state_slice(i)],
            assembled.guess.inputs[:, layout.input_slice(i)],
        )
        vehicles.append(
            _Vehicle(
                i, template, 0, partners, ModelCache(max_entries=2), guess, options.delta_initial
            )
        )
    sweeps = _Sweeps(fleet, vehicles, options, callback, progress)
    with _Helper(fleet, vehicles) if jobs > 1 and len(vehicles) > 1 else nullcontext() as helper:
        settled = sweeps.run(helper)
    return _fleet_result(
        assembled, vehicles, sweeps.history, settled, sweeps.stopped, options, start
    )


@dataclass
class _Sweeps:
    """The Gauss–Seidel sweeps over the vehicles (private; :func:`solve_decomposed`)."""

    fleet: _Fleet
    vehicles: list[_Vehicle]
    options: ProntoOptions
    callback: Callable[[ProntoIteration], None] | None
    progress: ProgressReporter
    history: list[ProntoIteration] = field(default_factory=list)
    clock: int = 0
    stopped: bool = False

    def run(self, helper: _Helper | None) -> bool:
        """Sweep until one moves no vehicle (True) or :data:`MAX_SWEEPS` (False)."""
        for sweep in range(MAX_SWEEPS + 1):
            with self.progress(f"sweep {sweep + 1}", total=len(self.vehicles)) as advance:
                moved = self._sweep(sweep, helper, advance)
            logger.info("decomposed sweep %d: %s", sweep, "moved" if moved else "settled")
            if self.stopped:
                return False
            if sweep > 0 and not moved:
                return True
        return False

    def _sweep(self, sweep: int, helper: _Helper | None, advance: Callable[[str], None]) -> bool:
        """One sweep over the vehicles due; whether one moved."""
        moved = False
        done: set[int] = set()
        for vehicle in self.vehicles:
            if vehicle.index in done:
                continue
            where = _fleet_positions(self.fleet.layout, self.vehicles)
            related = self._related(vehicle, where)
            if not (sweep == 0 or self._is_dirty(vehicle, related)):
                advance(f"{self.fleet.layout.names[vehicle.index]} (no neighbour moved)")
                continue
            pair = [vehicle]
            partner = (
                None if helper is None else self._independent(vehicle, related, where, done, sweep)
            )
            if helper is not None and partner is not None:
                pair.append(partner)
                helper.submit(partner, where, self._options(partner, sweep))
            done.update(v.index for v in pair)
            solved = [_solve_vehicle(self.fleet, vehicle, where, self._options(vehicle, sweep))]
            if helper is not None and partner is not None:
                solved.append(helper.result())
            moved |= self._keep(pair, solved)
            for solved_vehicle in pair:
                advance(self.fleet.layout.names[solved_vehicle.index])
            if self.stopped:
                return moved
        return moved

    def _options(self, vehicle: _Vehicle, sweep: int) -> ProntoOptions:
        """The first sweep's options, or the last barrier level from ``vehicle``'s ``δ``."""
        if sweep == 0:
            return self.options
        return dataclasses.replace(
            self.options, eps_initial=self.options.eps_final, delta_initial=vehicle.delta
        )

    def _keep(
        self, pair: list[_Vehicle], solved: list[tuple[ProntoResult, frozenset[int], int]]
    ) -> bool:
        """Keep the solutions of vehicles solved side by side; whether one moved."""
        self.clock += 2
        moved = False
        for vehicle, (result, neighbours, slots) in zip(pair, solved, strict=True):
            vehicle.result = result
            vehicle.steps += result.n_iter
            vehicle.trajectory = result.trajectory
            vehicle.delta = result.delta
            vehicle.neighbours = neighbours
            vehicle.solved_at = self.clock - 1
            if result.n_iter > 0:
                vehicle.moved_at = self.clock
                moved = True
            logger.info(
                "vehicle %s: %s in %d steps (%d neighbours, %d slots)",
                self.fleet.layout.names[vehicle.index],
                result.status.name,
                result.n_iter,
                len(neighbours),
                slots,
            )
            for iteration in result.history:
                entry = dataclasses.replace(iteration, iteration=len(self.history))
                self.history.append(entry)
                if self.callback is not None and not self.stopped:
                    try:
                        self.callback(entry)
                    except StopIteration:
                        self.stopped = True
        return moved

    def _related(self, vehicle: _Vehicle, where: FloatArray) -> set[int]:
        """The vehicles whose plans enter ``vehicle``'s problem.

        Those within reach of it now, its neighbours at its last solve, its comm partners.
        """
        near = _near(where, vehicle.index, self.fleet.reach)
        return near | vehicle.neighbours | set(vehicle.partners)

    def _is_dirty(self, vehicle: _Vehicle, related: set[int]) -> bool:
        """Whether a ``related`` vehicle (:meth:`_related`) moved since ``vehicle``'s last solve."""
        return any(self.vehicles[j].moved_at > vehicle.solved_at for j in related)

    def _independent(
        self, vehicle: _Vehicle, related: set[int], where: FloatArray, done: set[int], sweep: int
    ) -> _Vehicle | None:
        """The next vehicle due in this sweep that shares no term with ``vehicle`` (or None)."""
        return next(
            (
                other
                for other in self.vehicles[vehicle.index + 1 :]
                if other.index not in done
                and other.index not in related
                and vehicle.index not in other.partners
                and (sweep == 0 or self._is_dirty(other, self._related(other, where)))
            ),
            None,
        )


def _near(where: FloatArray, index: int, reach: float) -> set[int]:
    """The vehicles within ``reach`` of vehicle ``index`` at some stage."""
    others, distance = _distances(where, index)
    return set(others[np.any(distance <= reach, axis=0)].tolist())


def _solve_vehicle(
    fleet: _Fleet, vehicle: _Vehicle, where: FloatArray, options: ProntoOptions
) -> tuple[ProntoResult, frozenset[int], int]:
    """Solve ``vehicle``'s problem against ``where`` the others are.

    Returns the result, the neighbours that entered the problem and its neighbour slots;
    ``vehicle`` keeps its problem (rebuilt when it needs more slots), not the solution.
    """
    others, rank = _nearest_within(where, vehicle.index, fleet.reach)
    needed = int(np.max(np.sum(np.isfinite(rank), axis=1), initial=0))
    if needed > vehicle.slots:
        vehicle.slots = needed
        vehicle.template, _ = fleet.own_problem(vehicle.index, needed)
        vehicle.cache = ModelCache(max_entries=2)
    problem = vehicle.cache.rebind(
        vehicle.template,
        initial_state=vehicle.template.initial_state,
        stage_parameters=fleet.parameters(
            vehicle.index, vehicle.slots, list(vehicle.partners), where, (others, rank)
        ),
        backend=options.backend,
    )
    result = solve_pronto(problem, vehicle.trajectory, options=options, cache=vehicle.cache)
    neighbours = frozenset(others[np.any(np.isfinite(rank), axis=0)].tolist())
    return result, neighbours, vehicle.slots


class _Helper:
    """A second process that solves one vehicle's problem while this one solves another.

    Forked (:class:`~auvplan._worker.WorkerProcess`), so it starts with the fleet's
    problems and keeps its own copies of the vehicles' problems and caches; it ignores
    Ctrl-C (this process stops it) and is killed when the block ends, finished or not.
    """

    def __init__(self, fleet: _Fleet, vehicles: list[_Vehicle]) -> None:
        self._worker = WorkerProcess("fork", _adopt, (fleet, vehicles), name="auvplan-fleet")

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *_exc: object) -> None:
        self._worker.close()

    def submit(self, vehicle: _Vehicle, where: FloatArray, options: ProntoOptions) -> None:
        """Start solving ``vehicle`` (at its latest trajectory and ``δ``) against ``where``."""
        self._worker.submit(_solve_adopted, vehicle.index, vehicle.trajectory, where, options)

    def result(self) -> tuple[ProntoResult, frozenset[int], int]:
        """What :func:`_solve_vehicle` returned in the helper; its error raised here."""
        try:
            return self._worker.result()  # type: ignore[no-any-return]
        except WorkerLost as error:
            raise SolverError(f"the optimiser's second process failed: {error}") from error


#: In the helper process only: the fleet and vehicles it was forked with (:func:`_adopt`).
_adopted: list[tuple[_Fleet, list[_Vehicle]]] = []


def _adopt(fleet: _Fleet, vehicles: list[_Vehicle]) -> None:
    """The helper's start: keep the fleet and its vehicles for :func:`_solve_adopted`."""
    _adopted[:] = [(fleet, vehicles)]


def _solve_adopted(
    index: int, trajectory: Trajectory, where: FloatArray, options: ProntoOptions
) -> tuple[ProntoResult, frozenset[int], int]:
    """In the helper: :func:`_solve_vehicle` for vehicle ``index`` from ``trajectory``."""
    fleet, vehicles = _adopted[0]
    vehicle = vehicles[index]
    vehicle.trajectory = trajectory
    return _solve_vehicle(fleet, vehicle, where, options)


def _fleet_result(
    assembled: AssembledProblem,
    vehicles: list[_Vehicle],
    history: list[ProntoIteration],
    settled: bool,
    stopped: bool,
    options: ProntoOptions,
    start: float,
) -> ProntoResult:
    """The whole fleet's :class:`ProntoResult` from the vehicles' solutions."""
    layout = assembled.functions.layout
    problem = assembled.problem
    gains = np.zeros((problem.n_steps, layout.n_u, layout.n_x))
    for v in vehicles:
        if v.result is None:  # stopped before its first solve: its guess on its dynamics
            model = v.cache.get(v.template, options.backend)
            v.trajectory, own_gains = project_guess(model, v.trajectory, options)
        else:
            own_gains = v.result.regulator_gains
        gains[:, layout.input_slice(v.index), layout.state_slice(v.index)] = own_gains
    trajectory = Trajectory(
        layout.stack([v.trajectory.states for v in vehicles]),
        layout.stack([v.trajectory.inputs for v in vehicles]),
    )
    steps = sum(v.steps for v in vehicles)
    failed = [
        v
        for v in vehicles
        if v.result is not None and v.result.status is not ProntoStatus.CONVERGED
    ]
    status: ProntoStatus | None = None
    message = f"converged vehicle by vehicle: {steps} steps"
    if failed:
        assert failed[0].result is not None
        status = failed[0].result.status
        message = f"{layout.names[failed[0].index]}: {failed[0].result.message}"
    elif stopped:
        status, message = ProntoStatus.MAX_ITER, "stopped by the callback"
    elif not settled:
        status = ProntoStatus.MAX_ITER
        message = f"vehicles still moving after {MAX_SWEEPS} sweeps"
    return final_result(
        build_model(problem, options.backend), trajectory, gains, status=status,
        message=message, epsilon=options.eps_final, delta=min(v.delta for v in vehicles),
        n_iter=steps, history=tuple(history), options=options, start=start,
    )  # fmt: skip
