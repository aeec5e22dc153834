"""Trying a step, Armijo backtracking on ``h(P(ξ + γζ))`` and the stopping test (§5)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from auvplan._typing import FloatArray
from auvplan.optimization.lq import LqDirection
from auvplan.optimization.model import ProntoModel
from auvplan.optimization.problem import Trajectory
from auvplan.optimization.projection import project
from auvplan.optimization.stages import CostParts, evaluate_cost

__all__ = ["ArmijoResult", "StepTrial", "armijo_step", "converged", "try_step"]


@dataclass(frozen=True)
class StepTrial:
    """One trial point ``P(ξ + γζ)`` of the line search (Crocoddyl's ``tryStep``).

    Attributes
    ----------
    trajectory : Trajectory
        The projected candidate (non-finite if the closed loop diverged).
    cost : CostParts
        Its objective parts (``inf`` when non-finite).
    min_slack : float
        Its smallest scaled constraint slack.
    """

    trajectory: Trajectory
    cost: CostParts
    min_slack: float


def try_step(
    model: ProntoModel,
    trajectory: Trajectory,
    direction: tuple[FloatArray, FloatArray],
    gains: FloatArray,
    step: float,
    *,
    epsilon: float,
    delta: float,
) -> StepTrial:
    """Project ``ξ + γζ`` with the fixed regulator and evaluate the objective there.

    Parameters
    ----------
    model : ProntoModel
        Evaluators.
    trajectory : Trajectory
        ``ξ``.
    direction : tuple of ndarray
        ``(z (N + 1, n_x), v (N, n_u))``.
    gains : ndarray of shape (N, n_u, n_x)
        The regulator of the iteration.
    step : float
        ``γ``.
    epsilon, delta : float
        Barrier weight and switching point.

    Returns
    -------
    StepTrial
        ``P(ξ + γζ)``, ``h`` there and its smallest slack.
    """
    z, v = direction
    reference = Trajectory(trajectory.states + step * z, trajectory.inputs + step * v)
    candidate = project(model, reference, gains)
    cost, min_slack = evaluate_cost(model, candidate, epsilon, delta)
    return StepTrial(candidate, cost, min_slack)


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
        trial = try_step(
            model, trajectory, (direction.z, direction.v), gains, step, epsilon=epsilon, delta=delta
        )
        total = trial.cost.total
        feasible_ok = not require_feasible or trial.min_slack > 0.0
        if (
            np.isfinite(total)
            and feasible_ok
            and total <= current_cost + alpha * step * direction.slope
        ):
            return ArmijoResult(
                True,
                trial.trajectory,
                trial.cost,
                trial.min_slack,
                _min_argument(model, trial.min_slack),
                step,
                n_backtracks,
            )
        step *= beta
    return ArmijoResult(
        False, trajectory, CostParts(np.inf, np.inf, np.inf), -np.inf, -np.inf, 0.0, max_backtracks
    )


def converged(decrement: float, cost: float, tol: float, rtol: float) -> bool:
    """Stopping test ``−Dh·ζ < max(tol, rtol |h|)`` (``decrement = −Dh·ζ``, ``cost = h``).

    Examples
    --------
    >>> converged(1e-9, 1.0, 1e-6, 0.0)
    True
    >>> converged(0.5, 1e6, 1e-6, 1e-6)
    True
    """
    return bool(decrement < max(tol, rtol * abs(cost)))
