"""The search direction of one PRONTO iteration (Crocoddyl's ``computeDirection``).

Along the current trajectory ``ξ``: linearise, design the projection regulator, integrate the
closed-loop costate, form the Newton weights, and solve the LQ subproblem with the fallback
ladder (``reference/pronto.md`` §6.1–§6.3, §4.2). :func:`compute_direction` is the one
routine that does this, for :func:`~auvplan.optimization.pronto.solve_pronto` and for
:func:`~auvplan.optimization.numdiff.derivative_check`.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass

import numpy as np

from auvplan._typing import FloatArray
from auvplan.optimization.lq import LqDirection, solve_lq_direction
from auvplan.optimization.model import ProntoModel
from auvplan.optimization.options import FallbackModel, ProntoOptions
from auvplan.optimization.problem import Trajectory, TrajectoryProblem
from auvplan.optimization.projection import regulator_gains
from auvplan.optimization.separable import coordinate_groups
from auvplan.optimization.stages import (
    Linearization,
    StageWeights,
    compute_costate,
    linearize,
    quasi_newton_weights,
    second_order_weights,
)

__all__ = [
    "FirstOrder",
    "LocalModel",
    "compute_direction",
    "first_order_model",
    "local_model",
    "predicted_decrement",
    "shift_decrement",
    "steepest_weights",
]

_DEFAULT_OPTIONS = ProntoOptions()


@dataclass(frozen=True)
class FirstOrder:
    """The first-order part of a :class:`LocalModel`, shared by every barrier weight.

    Attributes
    ----------
    trajectory : Trajectory
        The expansion point ``ξ``.
    linearization : Linearization
        ``A, B, a, b, m_x`` and the cost parts at ``ξ`` (at its own ``ε``).
    gains : ndarray of shape (N, n_u, n_x)
        Projection regulator designed along ``ξ`` (it does not depend on ``ε``).
    """

    trajectory: Trajectory
    linearization: Linearization
    gains: FloatArray


@dataclass(frozen=True)
class LocalModel:
    """Second-order model of ``g(ξ) = h(P(ξ))`` at a trajectory (one PRONTO iteration).

    Attributes
    ----------
    trajectory : Trajectory
        The expansion point ``ξ`` (a trajectory of the dynamics).
    linearization : Linearization
        ``A, B, a, b, m_x`` and the cost parts at ``ξ``.
    gains : ndarray of shape (N, n_u, n_x)
        Projection regulator designed along ``ξ`` (kept fixed in the line search).
    costate : ndarray of shape (N + 1, n_x)
        Closed-loop costate ``λ``.
    weights : StageWeights
        Newton weights ``Q, S, R, P_N``.
    """

    trajectory: Trajectory
    linearization: Linearization
    gains: FloatArray
    costate: FloatArray
    weights: StageWeights

    @property
    def first_order(self) -> FirstOrder:
        """Its linearisation and regulator (for the same trajectory at another ``ε``)."""
        return FirstOrder(self.trajectory, self.linearization, self.gains)


def first_order_model(
    model: ProntoModel,
    trajectory: Trajectory,
    epsilon: float,
    delta: float,
    *,
    options: ProntoOptions = _DEFAULT_OPTIONS,
) -> FirstOrder:
    """Linearisation and projection regulator at ``trajectory`` (barrier ``ε``, ``δ``)."""
    lin = linearize(model, trajectory, epsilon, delta)
    return FirstOrder(trajectory, lin, regulator_gains(model, trajectory, lin.A, lin.B, options))


def local_model(
    model: ProntoModel,
    trajectory: Trajectory,
    epsilon: float,
    delta: float,
    *,
    options: ProntoOptions = _DEFAULT_OPTIONS,
    first_order: FirstOrder | None = None,
) -> LocalModel:
    """Linearisation, regulator, costate and Newton weights at ``trajectory``.

    Parameters
    ----------
    model : ProntoModel
        Evaluators.
    trajectory : Trajectory
        Current trajectory ``ξ``.
    epsilon, delta : float
        Barrier weight and switching point (ignored without constraints).
    options : ProntoOptions, optional
        ``terminal_regulator`` is used.
    first_order : FirstOrder, optional
        The linearisation and regulator at ``trajectory`` and ``delta`` for any barrier
        weight (:func:`first_order_model`): shifted to ``epsilon`` exactly
        (:meth:`~auvplan.optimization.stages.Linearization.at_barrier_weight`) instead of
        linearising again.

    Returns
    -------
    LocalModel
        The quadratic model of ``g`` at ``ξ``.
    """
    if first_order is None:
        first_order = first_order_model(model, trajectory, epsilon, delta, options=options)
    elif first_order.trajectory is not trajectory or first_order.linearization.delta != delta:
        raise ValueError("first_order is not at this trajectory and delta")
    lin = first_order.linearization.at_barrier_weight(epsilon)
    costate = compute_costate(lin, first_order.gains)
    weights = second_order_weights(model, trajectory, lin, costate)
    return LocalModel(trajectory, lin, first_order.gains, costate, weights)


def steepest_weights(problem: TrajectoryProblem) -> StageWeights:
    """The last-resort model of the ladder: the regulator weights ``Q_r``, ``R_r`` at every stage.

    The stage arrays are read-only broadcast views (copied only when the ladder uses them).
    """
    n_x, n_u, n_stages = problem.n_states, problem.n_inputs, problem.n_steps
    return StageWeights(
        np.broadcast_to(problem.state_weight, (n_stages, n_x, n_x)),
        np.broadcast_to(np.zeros((n_x, n_u)), (n_stages, n_x, n_u)),
        np.broadcast_to(problem.input_weight, (n_stages, n_u, n_u)),
        problem.state_weight.copy(),
    )


def compute_direction(
    model: ProntoModel,
    trajectory: Trajectory,
    epsilon: float,
    delta: float,
    *,
    options: ProntoOptions = _DEFAULT_OPTIONS,
    first_order: FirstOrder | None = None,
) -> tuple[LocalModel, LqDirection]:
    """The PRONTO search direction at ``trajectory`` and the model it minimises.

    Newton (exact weights) → convexified (eigenvalue-clipped Newton or, with
    ``options.fallback_model == "cost"``, quasi-Newton weights) → steepest (regulator weights).

    Parameters
    ----------
    model, trajectory, epsilon, delta, first_order
        As for :func:`local_model`.
    options : ProntoOptions, optional
        ``terminal_regulator``, ``fallback_model``, ``eigenvalue_floor`` and ``n_threads`` are
        used.

    Returns
    -------
    local : LocalModel
        Linearisation, regulator, costate and Newton weights at ``ξ``.
    direction : LqDirection
        ``ζ = (z, v)``, ``Dh·ζ`` and the ladder level used.

    Raises
    ------
    SolverError
        If no level of the ladder gives a descent direction.
    """
    local = local_model(model, trajectory, epsilon, delta, options=options, first_order=first_order)
    quasi = None
    if options.fallback_model is FallbackModel.COST:
        quasi = functools.partial(quasi_newton_weights, model, trajectory, local.linearization)
    direction = solve_lq_direction(
        local.linearization,
        local.weights,
        quasi_weights=quasi,
        steepest_weights=steepest_weights(model.problem),
        eigenvalue_floor=options.eigenvalue_floor,
        groups=coordinate_groups(model.problem.blocks, model.problem.n_states),
        threads=options.n_threads,
    )
    return local, direction


def predicted_decrement(
    local: LocalModel, direction: LqDirection, epsilon: float
) -> tuple[float, float]:
    """``−Dh·ζ`` and ``h`` at the local model's trajectory for another barrier weight ``ε'``.

    No new Hessian and no factorisation: the gradients and the cost are exact at ``ε'``
    (:meth:`Linearization.at_barrier_weight`); the model is that of ``direction`` (the
    ladder's model of ``local``; :meth:`LqFactor.slope`). Its weights differ from the exact
    ``ε'`` weights by ``(ε' − ε)`` times the barrier's Hessian and by the dynamics' curvature
    weighted with the barrier's part of the costate, both small where the barrier hardly
    pulls on the trajectory, which is when the prediction is used
    (:func:`~auvplan.optimization.pronto.solve_pronto`'s skipping of barrier levels).
    """
    assert direction.factor is not None
    lin = local.linearization.at_barrier_weight(epsilon)
    return -direction.factor.slope(lin), lin.cost.total


def shift_decrement(local: LocalModel, direction: LqDirection, epsilon: float) -> float:
    """The decrement of the gradient's change alone from the model's ``ε`` to ``ε'``.

    ``Δg = (ε'/ε − 1) ∇b`` (``b`` the barrier at ``ε``, :meth:`Linearization.barrier_shift`),
    ``Δgᵀ H⁻¹ Δg`` in the model of ``direction``: what is left at ``ε'`` after a Newton step
    that has zeroed the gradient at ``ε``.
    """
    assert direction.factor is not None
    d_a, d_b, d_m = local.linearization.barrier_shift(epsilon)
    return -direction.factor.slope(dataclasses.replace(local.linearization, a=d_a, b=d_b, m_x=d_m))
