r"""What a plan's cost is made of, and how close it came to each constraint.

The optimiser minimises one number; a user wants to know what it bought. :func:`cost_breakdown`
splits the objective of a solved fleet problem into its named terms
(:data:`~auvplan.mission.fleet.COST_TERMS`), each computed exactly as the optimiser counts it:

* the running terms of every vehicle (``energy``, ``tracking``, ``input``,
  :func:`~auvplan.mission.fleet.vehicle_cost_terms`) by the same RK4 quadrature of the rates
  along the same steps as the discrete stage cost (the quadrature is linear in the rate, so the
  terms add up to the optimiser's running cost);
* ``information``, the reward of the information map, ``dt Σ_{k<N} r(x_k)`` (negative);
* ``terminal``, ``m(x_N)``.

The barrier that keeps the iterates feasible is not an objective term: instead
:func:`constraint_slack` reports, for every labelled constraint row (a pair of vehicles, a
vehicle and an obstacle, a vehicle and a state limit), its smallest value ``min_k c(x_k, u_k,
p_k)`` (feasible when ``>= 0``, in the constraint's own normalised units).
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from auvplan._typing import FloatArray
from auvplan.mission.fleet import (
    RUNNING_TERMS,
    FleetProblemFunctions,
    vehicle_cost_terms,
)
from auvplan.optimization import Trajectory, TrajectoryProblem
from auvplan.optimization.integration import rk4_step


@dataclass(frozen=True)
class CostBreakdown:
    """The objective by term.

    ``running[term]`` ``(n_vehicles,)`` is each vehicle's share of a running term [J]
    (:data:`~auvplan.mission.fleet.RUNNING_TERMS`); ``information`` and ``terminal`` are
    fleet totals [J].
    """

    running: dict[str, FloatArray]
    information: float
    terminal: float

    def totals(self) -> dict[str, float]:
        """Every term's fleet total [J], by name (:data:`~auvplan.mission.fleet.COST_TERMS`)."""
        totals = {term: float(np.sum(values)) for term, values in self.running.items()}
        return {**totals, "information": self.information, "terminal": self.terminal}

    @property
    def total(self) -> float:
        """The objective without the barrier [J]."""
        return sum(self.totals().values())


def cost_breakdown(
    problem: TrajectoryProblem, functions: FleetProblemFunctions, trajectory: Trajectory
) -> CostBreakdown:
    """Split the objective of ``problem`` at ``trajectory`` into its named terms (module notes)."""
    states, inputs = trajectory.states, trajectory.inputs
    n_steps = inputs.shape[0]
    parameters = _stage_parameters(problem, n_steps)
    running = np.zeros((len(RUNNING_TERMS), len(functions.blocks)))
    for i, (block, model) in enumerate(zip(functions.blocks, functions.layout.models, strict=True)):
        has_current = block.parameters.stop - block.parameters.start > model.n_x
        terms = vehicle_cost_terms(model, has_current=has_current)
        x = ca.SX.sym("x", model.n_x)
        c = ca.SX.sym("c", model.n_u)
        p = ca.SX.sym("p", block.parameters.stop - block.parameters.start)
        rates = ca.Function("rates", [x, c, p], [terms(x, c, p, block.weights)])
        _, quadrature = rk4_step(block.dynamics, rates, x, c, p, problem.dt, problem.n_substeps)
        per_step = ca.Function("terms", [x, c, p], [quadrature]).map(n_steps, "serial")
        values = per_step(
            states[:-1, block.states].T,
            inputs[:, block.inputs].T,
            parameters[:, block.parameters].T,
        )
        running[:, i] = np.asarray(values).sum(axis=1)
    information = sum(
        problem.dt * float(np.sum(node.values(states[:-1]))) for node in problem.node_costs
    )
    terminal = float(functions.terminal_cost(states[-1]))
    return CostBreakdown(
        running=dict(zip(RUNNING_TERMS, running, strict=True)),
        information=information,
        terminal=terminal,
    )


def constraint_slack(
    problem: TrajectoryProblem, functions: FleetProblemFunctions, trajectory: Trajectory
) -> dict[str, dict[str, float]]:
    """The smallest value of every constraint row along ``trajectory``, by block and label.

    ``slack[block][label]`` with ``block`` a constraint name (``"collision"``, ``"obstacle"``,
    ``"communication"``, ``"corridor"``, ``"state_limits"``) and ``label`` the row's pair
    (``"a / b"``); feasible when ``>= 0``.
    """
    states, inputs = trajectory.states, trajectory.inputs
    n_steps = inputs.shape[0]
    parameters = _stage_parameters(problem, n_steps)
    slack: dict[str, dict[str, float]] = {}
    for constraint in functions.constraints:
        values = np.asarray(
            constraint.function.map(n_steps, "serial")(states[:-1].T, inputs.T, parameters.T)
        )
        slack[constraint.name] = {
            str(label): float(row.min())
            for label, row in zip(constraint.labels, values, strict=True)
        }
    return slack


def _stage_parameters(problem: TrajectoryProblem, n_steps: int) -> FloatArray:
    """The problem's stage parameters ``(n_steps, n_p)`` (no columns when it has none)."""
    if problem.stage_parameters is None:
        return np.zeros((n_steps, 0))
    return problem.stage_parameters


__all__ = ["CostBreakdown", "constraint_slack", "cost_breakdown"]
