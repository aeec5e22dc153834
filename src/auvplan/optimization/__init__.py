"""Trajectory optimisation: discrete-time PRONTO with approximate-barrier constraints.

Build a :class:`TrajectoryProblem` from CasADi Functions (continuous dynamics, running-cost
rate, terminal cost, path constraints ``c >= 0``) and call :func:`solve_pronto`;
:func:`solve_ipopt` and :func:`solve_fatrop` solve the identical discretised problem with CasADi
+ IPOPT and CasADi + FATROP.
The algorithm is documented in ``reference/pronto.md`` (§6, §7, §11).

Modules, in the order of the data flow:

- ``problem``: the problem and trajectory types; ``options``: solver options;
- ``integration``, ``discretization``, ``constraints``, ``terminal``: batched CasADi evaluators
  of the discrete map, the stage cost, the path constraints and the terminal cost;
- ``separable``, ``block_kernels``: separable problems (one block per vehicle) evaluated with
  compiled model kernels stepped by RK4, built once per model and cached on disk;
- ``model``: :func:`build_model` and the explicit :class:`ModelCache`;
- ``stages``: cost, linearisation, costate and Newton weights along a trajectory;
- ``projection``: regulator design and the projection operator;
- ``lq``: the LQ direction and its fallback ladder; ``steps``: :func:`compute_direction`;
- ``linesearch``: :func:`try_step`, :func:`armijo_step`, :func:`converged`;
- ``pronto``: :func:`solve_pronto`; ``result``: its records; ``numdiff``: derivative check;
- ``reference``: the CasADi + IPOPT and CasADi + FATROP references.
"""

from __future__ import annotations

from auvplan import _numba_cache  # noqa: F401 (damaged numba cache files heal: first)
from auvplan.optimization.barrier import (
    BarrierKind,
    barrier_expression,
    composed_barrier,
    hockey_stick,
    log_barrier,
)
from auvplan.optimization.block_kernels import BlockKernels, block_kernels
from auvplan.optimization.constraints import ConstraintModel, discretize_constraints
from auvplan.optimization.discretization import DiscreteModel, StepModel, discretize_rk4
from auvplan.optimization.integration import choose_substeps
from auvplan.optimization.linesearch import (
    ArmijoResult,
    StepTrial,
    armijo_step,
    converged,
    try_step,
)
from auvplan.optimization.lq import DirectionType, LqDirection, convexify, solve_lq_direction
from auvplan.optimization.model import ModelCache, ProntoModel, build_model
from auvplan.optimization.numdiff import DerivativeCheck, derivative_check
from auvplan.optimization.options import (
    FallbackModel,
    ProntoOptions,
    StageBackend,
    TerminalRegulator,
)
from auvplan.optimization.problem import NodeCost, PathConstraint, Trajectory, TrajectoryProblem
from auvplan.optimization.projection import design_regulator, project, project_guess
from auvplan.optimization.pronto import solve_pronto
from auvplan.optimization.reference import IpoptResult, IpoptStatus, solve_fatrop, solve_ipopt
from auvplan.optimization.result import ProntoIteration, ProntoResult, ProntoStatus
from auvplan.optimization.separable import BlockDiscreteModel, StageBlock, stack_blocks
from auvplan.optimization.stages import (
    CostParts,
    Linearization,
    StageWeights,
    compute_costate,
    evaluate_cost,
    linearize,
    second_order_weights,
)
from auvplan.optimization.steps import LocalModel, compute_direction
from auvplan.optimization.terminal import TerminalCost, make_terminal_cost

__all__ = [
    "ArmijoResult",
    "BarrierKind",
    "BlockDiscreteModel",
    "BlockKernels",
    "ConstraintModel",
    "CostParts",
    "DerivativeCheck",
    "DirectionType",
    "DiscreteModel",
    "FallbackModel",
    "IpoptResult",
    "IpoptStatus",
    "Linearization",
    "LocalModel",
    "LqDirection",
    "ModelCache",
    "NodeCost",
    "PathConstraint",
    "ProntoIteration",
    "ProntoModel",
    "ProntoOptions",
    "ProntoResult",
    "ProntoStatus",
    "StageBackend",
    "StageBlock",
    "StageWeights",
    "StepModel",
    "StepTrial",
    "TerminalCost",
    "TerminalRegulator",
    "Trajectory",
    "TrajectoryProblem",
    "armijo_step",
    "barrier_expression",
    "block_kernels",
    "build_model",
    "choose_substeps",
    "composed_barrier",
    "compute_costate",
    "compute_direction",
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
    "solve_fatrop",
    "solve_ipopt",
    "solve_lq_direction",
    "solve_pronto",
    "stack_blocks",
    "try_step",
]
