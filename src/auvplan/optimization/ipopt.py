"""CasADi + IPOPT bridge: the identical discretised problem by direct multiple shooting.

The decision variables are all states ``x_0..x_N`` and inputs ``u_0..u_{N-1}`` on the same
grid; the defects ``F(x_k, u_k, p_k) − x_{k+1} = 0`` use the very same (substepped) RK4 step
Function as PRONTO, the objective the same stage cost ``Σ L_k + m(x_N)`` (see
:mod:`auvplan.optimization.problem`). Path constraints are hard inequalities
``c(x_k, u_k, p_k) / scale ≥ 0``; with ``barrier=(ε, δ)`` the objective also carries the
identical approximate-barrier term ``ε dt Σ b(c / scale)`` so that costs are comparable with
PRONTO at equal ``ε``. IPOPT runs with MUMPS and the exact Hessian of the Lagrangian.
This is the independent reference of the tests and benchmarks.
"""

from __future__ import annotations

import enum
import time
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from auvplan.errors import InputError
from auvplan.optimization.barrier import BarrierKind, barrier_expression
from auvplan.optimization.discretization import discretize_rk4
from auvplan.optimization.problem import Trajectory, TrajectoryProblem

__all__ = ["IpoptResult", "IpoptStatus", "solve_ipopt"]


class IpoptStatus(enum.Enum):
    """Outcome of :func:`solve_ipopt`."""

    SOLVED = "solved"
    ACCEPTABLE = "acceptable"
    MAX_ITER = "max_iter"
    FAILED = "failed"


@dataclass(frozen=True)
class IpoptResult:
    """Result of :func:`solve_ipopt`.

    Attributes
    ----------
    trajectory : Trajectory
        States ``(N+1, n_x)`` and inputs ``(N, n_u)``.
    status : IpoptStatus
        Outcome; ``message`` is IPOPT's return status.
    cost : float
        ``Σ L_k + m(x_N)`` (no barrier).
    barrier_cost : float
        ``ε dt Σ b`` when ``barrier`` was given, else 0.
    n_iter : int
        IPOPT iterations.
    wall_time : float
        Seconds for the whole call (building the NLP included); ``solve_time`` only the solve.
    max_defect : float
        Largest dynamics defect ``|F(x_k, u_k) − x_{k+1}|`` of the returned trajectory.
    """

    trajectory: Trajectory
    status: IpoptStatus
    message: str
    cost: float
    barrier_cost: float
    n_iter: int
    wall_time: float
    solve_time: float
    max_defect: float

    @property
    def success(self) -> bool:
        """True when IPOPT solved the problem (to its tolerance or the acceptable level)."""
        return self.status in (IpoptStatus.SOLVED, IpoptStatus.ACCEPTABLE)

    @property
    def objective(self) -> float:
        """``cost + barrier_cost``."""
        return self.cost + self.barrier_cost


def solve_ipopt(
    problem: TrajectoryProblem,
    guess: Trajectory,
    *,
    barrier: tuple[float, float] | None = None,
    hard_constraints: bool = True,
    tol: float = 1e-10,
    max_iter: int = 3000,
    expand: bool = True,
) -> IpoptResult:
    """Solve the discretised problem with IPOPT (multiple shooting, MUMPS, exact Hessian).

    Parameters
    ----------
    problem : TrajectoryProblem
        The problem (same grid and models as for PRONTO).
    guess : Trajectory
        Initial values of all states and inputs (used as given, not projected).
    barrier : tuple of float, optional
        ``(ε, δ)``: add the approximate-barrier term of every path constraint to the objective.
    hard_constraints : bool
        Impose the path constraints ``c / scale ≥ 0`` as inequalities.
    tol : float
        IPOPT ``tol``.
    max_iter : int
        IPOPT ``max_iter``.
    expand : bool
        Expand the NLP to SX before solving (slow to build for long horizons, fast to
        evaluate); ``False`` keeps CasADi's mapped MX graph (fast to build).

    Returns
    -------
    IpoptResult
        Trajectory, cost, iterations, timings and status.

    Raises
    ------
    InputError
        If the guess has the wrong shape, ``barrier`` is not ``(ε > 0, δ > 0)`` or the
        problem has node costs (not CasADi expressions, so not in the NLP).
    """
    start = time.perf_counter()
    if problem.node_costs:
        raise InputError("the IPOPT reference cannot include node costs (set them to none)")
    n_x, n_u, n_steps = problem.n_states, problem.n_inputs, problem.n_steps
    if guess.states.shape != (n_steps + 1, n_x) or guess.inputs.shape != (n_steps, n_u):
        raise InputError(
            f"guess must have states ({n_steps + 1}, {n_x}) and inputs ({n_steps}, {n_u})"
        )
    if barrier is not None and not (barrier[0] > 0 and barrier[1] > 0):
        raise InputError(f"barrier must be (epsilon > 0, delta > 0), got {barrier!r}")
    model = discretize_rk4(
        problem.dynamics, problem.running_cost, problem.dt, n_substeps=problem.n_substeps
    )
    params = problem.parameters.T
    states = ca.MX.sym("X", n_x, n_steps + 1)
    inputs = ca.MX.sym("U", n_u, n_steps)
    current, following = states[:, :n_steps], states[:, 1:]
    defects = model.step_function.map(n_steps, "serial")(current, inputs, params) - following
    running = ca.sum2(model.cost_function.map(n_steps, "serial")(current, inputs, params))
    terminal = problem.terminal_cost(states[:, n_steps])
    barrier_term: ca.MX = ca.MX(0)
    inequalities: list[ca.MX] = []
    for constraint in problem.constraints:
        slacks = [
            constraint.function.map(n_steps, "serial")(current, inputs, params) / constraint.scale
        ]
        final = np.flatnonzero(constraint.at_final_node).tolist()
        if final:  # the components free of u also hold at x_N (last input and parameters)
            at_end = constraint.function(
                states[:, n_steps], inputs[:, n_steps - 1], params[:, n_steps - 1]
            )
            slacks.append(ca.vertcat(*[at_end[i] for i in final]) / constraint.scale)
        for slack in slacks:
            if hard_constraints:
                inequalities.append(ca.vec(slack))
            if barrier is not None:
                epsilon, delta = barrier
                is_hockey = constraint.kind is BarrierKind.HOCKEY
                values = barrier_expression(slack, delta, is_hockey=is_hockey)
                barrier_term = barrier_term + epsilon * problem.dt * ca.sum1(ca.sum2(values))
    variables = ca.vertcat(ca.vec(states), ca.vec(inputs))
    n_ineq = sum(int(g.numel()) for g in inequalities)
    constraints = ca.vertcat(ca.vec(defects), *inequalities)
    n_eq = n_x * n_steps
    nlp: dict[str, Any] = {"x": variables, "f": running + terminal + barrier_term, "g": constraints}
    options: dict[str, Any] = {
        "expand": expand,
        "print_time": False,
        "ipopt.print_level": 0,
        "ipopt.sb": "yes",
        "ipopt.linear_solver": "mumps",
        "ipopt.hessian_approximation": "exact",
        "ipopt.tol": tol,
        "ipopt.max_iter": max_iter,
    }
    solver = ca.nlpsol("auvplan_ipopt", "ipopt", nlp, options)
    lower = np.full(variables.numel(), -np.inf)
    upper = np.full(variables.numel(), np.inf)
    lower[:n_x] = upper[:n_x] = problem.initial_state
    x_init = np.concatenate([guess.states.ravel(), guess.inputs.ravel()])
    x_init[:n_x] = problem.initial_state
    lbg = np.concatenate([np.zeros(n_eq), np.zeros(n_ineq)])
    ubg = np.concatenate([np.zeros(n_eq), np.full(n_ineq, np.inf)])
    solve_start = time.perf_counter()
    solution = solver(x0=x_init, lbx=lower, ubx=upper, lbg=lbg, ubg=ubg)
    solve_time = time.perf_counter() - solve_start
    stats = solver.stats()
    values = np.asarray(solution["x"].full(), dtype=np.float64).ravel()
    n_state_values = n_x * (n_steps + 1)
    result_states = values[:n_state_values].reshape(n_steps + 1, n_x)
    result_inputs = values[n_state_values:].reshape(n_steps, n_u)
    evaluate = ca.Function("evaluate", [variables], [running + terminal, barrier_term, defects])
    cost, barrier_cost, defect = evaluate(values)
    return_status = str(stats.get("return_status", "unknown"))
    status = {
        "Solve_Succeeded": IpoptStatus.SOLVED,
        "Solved_To_Acceptable_Level": IpoptStatus.ACCEPTABLE,
        "Maximum_Iterations_Exceeded": IpoptStatus.MAX_ITER,
    }.get(return_status, IpoptStatus.FAILED)
    return IpoptResult(
        trajectory=Trajectory(result_states, result_inputs),
        status=status,
        message=return_status,
        cost=float(cost),
        barrier_cost=float(barrier_cost),
        n_iter=int(stats.get("iter_count", -1)),
        wall_time=time.perf_counter() - start,
        solve_time=solve_time,
        max_defect=float(np.max(np.abs(np.asarray(defect.full())))),
    )
