"""Discrete-time PRONTO (projection-operator Newton method) with approximate barriers.

The solver loop is written as named, individually testable steps (STYLE B2)::

    ξ ← project_guess(guess)                             # regulator designed along the guess
    for ε in ε-levels:                                   # barrier continuation (§7.5)
        repeat:
            linearise, regulator K (reused at a new level's first point)
            if predicted by the last two steps: done if ξ passes the last ε's test (probe)
            local, ζ = compute_direction(ξ)              # costate λ, Newton weights,
                                                         # LQ direction (ladder)
            if converged(−Dh·ζ): break                   # stopping criterion, or the next
                                                         # level's barrier shift outweighs it
            ξ = armijo_step(ξ, ζ, K)                     # try_step(γ) = h(P(ξ + γζ)), K fixed
            shrink δ once strictly feasible
        skip to the last ε if ξ is predicted converged there (the factorised LQ model)

Equations and defaults follow ``reference/pronto.md`` §6 (discrete PRONTO), §7 (barrier) and
§11. The discrete problem is stated in :mod:`auvplan.optimization.problem`.

References
----------
J. Hauser, "A projection operator approach to the optimization of trajectory functionals",
IFAC World Congress 2002. J. Hauser, A. Saccon, "A barrier function method for the
optimization of trajectory functionals with constraints", IEEE CDC 2006.
"""

from __future__ import annotations

import functools
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from threadpoolctl import ThreadpoolController

from auvplan._typing import FloatArray
from auvplan.errors import InputError, SolverError
from auvplan.interrupts import checkpoint
from auvplan.optimization.linesearch import ArmijoResult, armijo_step, converged
from auvplan.optimization.lq import DirectionType, LqDirection
from auvplan.optimization.model import ModelCache, ProntoModel
from auvplan.optimization.options import ProntoOptions
from auvplan.optimization.problem import Trajectory, TrajectoryProblem
from auvplan.optimization.projection import project_guess
from auvplan.optimization.result import ProntoIteration, ProntoResult, ProntoStatus
from auvplan.optimization.stages import evaluate_cost, min_slack
from auvplan.optimization.steps import (
    FirstOrder,
    LocalModel,
    compute_direction,
    first_order_model,
    predicted_decrement,
    shift_decrement,
)

__all__ = ["check_guess", "check_trajectory", "final_result", "solve_pronto"]

logger = logging.getLogger(__name__)


#: Largest step defect ``|x_{k+1} − F(x_k, u_k)|`` of a guess given as a trajectory, relative to
#: the largest state entry (rounding of a trajectory integrated by the same model: ~1e-16).
TRAJECTORY_RTOL = 1e-9


def check_trajectory(model: ProntoModel, trajectory: Trajectory) -> None:
    """Check that ``trajectory`` is one of the discrete dynamics from the problem's ``x0``.

    Raises
    ------
    InputError
        If it does not start at ``x0`` or a step is off by more than :data:`TRAJECTORY_RTOL`.
    """
    problem = model.problem
    states = trajectory.states
    stepped = model.discrete.step(states[:-1], trajectory.inputs, problem.parameters)
    defects = np.abs(np.vstack([states[:1] - problem.initial_state, states[1:] - stepped]))
    scale = max(1.0, float(np.max(np.abs(states))))
    worst = np.unravel_index(int(np.argmax(defects)), defects.shape)
    if defects[worst] > TRAJECTORY_RTOL * scale:
        where = "its start differs from x0" if worst[0] == 0 else f"step {worst[0] - 1} is off"
        raise InputError(
            f"the guess is not a trajectory of the dynamics ({where} by {defects[worst]:.3g} in "
            f"state {worst[1]}): solve it with projected=False"
        )


def check_guess(problem: TrajectoryProblem, guess: Trajectory) -> None:
    """Check that a guess has the problem's shape and finite values.

    Raises
    ------
    InputError
        On a wrong shape or non-finite values.
    """
    n_steps = problem.n_steps
    if guess.states.shape != (n_steps + 1, problem.n_states) or guess.inputs.shape != (
        n_steps,
        problem.n_inputs,
    ):
        raise InputError(
            f"guess must have states ({n_steps + 1}, {problem.n_states}) and inputs "
            f"({n_steps}, {problem.n_inputs}), got {guess.states.shape} and {guess.inputs.shape}"
        )
    if not (np.all(np.isfinite(guess.states)) and np.all(np.isfinite(guess.inputs))):
        raise InputError("guess contains non-finite values")


@dataclass
class _State:
    """Mutable loop state of :func:`solve_pronto` (private)."""

    trajectory: Trajectory
    gains: FloatArray | None
    """The last regulator (``None`` until the first direction, when the guess was not projected)."""
    delta: float
    n_iter: int = 0
    history: list[ProntoIteration] = field(default_factory=list)
    local: LocalModel | None = None
    """The model of the last direction (at ``trajectory`` when a level has converged)."""
    direction: LqDirection | None = None
    """The last direction (of ``local``, with its model's factorisation)."""
    probing: bool = True
    """Whether new points of a level are first tested at the last barrier weight (:func:`_probe`);
    off once a probe or a level's prediction (:func:`_next_level`) has failed."""
    finished: bool = False
    """The last level's stopping test has passed at a probe."""


def _record(
    state: _State,
    local: LocalModel,
    direction: LqDirection,
    start: float,
    callback: Callable[[ProntoIteration], None] | None,
    result: ArmijoResult | None = None,
) -> ProntoIteration:
    """Append the record of a direction (``result``: its line search, if a step was tried)."""
    lin = local.linearization
    record = ProntoIteration(
        iteration=len(state.history),
        cost=lin.cost.total,
        decrement=-direction.slope,
        step=result.step if result is not None else 0.0,
        direction=direction.direction,
        epsilon=lin.epsilon,
        delta=state.delta,
        min_slack=lin.min_slack,
        wall_time=time.perf_counter() - start,
        n_backtracks=result.n_backtracks if result is not None else 0,
    )
    state.history.append(record)
    logger.info(
        "PRONTO it %3d  h=%.10g  -Dh.z=%.3e  gamma=%.3g  %s  eps=%.1e  delta=%.1e  slack=%.3g",
        record.iteration,
        record.cost,
        record.decrement,
        record.step,
        record.direction.value,
        record.epsilon,
        state.delta,
        record.min_slack,
    )
    if callback is not None:
        callback(record)
    checkpoint()  # a stop request (SIGINT/SIGTERM) between iterations
    return record


def _first_order(
    model: ProntoModel, state: _State, epsilon: float, options: ProntoOptions
) -> FirstOrder:
    """The linearisation and regulator at the current trajectory.

    At a new barrier level the trajectory is where the last direction was computed: its
    linearisation is reused, shifted to the new ``ε`` (exact), unless ``δ`` has changed since.
    """
    local = state.local
    if (
        local is not None
        and local.trajectory is state.trajectory
        and local.linearization.delta == state.delta
    ):
        return local.first_order
    return first_order_model(model, state.trajectory, epsilon, state.delta, options=options)


#: The predicted decrement at the last barrier level must be below this share of its tolerance
#: for the levels between to be skipped (the prediction keeps the current level's weights).
SKIP_MARGIN = 0.5


#: A level ends once its decrement is below this share of the next level's barrier shift.
LEVEL_SHARE = 0.1


def _outweighed(local: LocalModel, direction: LqDirection, epsilon: float) -> bool:
    """Whether the next barrier level ``epsilon`` outweighs this level's remaining error.

    Going to ``epsilon`` shifts the gradient by ``Δg = (ε'/ε − 1) ∇b``, and its decrement
    ``s = Δgᵀ H⁻¹ Δg`` (:func:`shift_decrement`) is about what the next level starts with
    from this level's exact minimiser. From a point whose decrement here is ``d``, it
    starts with at most ``(√d + √s)²``: with
    ``d < LEVEL_SHARE · s`` that is at most 1.73 ``s``, and the Newton steps that would
    reduce ``d`` further here are not taken (IPOPT likewise solves a barrier problem only to
    a tolerance proportional to its barrier parameter).
    """
    shift = shift_decrement(local, direction, epsilon)
    return -direction.slope < LEVEL_SHARE * shift


def _worth_probing(
    local: LocalModel,
    direction: LqDirection,
    decrements: tuple[float, float],
    epsilon: float,
    options: ProntoOptions,
) -> bool:
    """Whether the point after a full Newton step is predicted to pass the last level's test.

    ``decrements = (d_{k−1}, d_k)``: the level's decrements at the last two points,
    ``local`` and ``direction`` the model and direction at the second. The level's decrement
    at the new point is estimated as ``d_k² / d_{k−1}`` (the contraction going on); the last
    level ``epsilon`` adds the barrier's shift of the gradient (:func:`shift_decrement`).
    Their sum of square roots, squared, must be below ``SKIP_MARGIN`` of the last level's
    tolerance.
    """
    before, last = decrements
    newton = last * last / before
    cost = local.linearization.cost.total
    if not converged(newton / SKIP_MARGIN, cost, options.tol, options.rtol):
        return False
    shift = shift_decrement(local, direction, epsilon)
    return converged((newton**0.5 + shift**0.5) ** 2 / SKIP_MARGIN, cost, options.tol, options.rtol)


def _probe(
    model: ProntoModel,
    state: _State,
    first_order: FirstOrder,
    epsilon: float,
    options: ProntoOptions,
    start: float,
    callback: Callable[[ProntoIteration], None] | None,
) -> bool:
    """Whether the current trajectory passes the last level's stopping test (at ``epsilon``).

    One direction at the last barrier weight from the level's own linearisation (shifted,
    exact): where the barrier does not move the minimiser, a level's converged point is
    the last level's, and this test replaces the level's own test, the prediction of
    :func:`_next_level` and the last level's test. A probe that fails turns probing off.
    """
    try:
        local, direction = compute_direction(
            model, state.trajectory, epsilon, state.delta, options=options,
            first_order=first_order,
        )  # fmt: skip
    except SolverError:
        state.probing = False
        return False
    record = _record(state, local, direction, start, callback)
    if converged(record.decrement, record.cost, options.tol, options.rtol) and (
        not model.has_constraints or record.min_slack > 0.0
    ):
        state.local, state.direction, state.gains = local, direction, local.gains
        state.finished = True
        return True
    state.probing = False
    return False


def _iterate_level(
    model: ProntoModel,
    state: _State,
    epsilon: float,
    tol: tuple[float, float],
    options: ProntoOptions,
    start: float,
    callback: Callable[[ProntoIteration], None] | None,
    following: tuple[float, ...] = (),
) -> ProntoStatus | None:
    """Run PRONTO at one barrier weight until convergence; ``None`` means converged.

    ``tol = (absolute, relative)`` tolerances of the stopping test (:func:`converged`).
    ``following``: the barrier weights of the levels after this one. The level also ends
    when the next one would move the minimiser much further than this one's remaining
    error (:func:`_outweighed`); new points are probed at the last one (:func:`_probe`),
    and ``state.finished`` tells when a probe has passed.
    """
    last_epsilon = following[-1] if following else None
    probe = False
    previous = None  # the decrement of the last step if it was a full Newton step
    while True:
        if len(state.history) >= options.max_iter:
            return ProntoStatus.MAX_ITER
        first_order = _first_order(model, state, epsilon, options)
        if probe and last_epsilon is not None:
            if _probe(model, state, first_order, last_epsilon, options, start, callback):
                return None
            if len(state.history) >= options.max_iter:
                return ProntoStatus.MAX_ITER
        local, direction = compute_direction(
            model, state.trajectory, epsilon, state.delta, options=options,
            first_order=first_order,
        )  # fmt: skip
        lin = local.linearization
        state.local, state.direction, state.gains = local, direction, local.gains
        decrement = -direction.slope
        current = lin.cost.total
        is_done = converged(decrement, current, *tol) or (
            bool(following) and _outweighed(local, direction, following[0])
        )
        result = None
        if not is_done:
            result = armijo_step(
                model,
                state.trajectory,
                direction,
                local.gains,
                current,
                epsilon=epsilon,
                delta=state.delta,
                alpha=options.alpha,
                beta=options.beta,
                max_backtracks=options.max_backtracks,
                require_feasible=model.has_constraints and lin.min_argument > 0.0,
            )
        _record(state, local, direction, start, callback, result)
        if is_done:
            return None
        assert result is not None
        if not result.accepted:
            # At machine precision the Armijo test cannot see a decrease any more.
            if decrement <= 1e-10 * max(1.0, abs(current)):
                return None
            return ProntoStatus.LINE_SEARCH_FAILED
        state.trajectory = result.trajectory
        state.n_iter += 1
        if model.has_constraints and result.min_argument > 0.0:
            state.delta = min(
                state.delta,
                options.delta_feasible_factor * result.min_argument,
                options.delta_feasible_max,
            )
        full_newton = result.step == 1.0 and direction.direction is DirectionType.NEWTON
        probe = (
            full_newton
            and previous is not None
            and last_epsilon is not None
            and state.probing
            and _worth_probing(local, direction, (previous, decrement), last_epsilon, options)
        )
        previous = decrement if full_newton else None


def infeasible_restart_delta(delta: float, smallest: float) -> float:
    """``δ`` for re-solving a level whose minimiser has smallest scaled slack ``smallest <= 0``.

    Where the minimiser violates a constraint by ``v = -smallest``, the barrier's pull
    ``ε |β'_δ(-v)| = ε (v + 2δ) / δ²`` balances what violating gains. The re-solve's pull at
    the boundary, ``ε |β'_δ'(0)| = 2ε / δ'``, exceeds that gain when
    ``δ' < 2δ² / (v + 2δ)``; half of it is taken (and at most ``δ / 2``), so a deep violation
    is cured in one re-solve instead of a halving per level.
    """
    violation = max(-smallest, 0.0)
    return min(0.5 * delta, delta**2 / (violation + 2.0 * delta))


def _next_level(
    state: _State, levels: tuple[float, ...], index: int, options: ProntoOptions
) -> int:
    """The level after ``levels[index]``, which ``state.trajectory`` has just solved.

    The last level when the trajectory is predicted to pass its stopping test already
    (:func:`predicted_decrement` below ``SKIP_MARGIN`` of the tolerance): the levels between
    would only confirm, each with a full direction, that the barrier does not move it. The
    last level's own test then decides, with an exact direction, as before.
    """
    last = len(levels) - 1
    local, direction = state.local, state.direction
    if (
        index + 1 >= last
        or local is None
        or direction is None
        or local.trajectory is not state.trajectory
    ):
        return index + 1
    decrement, cost = predicted_decrement(local, direction, levels[last])
    if converged(decrement / SKIP_MARGIN, cost, options.tol, options.rtol):
        logger.info("level eps=%.1e: predicted converged at eps=%.1e", levels[index], levels[last])
        return last
    state.probing = False
    return index + 1


def _continuation(
    model: ProntoModel,
    state: _State,
    options: ProntoOptions,
    start: float,
    callback: Callable[[ProntoIteration], None] | None,
) -> tuple[ProntoStatus | None, str, float]:
    """Run the barrier levels; return the status (``None``: converged), message and last ``ε``."""
    levels = options.epsilon_levels() if model.has_constraints else (0.0,)
    index, epsilon = 0, levels[0]
    try:
        while index < len(levels):
            epsilon = levels[index]
            last = index == len(levels) - 1
            tol = (options.tol, options.rtol) if last else (options.inner_tol, options.inner_rtol)
            restarts = 0
            while True:
                status = _iterate_level(
                    model, state, epsilon, tol, options, start, callback, levels[index + 1 :]
                )
                if state.finished:
                    return None, "", levels[-1]
                if status is not None or not model.has_constraints:
                    break
                smallest = min_slack(model, state.trajectory)
                if smallest > 0.0:
                    break
                if restarts >= options.max_infeasible_restarts:
                    status = ProntoStatus.INFEASIBLE
                    break
                restarts += 1
                state.delta = infeasible_restart_delta(state.delta, smallest)
                logger.info(
                    "level eps=%.1e ended infeasible (slack %.3g): delta reduced to %.2e",
                    epsilon,
                    smallest,
                    state.delta,
                )
            if status is not None:
                return status, "", epsilon
            index = _next_level(state, levels, index, options)
    except StopIteration:
        return ProntoStatus.MAX_ITER, "stopped by the callback", epsilon
    except SolverError as error:  # no descent direction from any model of the ladder
        return ProntoStatus.LINE_SEARCH_FAILED, str(error), epsilon
    return None, "", epsilon


@functools.cache
def _blas_pools() -> ThreadpoolController:
    """The process's thread pools, found once (a scan of the loaded libraries takes ~1 ms)."""
    return ThreadpoolController()


def solve_pronto(
    problem: TrajectoryProblem,
    guess: Trajectory,
    *,
    options: ProntoOptions | None = None,
    callback: Callable[[ProntoIteration], None] | None = None,
    cache: ModelCache | None = None,
    projected: bool = False,
) -> ProntoResult:
    """Minimise the problem's objective with discrete-time PRONTO (and barrier continuation).

    Parameters
    ----------
    problem : TrajectoryProblem
        Dynamics, costs, constraints, grid.
    guess : Trajectory
        Initial curve; need not satisfy the dynamics nor the constraints (it is projected
        with a regulator designed along it), unless ``projected``.
    options : ProntoOptions, optional
        Solver options (defaults: ``ProntoOptions()``).
    callback : callable, optional
        ``callback(record: ProntoIteration) -> None`` after every iteration; raising
        ``StopIteration`` stops the solve (status ``MAX_ITER``).
    cache : ModelCache, optional
        Where to look up (and keep) the problem's model; default: build it for this call.
    projected : bool
        The guess is already a trajectory of the dynamics from ``x0`` (a projected guess, or
        an earlier solve's trajectory, as the CasADi reference solvers start from): it is the
        first iterate as it is, without a projection (checked: :func:`check_trajectory`).

    Returns
    -------
    ProntoResult
        Final trajectory, status, cost parts, per-iteration history, last regulator gains.

    Raises
    ------
    InputError
        If the guess has the wrong shape or non-finite values, or is not a trajectory of the
        dynamics although ``projected``.
    SolverError
        If the projection of the guess diverges.

    Notes
    -----
    Without constraints this is plain discrete PRONTO. With constraints, ``ε`` runs through
    :meth:`ProntoOptions.epsilon_levels`; ``δ`` starts at ``delta_initial`` and is shrunk below
    the smallest barrier argument once the trajectory is strictly feasible, after which
    infeasible line-search candidates are rejected. A level that ends infeasible is re-solved
    with ``δ`` reduced by :func:`infeasible_restart_delta` (at most
    ``max_infeasible_restarts`` times). A level before the last also ends once the next
    level's barrier shift outweighs its decrement (:func:`_outweighed`). After a level, the
    levels before the last are skipped when the trajectory is predicted to pass the last
    level's test already (:func:`_next_level`); within a level, a point that the last two
    full Newton steps predict to pass it is tested there first (:func:`_probe`, recorded at
    the last ``ε``; the solve ends if it passes).
    """
    options = options if options is not None else ProntoOptions()
    check_guess(problem, guess)
    start = time.perf_counter()
    cache = cache if cache is not None else ModelCache(max_entries=1)
    model = cache.get(problem, options.backend)
    # The solver's linear algebra is on matrices of tens of rows, stage by stage: BLAS threads
    # only add synchronisation (3x slower eigen-decompositions on two cores).
    with _blas_pools().limit(limits=1, user_api="blas"):
        if projected:
            check_trajectory(model, guess)
            state = _State(guess, None, options.delta_initial)
        else:
            state = _State(*project_guess(model, guess, options), options.delta_initial)
        status, message, epsilon = _continuation(model, state, options, start, callback)
        gains = state.gains
        if gains is None:  # no direction was computed
            gains = first_order_model(
                model, state.trajectory, epsilon, state.delta, options=options
            ).gains
        return final_result(
            model, state.trajectory, gains, status=status, message=message,
            epsilon=epsilon, delta=state.delta, n_iter=state.n_iter,
            history=tuple(state.history), options=options, start=start,
        )  # fmt: skip


def final_result(
    model: ProntoModel,
    trajectory: Trajectory,
    gains: FloatArray,
    *,
    status: ProntoStatus | None,
    message: str,
    epsilon: float,
    delta: float,
    n_iter: int,
    history: tuple[ProntoIteration, ...],
    options: ProntoOptions,
    start: float,
) -> ProntoResult:
    """The :class:`ProntoResult` of a solve that ended at ``trajectory`` (barrier ``ε``, ``δ``).

    ``status`` None means converged: CONVERGED (with ``message``, or the stopping bound),
    unless the smallest scaled slack is not positive (INFEASIBLE). An empty ``message`` of
    another status gets that status's own. ``start`` is the solve's ``perf_counter`` start.
    """
    cost, smallest = evaluate_cost(model, trajectory, epsilon, delta)
    if status is None:
        if model.has_constraints and not smallest > 0.0:
            status = ProntoStatus.INFEASIBLE
            message = f"converged but infeasible: smallest scaled slack {smallest:.3g}"
        else:
            status = ProntoStatus.CONVERGED
            bound = max(options.tol, options.rtol * abs(cost.objective))
            message = message or f"converged: -Dh·ζ < {bound:.3g} after {n_iter} steps"
    elif not message:
        message = {
            ProntoStatus.MAX_ITER: f"reached max_iter = {options.max_iter}",
            ProntoStatus.LINE_SEARCH_FAILED: "Armijo line search failed to decrease the cost",
            ProntoStatus.INFEASIBLE: (
                f"no strictly feasible trajectory (smallest scaled slack {smallest:.3g})"
            ),
            ProntoStatus.CONVERGED: "converged",
        }[status]
    return ProntoResult(
        trajectory=trajectory,
        status=status,
        message=message,
        cost=cost.objective,
        running_cost=cost.running,
        terminal_cost=cost.terminal,
        barrier_cost=cost.barrier,
        n_iter=n_iter,
        history=history,
        regulator_gains=gains,
        epsilon=epsilon if model.has_constraints else 0.0,
        delta=delta if model.has_constraints else float("inf"),
        min_slack=smallest,
        wall_time=time.perf_counter() - start,
    )
