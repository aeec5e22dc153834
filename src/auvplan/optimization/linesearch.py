"""Armijo backtracking on ``h(P(ξ + γζ))`` and the stopping test (``reference/pronto.md`` §5)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from auvplan._typing import FloatArray
from auvplan.optimization.lq import LqDirection
from auvplan.optimization.problem import Trajectory
from auvplan.optimization.stages import CostParts, ProntoModel, evaluate_cost, project

__all__ = ["ArmijoResult", "armijo_step", "converged"]


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
