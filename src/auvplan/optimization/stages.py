"""Stage-wise PRONTO quantities along a trajectory: cost, linearisation, costate, weights.

Everything here is batched over the ``N`` stages (CasADi ``map``) or a compiled sequential
recursion (numba, :mod:`auvplan.optimization._kernels`). Equations: ``reference/pronto.md``
§6.2 (costate and second-order weights), §7 (barrier).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from auvplan._typing import BoolArray, FloatArray
from auvplan.optimization import _kernels
from auvplan.optimization.barrier import barrier_and_argument
from auvplan.optimization.constraints import SparseJacobians
from auvplan.optimization.model import ProntoModel
from auvplan.optimization.problem import Trajectory

__all__ = [
    "CostParts",
    "Linearization",
    "StageWeights",
    "compute_costate",
    "evaluate_cost",
    "linearize",
    "min_slack",
    "quasi_newton_weights",
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


def _barrier_terms(
    model: ProntoModel, slack: FloatArray, delta: float
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Barrier value, its first and second derivatives in ``s``, and the arguments ``z``.

    Each constraint column through its own kind of barrier (hockey or plain) only.
    """
    parts = [np.empty_like(slack) for _ in range(4)]
    hockey = model.is_hockey
    for columns, is_hockey in ((hockey, True), (~hockey, False)):
        if columns.any():
            terms = barrier_and_argument(slack[:, columns], delta, is_hockey=is_hockey)
            for part, term in zip(parts, terms, strict=True):
                part[:, columns] = term
    return parts[0], parts[1], parts[2], parts[3]


def constraint_nodes(
    model: ProntoModel, trajectory: Trajectory
) -> tuple[FloatArray, FloatArray, FloatArray, BoolArray]:
    """Where the path constraints are imposed: stages ``0..N−1`` and the final node ``N``.

    Returns the states ``(N+1, n_x)``, inputs and parameters ``(N+1, ·)`` (node ``N`` holds
    the last stage's) and the mask ``(N+1, n_c)`` of imposed components (at node ``N`` only
    those free of ``u``, :attr:`ProntoModel.at_final_node`).
    """
    params = model.problem.parameters
    inputs = np.concatenate([trajectory.inputs, trajectory.inputs[-1:]])
    imposed = np.ones((trajectory.n_steps + 1, model.slack_scales.size), dtype=np.bool_)
    imposed[-1] = model.at_final_node
    return trajectory.states, inputs, np.concatenate([params, params[-1:]]), imposed


def _scaled_slacks(model: ProntoModel, trajectory: Trajectory) -> tuple[FloatArray, BoolArray]:
    """Scaled slacks ``c / scale`` at the constraint nodes, and the imposed mask."""
    assert model.constraints is not None
    states, inputs, params, imposed = constraint_nodes(model, trajectory)
    return model.constraints.values(states, inputs, params) / model.slack_scales, imposed


def min_slack(model: ProntoModel, trajectory: Trajectory) -> float:
    """Smallest scaled constraint slack ``min_{k,j} c_kj / scale_j`` (``inf`` without any)."""
    if not model.has_constraints:
        return float("inf")
    slack, imposed = _scaled_slacks(model, trajectory)
    return float(np.min(slack[imposed]))


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
        ``running = Σ L_k``, ``terminal = m(x_N)``, ``barrier = ε dt Σ_{k,j} b_j(s_kj)``
        over the constraint nodes ``k = 0..N`` (:func:`constraint_nodes`).
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
        for term in model.problem.node_costs:
            running += model.problem.dt * float(np.sum(term.values(trajectory.states[:-1])))
        terminal = model.terminal.value(trajectory.states[-1])
        barrier = 0.0
        smallest = float("inf")
        if model.has_constraints:
            slack, imposed = _scaled_slacks(model, trajectory)
            value, _, _, _ = _barrier_terms(model, slack, delta)
            barrier = float(epsilon * model.problem.dt * np.sum(value, where=imposed))
            smallest = float(np.min(slack[imposed]))
    parts = CostParts(running, terminal, barrier)
    if not np.isfinite(parts.total):
        return CostParts(np.inf, np.inf, np.inf), -np.inf
    return parts, smallest


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
    barrier_outer : ndarray of shape (N + 1, n_c)
        ``ε dt b''(s) / scale²`` (weights of ``c_x c_xᵀ``); ``barrier_weight`` is
        ``ε dt b'(s) / scale`` (weights of ``∇²c``); ``constraint_jacobians`` the constraint
        Jacobians (``None`` without constraints); at the constraint nodes ``0..N``
        (:func:`constraint_nodes`; zero where not imposed).
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
    constraint_jacobians: SparseJacobians | None

    def barrier_shift(self, epsilon: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The change of ``a``, ``b`` and ``m_x`` from this ``ε`` to ``epsilon``.

        Every barrier term is proportional to ``ε``: with ``ρ = epsilon / self.epsilon`` the
        gradients change by ``(ρ − 1) ε dt Σ_j b'_j c_{x,j} / scale_j`` (zero without
        constraints).
        """
        n_x = self.A.shape[1]
        if self.constraint_jacobians is None or epsilon == self.epsilon:
            return np.zeros_like(self.a), np.zeros_like(self.b), np.zeros_like(self.m_x)
        ratio = epsilon / self.epsilon
        shift = (ratio - 1.0) * self.constraint_jacobians.weighted_sum(self.barrier_weight)
        return shift[:-1, :n_x], shift[:-1, n_x:], shift[-1, :n_x]

    def at_barrier_weight(self, epsilon: float) -> Linearization:
        """The same trajectory's linearisation at barrier weight ``epsilon`` (exact).

        The gradients move by :meth:`barrier_shift`; the barrier cost and weights scale by
        ``ρ = epsilon / self.epsilon``; ``A``, ``B`` stay.
        """
        if self.constraint_jacobians is None or epsilon == self.epsilon:
            return dataclasses.replace(self, epsilon=epsilon)
        ratio = epsilon / self.epsilon
        d_a, d_b, d_m = self.barrier_shift(epsilon)
        cost = CostParts(self.cost.running, self.cost.terminal, ratio * self.cost.barrier)
        return dataclasses.replace(
            self, a=self.a + d_a, b=self.b + d_b, m_x=self.m_x + d_m, cost=cost,
            epsilon=epsilon, barrier_outer=ratio * self.barrier_outer,
            barrier_weight=ratio * self.barrier_weight,
        )  # fmt: skip


def linearize(
    model: ProntoModel, trajectory: Trajectory, epsilon: float, delta: float
) -> Linearization:
    """Jacobians, cost gradients and barrier terms along a trajectory (batched).

    Notes
    -----
    With slack ``s = c / scale`` and ``b`` the composed barrier,
    ``a_k = L_x + ε dt Σ_j b'_j c_{x,j} / scale_j`` (likewise ``b_k``); the final node's
    barrier adds to ``m_x`` (its Hessian to ``P_N``, :func:`second_order_weights`).
    """
    problem = model.problem
    states, inputs, params = trajectory.states[:-1], trajectory.inputs, problem.parameters
    f_x, f_u, stage_cost, l_x, l_u = model.discrete.first_order(states, inputs, params)
    for term in problem.node_costs:
        value, gradient, _ = term.derivatives(states)
        stage_cost = stage_cost + problem.dt * value
        l_x = l_x + problem.dt * gradient
    terminal, m_x, m_xx = model.terminal.evaluate(trajectory.states[-1])
    n_nodes = trajectory.n_steps + 1
    n_c = model.constraints.n_c if model.constraints is not None else 0
    outer = np.zeros((n_nodes, n_c))
    weight = np.zeros((n_nodes, n_c))
    jacobians = None
    barrier = 0.0
    smallest = min_argument = float("inf")
    if model.has_constraints:
        assert model.constraints is not None
        node_states, node_inputs, node_params, imposed = constraint_nodes(model, trajectory)
        values, jacobians = model.constraints.jacobians(node_states, node_inputs, node_params)
        scale = model.slack_scales
        slack = values / scale
        value, first, second, argument = _barrier_terms(model, slack, delta)
        factor = epsilon * problem.dt
        barrier = float(factor * np.sum(value, where=imposed))
        weight = np.where(imposed, factor * first / scale, 0.0)
        outer = np.where(imposed, factor * second / (scale * scale), 0.0)
        gradient = jacobians.weighted_sum(weight)
        n_x = problem.n_states
        l_x = l_x + gradient[:-1, :n_x]
        l_u = l_u + gradient[:-1, n_x:]
        m_x = m_x + gradient[-1, :n_x]  # components free of u: no c_u at node N
        smallest = float(np.min(slack[imposed]))
        min_argument = float(np.min(argument[imposed]))
    return Linearization(
        A=f_x,
        B=f_u,
        a=np.ascontiguousarray(l_x),
        b=np.ascontiguousarray(l_u),
        m_x=m_x,
        m_xx=m_xx,
        cost=CostParts(float(np.sum(stage_cost)), terminal, barrier),
        min_slack=smallest,
        min_argument=min_argument,
        epsilon=epsilon,
        delta=delta,
        barrier_outer=outer,
        barrier_weight=weight,
        constraint_jacobians=jacobians,
    )


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


def _with_barrier_hessians(
    model: ProntoModel,
    trajectory: Trajectory,
    lin: Linearization,
    blocks: tuple[FloatArray, FloatArray, FloatArray],
) -> StageWeights:
    """``blocks`` plus the node costs' and the barrier's Hessians.

    The barrier Hessian is ``Σ_j [w''_j c_j' c_j'ᵀ + w'_j ∇²c_j]``, a node cost's ``dt ∇²r``;
    the final node's barrier Hessian (in ``x`` only) is added to ``P_N = m_xx``. ``blocks``
    are the caller's own arrays (fresh from the model's Hessians): the barrier's terms are
    added to them in place.
    """
    q, s, r = blocks
    p_final = lin.m_xx
    for term in model.problem.node_costs:
        q += model.problem.dt * term.derivatives(trajectory.states[:-1])[2]
    if model.has_constraints:
        assert model.constraints is not None
        assert lin.constraint_jacobians is not None
        states, inputs, params, _ = constraint_nodes(model, trajectory)
        stages, final = slice(None, -1), slice(-1, None)
        model.constraints.add_weighted_hessians(
            states[stages], inputs[stages], params[stages], lin.barrier_weight[stages],
            (q, s, r),
        )  # fmt: skip
        lin.constraint_jacobians[stages].add_outer_products(lin.barrier_outer[stages], (q, s, r))
        n_x, n_u = q.shape[1], r.shape[1]
        end = (lin.m_xx[None].copy(), np.zeros((1, n_x, n_u)), np.zeros((1, n_u, n_u)))
        model.constraints.add_weighted_hessians(
            states[final], inputs[final], params[final], lin.barrier_weight[final], end
        )
        lin.constraint_jacobians[final].add_outer_products(lin.barrier_outer[final], end)
        p_final = end[0][0]
    return StageWeights(q, s, r, p_final)


def second_order_weights(
    model: ProntoModel, trajectory: Trajectory, linearization: Linearization, costate: FloatArray
) -> StageWeights:
    """Newton weights ``Q = L_xx + Σ_i λ_{k+1,i} F^i_xx`` (and ``S``, ``R``), ``P_N = m_xx``.

    The Hessian of the step at stage ``k`` is weighted by ``λ_{k+1}`` (§6.2); barrier terms
    are added exactly.
    """
    blocks = model.discrete.lagrangian_hessians(
        trajectory.states[:-1], trajectory.inputs, model.problem.parameters, costate[1:]
    )
    return _with_barrier_hessians(model, trajectory, linearization, blocks)


def quasi_newton_weights(
    model: ProntoModel, trajectory: Trajectory, linearization: Linearization
) -> StageWeights:
    """Cost Hessians only (no ``λ·∇²F``): the quasi-Newton model, barrier terms included."""
    blocks = model.discrete.cost_hessians(
        trajectory.states[:-1], trajectory.inputs, model.problem.parameters
    )
    return _with_barrier_hessians(model, trajectory, linearization, blocks)
