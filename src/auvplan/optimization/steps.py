"""The search direction of one PRONTO iteration (Crocoddyl's ``computeDirection``).

Along the current trajectory ``ξ``: linearise, design the projection regulator, integrate the
closed-loop costate, form the Newton weights, and solve the LQ subproblem with the fallback
ladder (``reference/pronto.md`` §6.1–§6.3, §4.2). :func:`compute_direction` is the one
routine that does this, for :func:`~auvplan.optimization.pronto.solve_pronto` and for
:func:`~auvplan.optimization.numdiff.derivative_check`.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import SolverError
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
    "LocalModel",
    "compute_direction",
    "local_model",
    "predicted_decrement",
    "steepest_weights",
]

_DEFAULT_OPTIONS = ProntoOptions()


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


def local_model(
    model: ProntoModel,
    trajectory: Trajectory,
    epsilon: float,
    delta: float,
    *,
    options: ProntoOptions = _DEFAULT_OPTIONS,
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

    Returns
    -------
    LocalModel
        The quadratic model of ``g`` at ``ξ``.
    """
    lin = linearize(model, trajectory, epsilon, delta)
    gains = regulator_gains(model, trajectory, lin.A, lin.B, options)
    costate = compute_costate(lin, gains)
    weights = second_order_weights(model, trajectory, lin, costate)
    return LocalModel(trajectory, lin, gains, costate, weights)


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
) -> tuple[LocalModel, LqDirection]:
    """The PRONTO search direction at ``trajectory`` and the model it minimises.

    Newton (exact weights) → convexified (eigenvalue-clipped Newton or, with
    ``options.fallback_model == "cost"``, quasi-Newton weights) → steepest (regulator weights).

    Parameters
    ----------
    model, trajectory, epsilon, delta
        As for :func:`local_model`.
    options : ProntoOptions, optional
        ``terminal_regulator``, ``fallback_model`` and ``eigenvalue_floor`` are used.

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
    local = local_model(model, trajectory, epsilon, delta, options=options)
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
    )
    return local, direction


def predicted_decrement(
    model: ProntoModel,
    local: LocalModel,
    epsilon: float,
    *,
    options: ProntoOptions = _DEFAULT_OPTIONS,
) -> tuple[float, float]:
    """``−Dh·ζ`` and ``h`` at the local model's trajectory for another barrier weight ``ε'``.

    One LQ solve, no new Hessian: the gradients and the cost are exact at ``ε'``
    (:meth:`Linearization.at_barrier_weight`); the weights stay those of ``local``. They
    differ from the exact ``ε'`` weights by ``(ε' − ε)`` times the barrier's Hessian and by
    the dynamics' curvature weighted with the barrier's part of the costate, both small
    where the barrier hardly pulls on the trajectory, which is when the prediction is
    used (:func:`~auvplan.optimization.pronto.solve_pronto`'s skipping of barrier levels).
    ``inf`` when no model of the ladder gives a descent direction.
    """
    lin = local.linearization.at_barrier_weight(epsilon)
    try:
        direction = solve_lq_direction(
            lin,
            local.weights,
            eigenvalue_floor=options.eigenvalue_floor,
            groups=coordinate_groups(model.problem.blocks, model.problem.n_states),
        )
    except SolverError:
        return float("inf"), lin.cost.total
    return -direction.slope, lin.cost.total
