"""Trajectory optimisation: discrete-time PRONTO with approximate-barrier constraints.

Build a :class:`TrajectoryProblem` from CasADi Functions (continuous dynamics, running-cost
rate, terminal cost, path constraints ``c >= 0``) and call :func:`solve_pronto`;
:func:`solve_ipopt` solves the identical discretised problem with CasADi + IPOPT.
The algorithm is documented in ``reference/pronto.md`` (§6, §7, §11).
"""

from __future__ import annotations

from auvplan.optimization.barrier import (
    barrier_expression,
    composed_barrier,
    hockey_stick,
    log_barrier,
)
from auvplan.optimization.discretization import (
    ConstraintModel,
    DiscreteModel,
    TerminalCost,
    discretize_constraints,
    discretize_rk4,
    make_terminal_cost,
)
from auvplan.optimization.ipopt import IpoptResult, IpoptStatus, solve_ipopt
from auvplan.optimization.linesearch import ArmijoResult, armijo_step, converged
from auvplan.optimization.lq import DirectionType, LqDirection, convexify, solve_lq_direction
from auvplan.optimization.problem import PathConstraint, Trajectory, TrajectoryProblem
from auvplan.optimization.pronto import (
    DerivativeCheck,
    ProntoIteration,
    ProntoOptions,
    ProntoResult,
    ProntoStatus,
    derivative_check,
    project_guess,
    solve_pronto,
)
from auvplan.optimization.stages import (
    CostParts,
    Linearization,
    ProntoModel,
    StageWeights,
    build_model,
    compute_costate,
    design_regulator,
    evaluate_cost,
    linearize,
    project,
    second_order_weights,
)

__all__ = [
    "ArmijoResult",
    "ConstraintModel",
    "CostParts",
    "DerivativeCheck",
    "DirectionType",
    "DiscreteModel",
    "IpoptResult",
    "IpoptStatus",
    "Linearization",
    "LqDirection",
    "PathConstraint",
    "ProntoIteration",
    "ProntoModel",
    "ProntoOptions",
    "ProntoResult",
    "ProntoStatus",
    "StageWeights",
    "TerminalCost",
    "Trajectory",
    "TrajectoryProblem",
    "armijo_step",
    "barrier_expression",
    "build_model",
    "composed_barrier",
    "compute_costate",
    "converged",
    "convexify",
    "derivative_check",
    "design_regulator",
    "discretize_constraints",
    "discretize_rk4",
    "evaluate_cost",
    "hockey_stick",
    "linearize",
    "log_barrier",
    "make_terminal_cost",
    "project",
    "project_guess",
    "second_order_weights",
    "solve_ipopt",
    "solve_lq_direction",
    "solve_pronto",
]
