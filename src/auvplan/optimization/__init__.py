"""Trajectory optimisation: discrete-time PRONTO with approximate-barrier constraints.

The public names are listed in ``__all__``; see ``reference/pronto.md`` for the algorithm.
"""

from __future__ import annotations

from auvplan.optimization.discretization import (
    ConstraintModel,
    DiscreteModel,
    TerminalCost,
    discretize_constraints,
    discretize_rk4,
    make_terminal_cost,
)

__all__ = [
    "ConstraintModel",
    "DiscreteModel",
    "TerminalCost",
    "discretize_constraints",
    "discretize_rk4",
    "make_terminal_cost",
]
