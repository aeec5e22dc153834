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
import scipy.linalg

from auvplan._typing import BoolArray, FloatArray
from auvplan.errors import InputError, SolverError
from auvplan.optimization import _kernels
from auvplan.optimization.barrier import composed_barrier, hockey_stick
from auvplan.optimization.discretization import (
    ConstraintModel,
    DiscreteModel,
    TerminalCost,
    discretize_constraints,
    discretize_rk4,
    make_terminal_cost,
)
from auvplan.optimization.problem import Trajectory, TrajectoryProblem

__all__ = [
    "ArmijoResult",
    "CostParts",
    "DerivativeCheck",
    "DirectionType",
    "Linearization",
    "LqDirection",
    "ProntoIteration",
    "ProntoModel",
    "ProntoOptions",
    "ProntoResult",
    "ProntoStatus",
    "StageWeights",
    "armijo_step",
    "build_model",
    "compute_costate",
    "converged",
    "convexify",
    "derivative_check",
    "design_regulator",
    "evaluate_cost",
    "linearize",
    "project",
    "project_guess",
    "second_order_weights",
    "solve_lq_direction",
    "solve_pronto",
]

logger = logging.getLogger(__name__)


class ProntoStatus(enum.Enum):
    """Outcome of :func:`solve_pronto`."""

    CONVERGED = "converged"
    MAX_ITER = "max_iter"
    LINE_SEARCH_FAILED = "line_search_failed"
    INFEASIBLE = "infeasible"


class DirectionType(enum.Enum):
    """Which quadratic model produced the search direction (the fallback ladder)."""

    NEWTON = "newton"
    CONVEXIFIED = "convexified"
    STEEPEST = "steepest"


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
    eigenvalue_floor: float = 1e-8
    terminal_regulator: Literal["dare", "weight"] = "dare"
    n_threads: int = 1
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
class CostParts:
    """Objective split: running (RK4 quadrature), terminal, and ``ε``-weighted barrier."""

    running: float
    terminal: float
    barrier: float

    @property
    def total(self) -> float:
        """``running + terminal + barrier``."""
        return self.running + self.terminal + self.barrier

    @property
    def objective(self) -> float:
        """The original objective without barrier, ``running + terminal``."""
        return self.running + self.terminal


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


@dataclass(frozen=True, eq=False)
class ProntoModel:
    """Compiled, batched evaluators of a :class:`TrajectoryProblem` (see :func:`build_model`)."""

    problem: TrajectoryProblem
    discrete: DiscreteModel
    terminal: TerminalCost
    constraints: ConstraintModel | None
    slack_scales: FloatArray
    is_hockey: BoolArray

    @property
    def has_constraints(self) -> bool:
        """True when there is at least one constraint component."""
        return self.constraints is not None and self.constraints.n_c > 0


_MODEL_CACHE: dict[tuple[int, int], tuple[TrajectoryProblem, ProntoModel]] = {}


def build_model(problem: TrajectoryProblem, *, n_threads: int = 1) -> ProntoModel:
    """Discretise a problem (RK4 map, stage cost, constraints, terminal cost); cached per problem.

    Parameters
    ----------
    problem : TrajectoryProblem
        The problem.
    n_threads : int, optional
        Threads for the batched stage evaluations (1 = serial).

    Returns
    -------
    ProntoModel
        Batched evaluators.
    """
    key = (id(problem), n_threads)
    cached = _MODEL_CACHE.get(key)
    if cached is not None and cached[0] is problem:
        return cached[1]
    discrete = discretize_rk4(
        problem.dynamics,
        problem.running_cost,
        problem.dt,
        parallelization="thread" if n_threads > 1 else "serial",
        n_threads=n_threads,
    )
    terminal = make_terminal_cost(problem.terminal_cost, problem.n_states)
    constraints = None
    scales: list[float] = []
    hockey: list[bool] = []
    if problem.constraints:
        constraints = discretize_constraints(
            tuple(c.function for c in problem.constraints),
            problem.n_states,
            problem.n_inputs,
            problem.n_parameters,
        )
        for constraint in problem.constraints:
            scales += [constraint.scale] * constraint.n_components
            hockey += [constraint.kind == "hockey"] * constraint.n_components
    model = ProntoModel(
        problem=problem,
        discrete=discrete,
        terminal=terminal,
        constraints=constraints,
        slack_scales=np.asarray(scales, dtype=np.float64),
        is_hockey=np.asarray(hockey, dtype=np.bool_),
    )
    if len(_MODEL_CACHE) > 16:
        _MODEL_CACHE.clear()
    _MODEL_CACHE[key] = (problem, model)
    return model


def _barrier_terms(
    model: ProntoModel, slack: FloatArray, delta: float
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Barrier value, its first and second derivatives in ``s``, and the arguments ``z``."""
    hockey_value = composed_barrier(slack, delta, is_hockey=True)
    plain_value = composed_barrier(slack, delta, is_hockey=False)
    mask = model.is_hockey[None, :]
    parts = [np.where(mask, h, p) for h, p in zip(hockey_value, plain_value, strict=True)]
    argument = np.where(mask, hockey_stick(slack)[0], slack)
    return parts[0], parts[1], parts[2], argument


def _min_slack(model: ProntoModel, trajectory: Trajectory) -> float:
    if not model.has_constraints:
        return float("inf")
    assert model.constraints is not None
    values = model.constraints.values(
        trajectory.states[:-1], trajectory.inputs, model.problem.parameters
    )
    return float(np.min(values / model.slack_scales))


def evaluate_cost(
    model: ProntoModel, trajectory: Trajectory, epsilon: float, delta: float
) -> tuple[CostParts, float]:
    """Objective parts of a trajectory and its smallest scaled slack.

    Parameters
    ----------
    model : ProntoModel
        Evaluators.
    trajectory : Trajectory
        States ``(N+1, n_x)`` and inputs ``(N, n_u)``.
    epsilon, delta : float
        Barrier weight and switching point (ignored without constraints).

    Returns
    -------
    parts : CostParts
        ``running = Σ L_k``, ``terminal = m(x_N)``, ``barrier = ε dt Σ_{k,j} b_j(s_kj)``.
        Non-finite trajectories give ``inf`` parts.
    min_slack : float
        ``min_{k,j} c_kj / scale_j`` (``inf`` without constraints).
    """
    if not (np.all(np.isfinite(trajectory.states)) and np.all(np.isfinite(trajectory.inputs))):
        return CostParts(np.inf, np.inf, np.inf), -np.inf
    params = model.problem.parameters
    with np.errstate(over="ignore", invalid="ignore"):
        running = float(
            np.sum(model.discrete.cost(trajectory.states[:-1], trajectory.inputs, params))
        )
        terminal = model.terminal.value(trajectory.states[-1])
        barrier = 0.0
        min_slack = float("inf")
        if model.has_constraints:
            assert model.constraints is not None
            values = model.constraints.values(trajectory.states[:-1], trajectory.inputs, params)
            slack = values / model.slack_scales
            value, _, _, _ = _barrier_terms(model, slack, delta)
            barrier = float(epsilon * model.problem.dt * np.sum(value))
            min_slack = float(np.min(slack))
    parts = CostParts(running, terminal, barrier)
    if not np.isfinite(parts.total):
        return CostParts(np.inf, np.inf, np.inf), -np.inf
    return parts, min_slack


@dataclass(frozen=True)
class Linearization:
    """First-order data along a trajectory (time-major).

    Attributes
    ----------
    A, B : ndarray of shape (N, n_x, n_x), (N, n_x, n_u)
        ``F_x``, ``F_u``.
    a, b : ndarray of shape (N, n_x), (N, n_u)
        Gradients of the barrier-augmented stage cost.
    m_x : ndarray of shape (n_x,)
        Terminal-cost gradient; ``m_xx`` its Hessian ``(n_x, n_x)``.
    cost : CostParts
        Objective parts at the trajectory.
    min_slack : float
        Smallest scaled slack; ``min_argument`` the smallest barrier argument ``z``.
    barrier_outer : ndarray of shape (N, n_c)
        ``ε dt b''(s) / scale²`` (weights of ``c_x c_xᵀ``); ``barrier_weight`` is
        ``ε dt b'(s) / scale`` (weights of ``∇²c``); ``c_x``, ``c_u`` the constraint Jacobians.
    """

    A: FloatArray
    B: FloatArray
    a: FloatArray
    b: FloatArray
    m_x: FloatArray
    m_xx: FloatArray
    cost: CostParts
    min_slack: float
    min_argument: float
    epsilon: float
    delta: float
    barrier_outer: FloatArray
    barrier_weight: FloatArray
    c_x: FloatArray
    c_u: FloatArray


def linearize(
    model: ProntoModel, trajectory: Trajectory, epsilon: float, delta: float
) -> Linearization:
    """Jacobians, cost gradients and barrier terms along a trajectory (batched).

    Notes
    -----
    With slack ``s = c / scale`` and ``b`` the composed barrier,
    ``a_k = L_x + ε dt Σ_j b'_j c_{x,j} / scale_j`` (likewise ``b_k``).
    """
    problem = model.problem
    states, inputs, params = trajectory.states[:-1], trajectory.inputs, problem.parameters
    f_x, f_u, stage_cost, l_x, l_u = model.discrete.first_order(states, inputs, params)
    terminal, m_x, m_xx = model.terminal.evaluate(trajectory.states[-1])
    n_stages = trajectory.n_steps
    n_c = model.constraints.n_c if model.constraints is not None else 0
    outer = np.zeros((n_stages, n_c))
    weight = np.zeros((n_stages, n_c))
    c_x = np.zeros((n_stages, n_c, problem.n_states))
    c_u = np.zeros((n_stages, n_c, problem.n_inputs))
    barrier = 0.0
    min_slack = min_argument = float("inf")
    if model.has_constraints:
        assert model.constraints is not None
        values, c_x, c_u = model.constraints.jacobians(states, inputs, params)
        scale = model.slack_scales
        slack = values / scale
        value, first, second, argument = _barrier_terms(model, slack, delta)
        factor = epsilon * problem.dt
        barrier = float(factor * np.sum(value))
        weight = factor * first / scale
        outer = factor * second / (scale * scale)
        l_x = l_x + np.einsum("kj,kji->ki", weight, c_x)
        l_u = l_u + np.einsum("kj,kji->ki", weight, c_u)
        min_slack = float(np.min(slack))
        min_argument = float(np.min(argument))
    return Linearization(
        A=f_x,
        B=f_u,
        a=np.ascontiguousarray(l_x),
        b=np.ascontiguousarray(l_u),
        m_x=m_x,
        m_xx=m_xx,
        cost=CostParts(float(np.sum(stage_cost)), terminal, barrier),
        min_slack=min_slack,
        min_argument=min_argument,
        epsilon=epsilon,
        delta=delta,
        barrier_outer=outer,
        barrier_weight=weight,
        c_x=c_x,
        c_u=c_u,
    )


def design_regulator(
    A: FloatArray,
    B: FloatArray,
    Q_r: FloatArray,
    R_r: FloatArray,
    *,
    terminal: Literal["dare", "weight"] = "dare",
) -> FloatArray:
    """Time-varying discrete LQR along a trajectory (the projection regulator, §6.1).

    Parameters
    ----------
    A, B : ndarray of shape (N, n_x, n_x), (N, n_x, n_u)
        Linearisation along the trajectory.
    Q_r, R_r : ndarray of shape (n_x, n_x), (n_u, n_u)
        Regulator weights (``R_r ≻ 0``).
    terminal : {"dare", "weight"}
        ``P_N`` from :func:`scipy.linalg.solve_discrete_are` at the last stage (falls back
        to ``Q_r`` when the ARE fails) or ``Q_r``.

    Returns
    -------
    ndarray of shape (N, n_u, n_x)
        Gains ``K_k`` for ``u_k = μ_k + K_k (α_k − x_k)``.

    Raises
    ------
    SolverError
        If the Riccati recursion breaks down (non-finite linearisation).
    """
    p_final = Q_r
    if terminal == "dare":
        try:
            with np.errstate(all="ignore"):
                candidate = scipy.linalg.solve_discrete_are(A[-1], B[-1], Q_r, R_r)
            if np.all(np.isfinite(candidate)) and np.min(np.linalg.eigvalsh(candidate)) > -1e-9:
                p_final = 0.5 * (candidate + candidate.T)
        except (np.linalg.LinAlgError, ValueError):
            p_final = Q_r
    gains, ok = _kernels.regulator_riccati(
        np.ascontiguousarray(A), np.ascontiguousarray(B), Q_r, R_r, np.ascontiguousarray(p_final)
    )
    if not ok or not np.all(np.isfinite(gains)):
        raise SolverError(
            "the projection-regulator Riccati recursion broke down (non-finite A, B?)"
        )
    return gains


def project(model: ProntoModel, reference: Trajectory, gains: FloatArray) -> Trajectory:
    """Projection operator ``P``: closed loop ``u_k = μ_k + K_k (α_k − x_k)`` from ``x0``.

    Parameters
    ----------
    model : ProntoModel
        Evaluators.
    reference : Trajectory
        The curve ``η = (α, μ)`` (need not satisfy the dynamics).
    gains : ndarray of shape (N, n_u, n_x)
        Regulator gains.

    Returns
    -------
    Trajectory
        ``P(η)``; may contain non-finite values if the simulation diverged.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        states, inputs = model.discrete.rollout(
            model.problem.initial_state,
            reference.states,
            reference.inputs,
            gains,
            model.problem.parameters,
        )
    return Trajectory(states, inputs)


def compute_costate(linearization: Linearization, gains: FloatArray) -> FloatArray:
    """Closed-loop costate ``λ_k = a_k − K_kᵀ b_k + (A_k − B_k K_k)ᵀ λ_{k+1}``, ``λ_N = m_x``.

    Returns
    -------
    ndarray of shape (N + 1, n_x)
        ``λ_0 .. λ_N``.
    """
    lin = linearization
    return _kernels.closed_loop_costate(lin.A, lin.B, gains, lin.a, lin.b, lin.m_x)


@dataclass(frozen=True)
class StageWeights:
    """Quadratic-model weights ``Q (N, n_x, n_x)``, ``S (N, n_x, n_u)``, ``R``, ``P_N``."""

    Q: FloatArray
    S: FloatArray
    R: FloatArray
    P_N: FloatArray


def _barrier_hessians(
    model: ProntoModel, trajectory: Trajectory, lin: Linearization
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Hessian blocks of the barrier term: ``Σ_j [w''_j c_j' c_j'ᵀ + w'_j ∇²c_j]``."""
    assert model.constraints is not None
    h_xx, h_xu, h_uu = model.constraints.weighted_hessians(
        trajectory.states[:-1], trajectory.inputs, model.problem.parameters, lin.barrier_weight
    )
    outer = lin.barrier_outer
    h_xx = h_xx + np.einsum("kj,kja,kjb->kab", outer, lin.c_x, lin.c_x)
    h_xu = h_xu + np.einsum("kj,kja,kjb->kab", outer, lin.c_x, lin.c_u)
    h_uu = h_uu + np.einsum("kj,kja,kjb->kab", outer, lin.c_u, lin.c_u)
    return h_xx, h_xu, h_uu


def second_order_weights(
    model: ProntoModel, trajectory: Trajectory, linearization: Linearization, costate: FloatArray
) -> StageWeights:
    """Newton weights ``Q = L_xx + Σ_i λ_{k+1,i} F^i_xx`` (and ``S``, ``R``), ``P_N = m_xx``.

    The Hessian of the step at stage ``k`` is weighted by ``λ_{k+1}`` (§6.2); barrier terms
    are added exactly.
    """
    q, s, r = model.discrete.lagrangian_hessians(
        trajectory.states[:-1], trajectory.inputs, model.problem.parameters, costate[1:]
    )
    if model.has_constraints:
        b_xx, b_xu, b_uu = _barrier_hessians(model, trajectory, linearization)
        q, s, r = q + b_xx, s + b_xu, r + b_uu
    return StageWeights(q, s, r, linearization.m_xx)


def _quasi_weights(
    model: ProntoModel, trajectory: Trajectory, linearization: Linearization
) -> StageWeights:
    """Cost Hessians only (no ``λ·∇²F``): the quasi-Newton model."""
    q, s, r = model.discrete.cost_hessians(
        trajectory.states[:-1], trajectory.inputs, model.problem.parameters
    )
    if model.has_constraints:
        b_xx, b_xu, b_uu = _barrier_hessians(model, trajectory, linearization)
        q, s, r = q + b_xx, s + b_xu, r + b_uu
    return StageWeights(q, s, r, linearization.m_xx)


@dataclass(frozen=True)
class _QuasiWeights:
    """Deferred evaluation of the quasi-Newton weights (only needed when Newton fails)."""

    model: ProntoModel
    trajectory: Trajectory
    linearization: Linearization

    def __call__(self) -> StageWeights:
        return _quasi_weights(self.model, self.trajectory, self.linearization)


def convexify(weights: StageWeights, floor: float) -> StageWeights:
    """Clip the eigenvalues of every ``[[Q, S], [Sᵀ, R]]`` and of ``P_N`` at ``floor``.

    Returns
    -------
    StageWeights
        Positive-definite weights (projection onto ``{W ⪰ floor·I}`` per stage).
    """
    n_x = weights.Q.shape[1]
    top = np.concatenate([weights.Q, weights.S], axis=2)
    bottom = np.concatenate([np.swapaxes(weights.S, 1, 2), weights.R], axis=2)
    stacked = np.concatenate([top, bottom], axis=1)
    stacked = 0.5 * (stacked + np.swapaxes(stacked, 1, 2))
    values, vectors = np.linalg.eigh(stacked)
    clipped = np.einsum("kij,kj,klj->kil", vectors, np.maximum(values, floor), vectors)
    p_values, p_vectors = np.linalg.eigh(0.5 * (weights.P_N + weights.P_N.T))
    p_clipped = (p_vectors * np.maximum(p_values, floor)) @ p_vectors.T
    return StageWeights(
        np.ascontiguousarray(clipped[:, :n_x, :n_x]),
        np.ascontiguousarray(clipped[:, :n_x, n_x:]),
        np.ascontiguousarray(clipped[:, n_x:, n_x:]),
        p_clipped,
    )


@dataclass(frozen=True)
class LqDirection:
    """Search direction ``ζ = (z, v)`` from the LQ subproblem.

    Attributes
    ----------
    z : ndarray of shape (N + 1, n_x)
        State direction (``z_0 = 0``).
    v : ndarray of shape (N, n_u)
        Input direction.
    slope : float
        ``Dh·ζ`` (negative for a descent direction).
    model_curvature : float
        Second derivative of the model that produced ζ, along ζ.
    direction : DirectionType
        Ladder level used.
    """

    z: FloatArray
    v: FloatArray
    slope: float
    model_curvature: float
    direction: DirectionType


def _quadratic_form(weights: StageWeights, z: FloatArray, v: FloatArray) -> float:
    zs, zn = z[:-1], z[-1]
    return float(
        np.einsum("ki,kij,kj->", zs, weights.Q, zs)
        + 2.0 * np.einsum("ki,kij,kj->", zs, weights.S, v)
        + np.einsum("ki,kij,kj->", v, weights.R, v)
        + zn @ weights.P_N @ zn
    )


def _slope(linearization: Linearization, z: FloatArray, v: FloatArray) -> float:
    lin = linearization
    return float(np.sum(lin.a * z[:-1]) + np.sum(lin.b * v) + lin.m_x @ z[-1])


def _try_direction(
    linearization: Linearization, weights: StageWeights, direction: DirectionType
) -> LqDirection | None:
    lin = linearization
    feedback, feedforward, failed = _kernels.lq_backward(
        lin.A,
        lin.B,
        np.ascontiguousarray(weights.Q),
        np.ascontiguousarray(weights.S),
        np.ascontiguousarray(weights.R),
        lin.a,
        lin.b,
        np.ascontiguousarray(weights.P_N),
        np.ascontiguousarray(lin.m_x),
    )
    if failed >= 0:
        logger.debug("%s LQ model not positive definite at stage %d", direction.value, failed)
        return None
    z, v = _kernels.lq_forward(lin.A, lin.B, feedback, feedforward)
    slope = _slope(lin, z, v)
    if not (np.isfinite(slope) and np.all(np.isfinite(z))):
        return None
    curvature = _quadratic_form(weights, z, v)
    if slope > 0.0:
        logger.debug("%s direction is not a descent direction (Dh·ζ = %g)", direction.value, slope)
        return None
    return LqDirection(z, v, slope, curvature, direction)


def solve_lq_direction(
    linearization: Linearization,
    weights: StageWeights,
    *,
    quasi_weights: Callable[[], StageWeights] | None = None,
    steepest_weights: StageWeights | None = None,
    eigenvalue_floor: float = 1e-8,
) -> LqDirection:
    """Search direction by the discrete Riccati recursion with cross term (§6.3).

    Fallback ladder: Newton (``weights``) → convexified quasi-Newton (eigenvalue-clipped
    ``quasi_weights()``, or clipped ``weights`` when none given) → steepest
    (``steepest_weights``, e.g. the regulator weights). A level is rejected when some
    ``M_k = R_k + B_kᵀ P_{k+1} B_k`` fails the Cholesky test or ``Dh·ζ > 0``.

    Parameters
    ----------
    linearization : Linearization
        ``A, B, a, b, m_x`` along the current trajectory.
    weights : StageWeights
        Exact second-order weights (:func:`second_order_weights`).
    quasi_weights : callable, optional
        Lazily computed quasi-Newton weights (cost Hessians only).
    steepest_weights : StageWeights, optional
        Last-resort positive-definite model.
    eigenvalue_floor : float
        Eigenvalue clip of the convexified model.

    Returns
    -------
    LqDirection
        Direction, slope ``Dh·ζ`` and the ladder level used.

    Raises
    ------
    SolverError
        If no level produced a descent direction.
    """
    direction = _try_direction(linearization, weights, DirectionType.NEWTON)
    if direction is not None:
        return direction
    base = quasi_weights() if quasi_weights is not None else weights
    direction = _try_direction(
        linearization, convexify(base, eigenvalue_floor), DirectionType.CONVEXIFIED
    )
    if direction is not None:
        return direction
    if steepest_weights is not None:
        direction = _try_direction(linearization, steepest_weights, DirectionType.STEEPEST)
        if direction is not None:
            return direction
    raise SolverError("no descent direction: Newton, convexified and steepest models all failed")


@dataclass(frozen=True)
class ArmijoResult:
    """Outcome of :func:`armijo_step`."""

    accepted: bool
    trajectory: Trajectory
    cost: CostParts
    min_slack: float
    min_argument: float
    step: float
    n_backtracks: int


def _min_argument(model: ProntoModel, min_slack: float) -> float:
    """Lower bound of the smallest barrier argument ``z`` from the smallest slack.

    ``σ`` is monotone and ``tanh s ≤ s``, so ``tanh(min s)`` bounds every ``z`` from below.
    """
    if not model.has_constraints:
        return float("inf")
    if np.any(model.is_hockey) and min_slack > 0.0:
        return float(np.tanh(min_slack))
    return min_slack


def armijo_step(
    model: ProntoModel,
    trajectory: Trajectory,
    direction: LqDirection,
    gains: FloatArray,
    current_cost: float,
    *,
    epsilon: float,
    delta: float,
    alpha: float = 0.4,
    beta: float = 0.7,
    max_backtracks: int = 30,
    require_feasible: bool = False,
) -> ArmijoResult:
    """Armijo backtracking on ``g(γ) = h(P(ξ + γζ))`` with the iteration's regulator fixed.

    Accept ``γ`` when ``h(P(ξ + γζ)) ≤ h(ξ) + α γ Dh·ζ``; otherwise ``γ ← β γ``. Non-finite
    candidates (diverged projection) are rejected; with ``require_feasible`` so are
    candidates with a non-positive slack.

    Returns
    -------
    ArmijoResult
        ``accepted`` is False when ``max_backtracks`` reductions did not succeed.
    """
    step = 1.0
    for n_backtracks in range(max_backtracks + 1):
        reference = Trajectory(
            trajectory.states + step * direction.z, trajectory.inputs + step * direction.v
        )
        candidate = project(model, reference, gains)
        cost, min_slack = evaluate_cost(model, candidate, epsilon, delta)
        feasible_ok = not require_feasible or min_slack > 0.0
        if (
            np.isfinite(cost.total)
            and feasible_ok
            and cost.total <= current_cost + alpha * step * direction.slope
        ):
            return ArmijoResult(
                True,
                candidate,
                cost,
                min_slack,
                _min_argument(model, min_slack),
                step,
                n_backtracks,
            )
        step *= beta
    return ArmijoResult(
        False, trajectory, CostParts(np.inf, np.inf, np.inf), -np.inf, -np.inf, 0.0, max_backtracks
    )


def converged(decrement: float, tol: float) -> bool:
    """Stopping test ``−Dh·ζ < tol`` (``decrement = −Dh·ζ``).

    Examples
    --------
    >>> converged(1e-9, 1e-6)
    True
    """
    return bool(decrement < tol)


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
    model = build_model(problem, n_threads=options.n_threads)
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
