"""Model building: a :class:`TrajectoryProblem` turned into batched evaluators.

:func:`build_model` discretises the problem (RK4 map and stage cost, constraints, terminal
cost). Building costs CasADi graph construction and common-subexpression elimination (up to
seconds for vehicle fleets), so a caller that solves the same problem repeatedly keeps the
models in an explicit :class:`ModelCache` and passes it to the solver.
"""

from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass, field

import numpy as np

from auvplan._typing import BoolArray, FloatArray
from auvplan.optimization._numba_codegen import UnsupportedOperation
from auvplan.optimization.barrier import BarrierKind
from auvplan.optimization.constraints import ConstraintModel, discretize_constraints
from auvplan.optimization.discretization import StepModel, discretize_rk4
from auvplan.optimization.options import StageBackend
from auvplan.optimization.problem import TrajectoryProblem
from auvplan.optimization.separable import BlockDiscreteModel
from auvplan.optimization.terminal import TerminalCost, make_terminal_cost

__all__ = ["ModelCache", "ProntoModel", "build_model"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True, eq=False)
class ProntoModel:
    """Compiled, batched evaluators of a :class:`TrajectoryProblem` (see :func:`build_model`).

    Attributes
    ----------
    problem : TrajectoryProblem
        The problem.
    discrete : StepModel
        Step ``F`` and stage cost ``L`` with their derivatives (CasADi or block kernels).
    terminal : TerminalCost
        ``m(x_N)`` with its derivatives.
    constraints : ConstraintModel or None
        All path constraints stacked (``None`` without constraints).
    slack_scales : ndarray of shape (n_c,)
        Scale of every constraint component (the barrier sees ``c / scale``).
    is_hockey : ndarray of shape (n_c,)
        Whether each component's barrier is composed with the hockey stick.
    at_final_node : ndarray of shape (n_c,)
        Whether each component is also imposed at the final node ``x_N``
        (:attr:`PathConstraint.at_final_node`).
    """

    problem: TrajectoryProblem
    discrete: StepModel
    terminal: TerminalCost
    constraints: ConstraintModel | None
    slack_scales: FloatArray
    is_hockey: BoolArray
    at_final_node: BoolArray

    @property
    def has_constraints(self) -> bool:
        """True when there is at least one constraint component."""
        return self.constraints is not None and self.constraints.n_c > 0


def _discrete_model(problem: TrajectoryProblem, backend: StageBackend) -> StepModel:
    """The step's evaluator: block kernels when possible, else the stacked CasADi functions."""
    if problem.blocks and backend.stage_kernels:
        sizes = (problem.n_states, problem.n_inputs, problem.n_parameters)
        try:
            return BlockDiscreteModel.build(
                problem.blocks, sizes, problem.dt, problem.n_substeps, threads=backend.n_threads
            )
        except UnsupportedOperation as error:
            logger.warning("stage kernels unavailable (%s): evaluating with CasADi", error)
    return discretize_rk4(
        problem.dynamics,
        problem.running_cost,
        problem.dt,
        n_substeps=problem.n_substeps,
        parallelization="thread" if backend.n_threads > 1 else "serial",
        n_threads=backend.n_threads,
        compile_c=backend.compile_c,
    )


def build_model(problem: TrajectoryProblem, backend: StageBackend | None = None) -> ProntoModel:
    """Discretise a problem (RK4 map, stage cost, constraints, terminal cost).

    Parameters
    ----------
    problem : TrajectoryProblem
        The problem.
    backend : StageBackend, optional
        How to evaluate the step (default: kernels for separable problems, else CasADi).

    Returns
    -------
    ProntoModel
        Batched evaluators (built anew; see :class:`ModelCache` to reuse them).
    """
    discrete = _discrete_model(problem, StageBackend() if backend is None else backend)
    terminal = make_terminal_cost(problem.terminal_cost, problem.n_states)
    constraints = None
    scales: list[float] = []
    hockey: list[bool] = []
    final: list[BoolArray] = []
    if problem.constraints:
        constraints = discretize_constraints(
            tuple(c.function for c in problem.constraints),
            problem.n_states,
            problem.n_inputs,
            problem.n_parameters,
        )
        for constraint in problem.constraints:
            scales += [constraint.scale] * constraint.n_components
            hockey += [constraint.kind is BarrierKind.HOCKEY] * constraint.n_components
            final.append(constraint.at_final_node)
    return ProntoModel(
        problem=problem,
        discrete=discrete,
        terminal=terminal,
        constraints=constraints,
        slack_scales=np.asarray(scales, dtype=np.float64),
        is_hockey=np.asarray(hockey, dtype=np.bool_),
        at_final_node=np.concatenate(final) if final else np.zeros(0, dtype=np.bool_),
    )


@dataclass(eq=False)
class ModelCache:
    """Models built for given problems, reused while the cache object lives.

    Entries are matched by the identity of the problem object (problems are immutable) and
    the build options; the cache holds a reference to each problem, so an identity is never
    reused while its entry exists. At most ``max_entries`` models are kept (the least recently
    used evicted).

    Examples
    --------
    >>> import casadi as ca, numpy as np
    >>> x, u, p = ca.SX.sym("x"), ca.SX.sym("u"), ca.SX.sym("p", 0)
    >>> problem = TrajectoryProblem(
    ...     ca.Function("f", [x, u, p], [u]), ca.Function("l", [x, u, p], [u**2]),
    ...     ca.Function("m", [x], [x**2]), np.zeros(1), 0.1, 10)
    >>> cache = ModelCache()
    >>> cache.get(problem) is cache.get(problem)
    True
    """

    max_entries: int = 16
    _entries: list[tuple[TrajectoryProblem, StageBackend, ProntoModel]] = field(
        default_factory=list, repr=False
    )

    def get(self, problem: TrajectoryProblem, backend: StageBackend | None = None) -> ProntoModel:
        """The model of ``problem`` for this backend, built by :func:`build_model` if new."""
        backend = StageBackend() if backend is None else backend
        for index, (cached, cached_backend, model) in enumerate(self._entries):
            if cached is problem and cached_backend == backend:
                self._entries.append(self._entries.pop(index))
                return model
        model = build_model(problem, backend)
        self._entries.append((problem, backend, model))
        del self._entries[: -self.max_entries]
        return model

    def rebind(
        self,
        problem: TrajectoryProblem,
        *,
        initial_state: FloatArray,
        stage_parameters: FloatArray,
        backend: StageBackend | None = None,
    ) -> TrajectoryProblem:
        """``problem`` with another initial state and stage parameters, sharing its model.

        The evaluators depend on the functions, the grid and the sizes, not on these values:
        the copy is entered with ``problem``'s model (built if new), so a problem solved
        again and again with new parameters is built once.
        """
        backend = StageBackend() if backend is None else backend
        model = self.get(problem, backend)
        copy = dataclasses.replace(
            problem, initial_state=initial_state, stage_parameters=stage_parameters
        )
        self._entries.append((copy, backend, dataclasses.replace(model, problem=copy)))
        del self._entries[: -self.max_entries]
        return copy
