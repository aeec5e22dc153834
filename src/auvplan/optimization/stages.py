"""Stage-wise PRONTO quantities along a trajectory: costs, linearisation, regulator, projection.

Everything here is batched over the ``N`` stages (CasADi ``map``) or a compiled sequential
recursion (numba, :mod:`auvplan.optimization._kernels`). Equations: ``reference/pronto.md``
§6.1 (projection and regulator), §6.2 (costate and second-order weights), §7 (barrier).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import scipy.linalg

from auvplan._typing import BoolArray, FloatArray
from auvplan.errors import SolverError
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
    "CostParts",
    "Linearization",
    "ProntoModel",
    "StageWeights",
    "build_model",
    "compute_costate",
    "design_regulator",
    "evaluate_cost",
    "linearize",
    "project",
    "second_order_weights",
]


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


_MODEL_CACHE: dict[tuple[int, int, bool], tuple[TrajectoryProblem, ProntoModel]] = {}


def build_model(
    problem: TrajectoryProblem, *, n_threads: int = 1, compile_c: bool = False
) -> ProntoModel:
    """Discretise a problem (RK4 map, stage cost, constraints, terminal cost); cached per problem.

    Parameters
    ----------
    problem : TrajectoryProblem
        The problem.
    n_threads : int, optional
        Threads for the batched stage evaluations (1 = serial).
    compile_c : bool, optional
        Compile the stage functions to C (cached on disk; see :func:`discretize_rk4`).

    Returns
    -------
    ProntoModel
        Batched evaluators.
    """
    key = (id(problem), n_threads, compile_c)
    cached = _MODEL_CACHE.get(key)
    if cached is not None and cached[0] is problem:
        return cached[1]
    discrete = discretize_rk4(
        problem.dynamics,
        problem.running_cost,
        problem.dt,
        parallelization="thread" if n_threads > 1 else "serial",
        n_threads=n_threads,
        compile_c=compile_c,
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
