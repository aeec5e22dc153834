"""Discrete-time PRONTO (projection-operator Newton method) with approximate barriers.

The solver loop is written as named, individually testable steps (STYLE B2)::

    ξ ← project(guess)                                   # regulator designed along the guess
    for ε in ε-levels:                                   # barrier continuation (§7.5)
        repeat:
            lin  = linearize(ξ)                          # A, B, a, b, m_x, cost, slacks
            K    = design_regulator(A, B, Q_r, R_r)      # time-varying DLQR along ξ
            λ    = compute_costate(lin, K)               # closed-loop costate
            W    = second_order_weights(ξ, lin, λ)       # l'' + Σ λ_{k+1,i} F^i''
            ζ    = solve_lq_direction(lin, W)            # Newton → convexified → steepest
            if converged(−Dh·ζ): break
            ξ    = armijo_step(ξ, ζ, K)                  # on h(P(ξ + γζ)), K fixed
            shrink δ once strictly feasible

Equations and defaults follow ``reference/pronto.md`` §6 (discrete PRONTO), §7 (barrier) and
§11. The discrete problem is stated in :mod:`auvplan.optimization.problem`.

References
----------
J. Hauser, "A projection operator approach to the optimization of trajectory functionals",
IFAC World Congress 2002. J. Hauser, A. Saccon, "A barrier function method for the
optimization of trajectory functionals with constraints", IEEE CDC 2006.
"""

from __future__ import annotations

import enum
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError, SolverError
from auvplan.optimization import _kernels
from auvplan.optimization.linesearch import armijo_step, converged
from auvplan.optimization.lq import (
    DirectionType,
    _quadratic_form,
    _slope,
    solve_lq_direction,
)
from auvplan.optimization.problem import Trajectory, TrajectoryProblem
from auvplan.optimization.stages import (
    ProntoModel,
    StageWeights,
    _min_slack,
    _QuasiWeights,
    build_model,
    compute_costate,
    design_regulator,
    evaluate_cost,
    linearize,
    project,
    second_order_weights,
)

__all__ = [
    "DerivativeCheck",
    "ProntoIteration",
    "ProntoOptions",
    "ProntoResult",
    "ProntoStatus",
    "derivative_check",
    "project_guess",
    "solve_pronto",
]

logger = logging.getLogger(__name__)


class ProntoStatus(enum.Enum):
    """Outcome of :func:`solve_pronto`."""

    CONVERGED = "converged"
    MAX_ITER = "max_iter"
    LINE_SEARCH_FAILED = "line_search_failed"
    INFEASIBLE = "infeasible"


@dataclass(frozen=True)
class ProntoOptions:
    """Options of :func:`solve_pronto`.

    Attributes
    ----------
    tol : float
        Stop when ``−Dh·ζ < tol`` at the final barrier level (cost units).
    inner_tol : float
        Same test at intermediate barrier levels.
    max_iter : int
        Maximum number of PRONTO iterations (directions computed) over all levels.
    alpha, beta : float
        Armijo sufficient-decrease and backtracking factors.
    max_backtracks : int
        Maximum number of step reductions per line search.
    eps_initial, eps_final, eps_factor : float
        Barrier weight continuation ``ε ← eps_factor · ε`` from ``eps_initial`` down to
        ``eps_final`` (the last level is exactly ``eps_final``).
    delta_initial : float
        Initial barrier switching point ``δ`` (keep it larger than the worst initial
        violation of the scaled slacks).
    delta_feasible_factor : float
        Once strictly feasible: ``δ ← min(δ, delta_feasible_factor · min z, delta_feasible_max)``
        with ``z`` the barrier arguments.
    delta_feasible_max : float
        Cap on ``δ`` once feasible.
    max_infeasible_restarts : int
        How often a barrier level is re-solved with ``δ`` halved when it ends infeasible.
    eigenvalue_floor : float
        Smallest eigenvalue kept by the convexified model (per stage, relative to ``dt``).
    terminal_regulator : {"dare", "weight"}
        Terminal matrix of the projection regulator: discrete ARE at the last stage (falls
        back to ``Q_r`` when it fails), or ``Q_r``.
    n_threads : int
        Threads for the batched stage evaluations (CasADi ``map(N, "thread", n)``); 1 = serial.
    compile_c : bool
        Evaluate C-compiled stage functions (compiled once per model and cached on disk;
        about 10x faster Hessians; needs a C compiler, else the CasADi VM is used).
    fallback_model : {"newton", "cost"}
        Which weights the convexified fallback clips: the exact Newton weights (default; no
        extra evaluation) or the cost Hessians only (quasi-Newton, one more Hessian pass).
    """

    tol: float = 1e-6
    inner_tol: float = 1e-4
    max_iter: int = 200
    alpha: float = 0.4
    beta: float = 0.7
    max_backtracks: int = 30
    eps_initial: float = 1.0
    eps_final: float = 1e-4
    eps_factor: float = 0.1
    delta_initial: float = 0.5
    delta_feasible_factor: float = 0.1
    delta_feasible_max: float = 1e-3
    max_infeasible_restarts: int = 10
    eigenvalue_floor: float = 1e-2
    terminal_regulator: Literal["dare", "weight"] = "dare"
    n_threads: int = 1
    compile_c: bool = False
    fallback_model: Literal["newton", "cost"] = "newton"

    def __post_init__(self) -> None:
        checks = {
            "tol": self.tol > 0,
            "inner_tol": self.inner_tol > 0,
            "max_iter": self.max_iter >= 1,
            "alpha": 0 < self.alpha < 1,
            "beta": 0 < self.beta < 1,
            "max_backtracks": self.max_backtracks >= 1,
            "eps_initial": self.eps_initial > 0,
            "eps_final": 0 < self.eps_final <= self.eps_initial,
            "eps_factor": 0 < self.eps_factor < 1,
            "delta_initial": self.delta_initial > 0,
            "delta_feasible_factor": 0 < self.delta_feasible_factor < 1,
            "delta_feasible_max": self.delta_feasible_max > 0,
            "eigenvalue_floor": self.eigenvalue_floor > 0,
            "terminal_regulator": self.terminal_regulator in ("dare", "weight"),
            "n_threads": self.n_threads >= 1,
            "fallback_model": self.fallback_model in ("newton", "cost"),
        }
        for name, ok in checks.items():
            if not ok:
                raise InputError(f"ProntoOptions.{name} is out of range: {getattr(self, name)!r}")

    def epsilon_levels(self) -> tuple[float, ...]:
        """The barrier weights visited by the continuation, largest first."""
        levels = [self.eps_initial]
        while levels[-1] * self.eps_factor > self.eps_final * (1.0 + 1e-12):
            levels.append(levels[-1] * self.eps_factor)
        if levels[-1] != self.eps_final:
            levels.append(self.eps_final)
        return tuple(levels)


@dataclass(frozen=True)
class ProntoIteration:
    """One PRONTO iteration (a record of the history).

    Attributes
    ----------
    iteration : int
        Running index over all barrier levels.
    cost : float
        Objective ``h`` (including ``ε``-weighted barrier) at the start of the iteration.
    decrement : float
        ``−Dh·ζ`` of the computed direction.
    step : float
        Accepted Armijo step ``γ`` (0 when the iteration stopped on convergence).
    direction : DirectionType
        Model that produced ζ.
    epsilon, delta : float
        Barrier weight and switching point in force.
    min_slack : float
        Smallest scaled constraint slack ``c / scale`` on the current trajectory (``inf``
        without constraints).
    wall_time : float
        Seconds since the solve started.
    n_backtracks : int
        Step reductions in the line search.
    """

    iteration: int
    cost: float
    decrement: float
    step: float
    direction: DirectionType
    epsilon: float
    delta: float
    min_slack: float
    wall_time: float
    n_backtracks: int


@dataclass(frozen=True)
class ProntoResult:
    """Result of :func:`solve_pronto`.

    Attributes
    ----------
    trajectory : Trajectory
        Final trajectory (always a trajectory of the discrete dynamics).
    status : ProntoStatus
        Outcome.
    message : str
        Human-readable explanation.
    cost : float
        Original objective ``Σ L + m`` (no barrier).
    running_cost, terminal_cost, barrier_cost : float
        Parts; ``barrier_cost`` is ``ε dt Σ b`` at the final ``ε`` and ``δ``.
    n_iter : int
        Number of accepted steps.
    history : tuple of ProntoIteration
        Per-iteration records.
    regulator_gains : ndarray of shape (N, n_u, n_x)
        Projection regulator of the last iteration (``u = μ + K (α − x)``).
    epsilon, delta : float
        Final barrier weight and switching point (0 and inf without constraints).
    min_slack : float
        Smallest scaled constraint slack of the final trajectory.
    wall_time : float
        Seconds.
    """

    trajectory: Trajectory
    status: ProntoStatus
    message: str
    cost: float
    running_cost: float
    terminal_cost: float
    barrier_cost: float
    n_iter: int
    history: tuple[ProntoIteration, ...]
    regulator_gains: FloatArray
    epsilon: float
    delta: float
    min_slack: float
    wall_time: float

    @property
    def success(self) -> bool:
        """True when the solver converged to a feasible trajectory."""
        return self.status is ProntoStatus.CONVERGED

    @property
    def objective(self) -> float:
        """Barrier-augmented objective at the final ``ε``: ``cost + barrier_cost``."""
        return self.cost + self.barrier_cost


def _steepest_weights(model: ProntoModel, n_stages: int) -> StageWeights:
    problem = model.problem
    n_x, n_u = problem.n_states, problem.n_inputs
    return StageWeights(
        np.broadcast_to(problem.state_weight, (n_stages, n_x, n_x)).copy(),
        np.zeros((n_stages, n_x, n_u)),
        np.broadcast_to(problem.input_weight, (n_stages, n_u, n_u)).copy(),
        problem.state_weight.copy(),
    )


def _check_guess(problem: TrajectoryProblem, guess: Trajectory) -> None:
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


def project_guess(
    model: ProntoModel, guess: Trajectory, options: ProntoOptions
) -> tuple[Trajectory, FloatArray]:
    """Project a curve onto the trajectory manifold with a regulator designed along it."""
    f_x, f_u = model.discrete.jacobians(guess.states[:-1], guess.inputs, model.problem.parameters)
    gains = design_regulator(
        f_x,
        f_u,
        model.problem.state_weight,
        model.problem.input_weight,
        terminal=options.terminal_regulator,
    )
    trajectory = project(model, guess, gains)
    if not (np.all(np.isfinite(trajectory.states)) and np.all(np.isfinite(trajectory.inputs))):
        raise SolverError(
            "the projection of the initial guess diverged; use a better guess or regulator"
        )
    return trajectory, gains


@dataclass
class _State:
    """Mutable loop state of :func:`solve_pronto` (private)."""

    trajectory: Trajectory
    gains: FloatArray
    delta: float
    n_iter: int = 0
    history: list[ProntoIteration] = field(default_factory=list)


def _iterate_level(
    model: ProntoModel,
    state: _State,
    epsilon: float,
    tol: float,
    options: ProntoOptions,
    start: float,
    callback: Callable[[ProntoIteration], None] | None,
) -> ProntoStatus | None:
    """Run PRONTO at one barrier weight until convergence; ``None`` means converged."""
    problem = model.problem
    steepest = _steepest_weights(model, problem.n_steps)
    while True:
        if len(state.history) >= options.max_iter:
            return ProntoStatus.MAX_ITER
        trajectory = state.trajectory
        lin = linearize(model, trajectory, epsilon, state.delta)
        gains = design_regulator(
            lin.A,
            lin.B,
            problem.state_weight,
            problem.input_weight,
            terminal=options.terminal_regulator,
        )
        state.gains = gains
        costate = compute_costate(lin, gains)
        weights = second_order_weights(model, trajectory, lin, costate)
        direction = solve_lq_direction(
            lin,
            weights,
            quasi_weights=(
                _QuasiWeights(model, trajectory, lin) if options.fallback_model == "cost" else None
            ),
            steepest_weights=steepest,
            eigenvalue_floor=options.eigenvalue_floor,
        )
        decrement = -direction.slope
        current = lin.cost.total
        is_done = converged(decrement, tol)
        result = None
        if not is_done:
            result = armijo_step(
                model,
                trajectory,
                direction,
                gains,
                current,
                epsilon=epsilon,
                delta=state.delta,
                alpha=options.alpha,
                beta=options.beta,
                max_backtracks=options.max_backtracks,
                require_feasible=model.has_constraints and lin.min_argument > 0.0,
            )
        record = ProntoIteration(
            iteration=len(state.history),
            cost=current,
            decrement=decrement,
            step=result.step if result is not None else 0.0,
            direction=direction.direction,
            epsilon=epsilon,
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
            epsilon,
            state.delta,
            record.min_slack,
        )
        if callback is not None:
            callback(record)
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


def solve_pronto(
    problem: TrajectoryProblem,
    guess: Trajectory,
    *,
    options: ProntoOptions | None = None,
    callback: Callable[[ProntoIteration], None] | None = None,
) -> ProntoResult:
    """Minimise the problem's objective with discrete-time PRONTO (and barrier continuation).

    Parameters
    ----------
    problem : TrajectoryProblem
        Dynamics, costs, constraints, grid.
    guess : Trajectory
        Initial curve; need not satisfy the dynamics nor the constraints (it is projected
        with a regulator designed along it).
    options : ProntoOptions, optional
        Solver options (defaults: ``ProntoOptions()``).
    callback : callable, optional
        ``callback(record: ProntoIteration) -> None`` after every iteration; raising
        ``StopIteration`` stops the solve (status ``MAX_ITER``).

    Returns
    -------
    ProntoResult
        Final trajectory, status, cost parts, per-iteration history, last regulator gains.

    Raises
    ------
    InputError
        If the guess has the wrong shape or non-finite values.
    SolverError
        If the projection of the guess diverges.

    Notes
    -----
    Without constraints this is plain discrete PRONTO. With constraints, ``ε`` runs through
    :meth:`ProntoOptions.epsilon_levels`; ``δ`` starts at ``delta_initial`` and is shrunk below
    the smallest barrier argument once the trajectory is strictly feasible, after which
    infeasible line-search candidates are rejected. A level that ends infeasible is re-solved
    with ``δ`` halved (at most ``max_infeasible_restarts`` times).
    """
    options = options if options is not None else ProntoOptions()
    _check_guess(problem, guess)
    start = time.perf_counter()
    model = build_model(problem, n_threads=options.n_threads, compile_c=options.compile_c)
    trajectory, gains = project_guess(model, guess, options)
    state = _State(trajectory, gains, options.delta_initial)
    levels = options.epsilon_levels() if model.has_constraints else (0.0,)
    status: ProntoStatus | None = None
    message = ""
    epsilon = levels[0]
    try:
        for index, epsilon in enumerate(levels):
            is_last = index == len(levels) - 1
            tol = options.tol if is_last else options.inner_tol
            restarts = 0
            while True:
                status = _iterate_level(model, state, epsilon, tol, options, start, callback)
                if status is not None or not model.has_constraints:
                    break
                if _min_slack(model, state.trajectory) > 0.0:
                    break
                if restarts >= options.max_infeasible_restarts:
                    status = ProntoStatus.INFEASIBLE
                    break
                restarts += 1
                state.delta *= 0.5
                logger.info(
                    "level eps=%.1e ended infeasible: delta halved to %.2e", epsilon, state.delta
                )
            if status is not None:
                break
    except StopIteration:
        status = ProntoStatus.MAX_ITER
        message = "stopped by the callback"
    except SolverError as error:  # no descent direction from any model of the ladder
        status = ProntoStatus.LINE_SEARCH_FAILED
        message = str(error)
    cost, min_slack = evaluate_cost(model, state.trajectory, epsilon, state.delta)
    if status is None:
        if model.has_constraints and not min_slack > 0.0:
            status = ProntoStatus.INFEASIBLE
            message = f"converged but infeasible: smallest scaled slack {min_slack:.3g}"
        else:
            status = ProntoStatus.CONVERGED
            message = f"converged: -Dh·ζ < {options.tol:g} after {state.n_iter} steps"
    elif not message:
        message = {
            ProntoStatus.MAX_ITER: f"reached max_iter = {options.max_iter}",
            ProntoStatus.LINE_SEARCH_FAILED: "Armijo line search failed to decrease the cost",
            ProntoStatus.INFEASIBLE: (
                f"no strictly feasible trajectory (smallest scaled slack {min_slack:.3g})"
            ),
            ProntoStatus.CONVERGED: "converged",
        }[status]
    return ProntoResult(
        trajectory=state.trajectory,
        status=status,
        message=message,
        cost=cost.objective,
        running_cost=cost.running,
        terminal_cost=cost.terminal,
        barrier_cost=cost.barrier,
        n_iter=state.n_iter,
        history=tuple(state.history),
        regulator_gains=state.gains,
        epsilon=epsilon if model.has_constraints else 0.0,
        delta=state.delta if model.has_constraints else float("inf"),
        min_slack=min_slack,
        wall_time=time.perf_counter() - start,
    )


@dataclass(frozen=True)
class DerivativeCheck:
    """Analytic vs central-difference derivatives of ``g(γ) = h(P(ξ + γζ))`` at ``γ = 0``.

    Attributes
    ----------
    slope, slope_fd : float
        ``Dh·ζ`` and ``(g(s) − g(−s)) / 2s``.
    curvature, curvature_fd : float
        ``D²g(ζ, ζ)`` (exact weights) and ``(g(s) − 2g(0) + g(−s)) / s²``.
    slope_error, curvature_error : float
        Relative errors.
    """

    slope: float
    slope_fd: float
    curvature: float
    curvature_fd: float
    slope_error: float
    curvature_error: float


def derivative_check(
    problem: TrajectoryProblem,
    trajectory: Trajectory,
    direction: Trajectory | None = None,
    *,
    epsilon: float = 1.0,
    delta: float = 0.5,
    step: float = 1e-4,
) -> DerivativeCheck:
    """Compare ``Dh·ζ`` and ``D²g(ζ,ζ)`` with central differences of ``g`` along ζ.

    Parameters
    ----------
    problem : TrajectoryProblem
        The problem.
    trajectory : Trajectory
        Point ξ (projected first, so it need not be a trajectory).
    direction : Trajectory, optional
        Only its ``inputs`` ``v (N, n_u)`` are used; the state part is the tangent response
        ``z_{k+1} = A_k z_k + B_k v_k``, ``z_0 = 0``. Default: the PRONTO search direction.
    epsilon, delta : float
        Barrier weight and switching point (ignored without constraints).
    step : float
        Finite-difference step ``s`` in ``γ``.

    Returns
    -------
    DerivativeCheck
        Both derivatives and their relative errors.
    """
    model = build_model(problem)
    xi, _ = project_guess(model, trajectory, ProntoOptions())
    lin = linearize(model, xi, epsilon, delta)
    gains = design_regulator(lin.A, lin.B, problem.state_weight, problem.input_weight)
    costate = compute_costate(lin, gains)
    weights = second_order_weights(model, xi, lin, costate)
    if direction is None:
        zeta = solve_lq_direction(
            lin, weights, steepest_weights=_steepest_weights(model, problem.n_steps)
        )
        z, v = zeta.z, zeta.v
    else:
        v = np.asarray(direction.inputs, dtype=np.float64)
        z, v = _kernels.lq_forward(
            lin.A, lin.B, np.zeros((problem.n_steps, problem.n_inputs, problem.n_states)), v
        )
    slope = _slope(lin, z, v)
    curvature = _quadratic_form(weights, z, v)

    def g(gamma: float) -> float:
        candidate = project(model, Trajectory(xi.states + gamma * z, xi.inputs + gamma * v), gains)
        return evaluate_cost(model, candidate, epsilon, delta)[0].total

    g_plus, g_zero, g_minus = g(step), g(0.0), g(-step)
    slope_fd = (g_plus - g_minus) / (2.0 * step)
    curvature_fd = (g_plus - 2.0 * g_zero + g_minus) / step**2
    return DerivativeCheck(
        slope=slope,
        slope_fd=slope_fd,
        curvature=curvature,
        curvature_fd=curvature_fd,
        slope_error=abs(slope - slope_fd) / max(abs(slope), 1e-300),
        curvature_error=abs(curvature - curvature_fd) / max(abs(curvature), 1e-300),
    )
