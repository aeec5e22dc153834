"""Records of a PRONTO solve: status, per-iteration history and the result."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from auvplan._typing import FloatArray
from auvplan.optimization.lq import DirectionType
from auvplan.optimization.problem import Trajectory

__all__ = ["ProntoIteration", "ProntoResult", "ProntoStatus"]


class ProntoStatus(enum.Enum):
    """Outcome of :func:`~auvplan.optimization.pronto.solve_pronto`."""

    CONVERGED = "converged"
    MAX_ITER = "max_iter"
    LINE_SEARCH_FAILED = "line_search_failed"
    INFEASIBLE = "infeasible"


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
        Barrier weight of the direction and switching point in force (a probe of the last
        level's test from an earlier level records the last ``ε``, with step 0).
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
    """Result of :func:`~auvplan.optimization.pronto.solve_pronto`.

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
