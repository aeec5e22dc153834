"""CasADi reference solvers: IPOPT and FATROP on the identical discretised problem.

The decision variables are all states ``x_0..x_N`` and inputs ``u_0..u_{N-1}`` on the same
grid, ordered stage by stage ``(x_0, u_0, x_1, u_1, …, x_N)``; the defects
``x_{k+1} − F(x_k, u_k, p_k) = 0`` (FATROP's sign) use the very same (substepped) RK4 step
Function as PRONTO, the objective the same stage cost ``Σ L_k + m(x_N)`` (see
:mod:`auvplan.optimization.problem`).
Path constraints are hard inequalities ``c(x_k, u_k, p_k) / scale ≥ 0``; with
``barrier=(ε, δ)`` the objective also carries the identical approximate-barrier term
``ε dt Σ b(c / scale)`` so that costs are comparable with PRONTO at equal ``ε``. The
constraint rows are ordered stage by stage too, each stage's defect first and then its path
constraints, which is the layout FATROP's structure detection reads (a row of stage ``k``
depends on ``x_k, u_k`` and ``x_{k+1}`` only).

- :func:`solve_ipopt`: IPOPT with MUMPS and the exact Hessian of the Lagrangian, the
  independent reference of the tests and benchmarks.
- :func:`solve_fatrop`: FATROP (Vanroye et al., IROS 2023), the structure-exploiting interior
  point method shipped in CasADi's wheel: a Riccati recursion over the stages, the same
  exact Hessian.

Every stage ``k < N`` is one call of a single stage Function
``(x_k, u_k, p_k) -> (F(x_k, u_k, p_k), L(x_k, u_k, p_k), c(x_k, u_k, p_k) / scale)``
(the step, the stage cost and all path constraints stacked; ``p`` is not differentiated),
mapped over the ``N`` stages, so the NLP's expression graph holds one mapped call and its
derivatives whatever ``N``. Either solver optionally compiles it, as a user would run it for
speed (``compiled=True``): the stage Function and the two derivatives CasADi's AD of the
mapped graph asks of it are generated into one C file, compiled with the system compiler
(``gcc -O1``, cached by content hash:
:func:`~auvplan.optimization._compile.compile_functions`; without a working compiler the
stage Function stays on CasADi's virtual machine) and loaded with ``casadi.external``, which
finds them by name: the Jacobian ``jac_<stage>`` (the constraint Jacobian's blocks
``∂(F, L, c)/∂(x, u)``) and, of its adjoint ``adj1_<stage>`` (``λᵀ∂(F, L, c)/∂(x, u)``),
the Jacobian ``jac_adj1_<stage>``, which holds the stage block of the Hessian of the
Lagrangian ``∇²_{(x,u)} (σ L + λ_Fᵀ F + λ_cᵀ c)``. The ``N`` stages then cost ``N``
compiled calls per evaluation; nothing of size ``N`` is compiled.
"""

from __future__ import annotations

import enum
import time
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from auvplan.errors import InputError
from auvplan.optimization._compile import compile_functions
from auvplan.optimization.barrier import BarrierKind, barrier_expression
from auvplan.optimization.discretization import DiscreteModel, discretize_rk4
from auvplan.optimization.problem import Trajectory, TrajectoryProblem

__all__ = ["IpoptResult", "IpoptStatus", "solve_fatrop", "solve_ipopt"]


class IpoptStatus(enum.Enum):
    """Outcome of :func:`solve_ipopt` or :func:`solve_fatrop`."""

    SOLVED = "solved"
    ACCEPTABLE = "acceptable"
    MAX_ITER = "max_iter"
    FAILED = "failed"


@dataclass(frozen=True)
class IpoptResult:
    """Result of :func:`solve_ipopt` or :func:`solve_fatrop` (the name is IPOPT's, the first).

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
        Seconds for the whole call (building the NLP included); ``solve_time`` only the solve
        (for FATROP with ``compiled=True`` the C compilation is ``wall_time − solve_time``).
    max_defect : float
        Largest dynamics defect ``|x_{k+1} − F(x_k, u_k)|`` of the returned trajectory.
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
    compiled: bool = False,
    repeats: int = 1,
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
    compiled : bool
        Compile the stage Function and its derivatives to C (module notes; cached on disk)
        and keep the NLP mapped (``expand`` is then ignored).
    repeats : int
        Solve this many times from the same start (the same iterations each time) and report
        the fastest as ``solve_time``: a benchmark's solve alone on a machine whose speed
        varies from second to second.

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
    options: dict[str, Any] = {
        "expand": expand and not compiled,
        "ipopt.print_level": 0,
        "ipopt.sb": "yes",
        "ipopt.linear_solver": "mumps",
        "ipopt.hessian_approximation": "exact",
        "ipopt.tol": tol,
        "ipopt.max_iter": max_iter,
    }
    return _solve(
        problem, guess, "ipopt", options, barrier, hard_constraints, compiled=compiled,
        repeats=repeats,
    )  # fmt: skip


def solve_fatrop(
    problem: TrajectoryProblem,
    guess: Trajectory,
    *,
    barrier: tuple[float, float] | None = None,
    hard_constraints: bool = True,
    tol: float = 1e-8,
    max_iter: int = 3000,
    expand: bool = True,
    compiled: bool = False,
    repeats: int = 1,
) -> IpoptResult:
    """Solve the discretised problem with FATROP (module notes), as :func:`solve_ipopt`.

    FATROP detects the NLP's stage structure (``structure_detection = "auto"``, the rows'
    ``equality`` flags); its objective is scaled as IPOPT's gradient-based scaling scales it
    (:func:`_objective_scale`), which FATROP does not do itself. ``tol`` is FATROP's ``tol``
    (on the scaled problem); ``expand``, ``compiled`` and ``repeats`` as for
    :func:`solve_ipopt` (an expanded NLP of thousands of stacked-fleet stages takes more than
    10 GB to build: keep it mapped there). Parameters, returns and errors otherwise as for
    :func:`solve_ipopt`.
    """
    options: dict[str, Any] = {
        "expand": expand and not compiled,
        "structure_detection": "auto",
        "debug": False,
        "fatrop.print_level": 0,
        "fatrop.tol": tol,
        "fatrop.max_iter": max_iter,
    }
    return _solve(
        problem, guess, "fatrop", options, barrier, hard_constraints, compiled=compiled,
        repeats=repeats,
    )  # fmt: skip


#: IPOPT's return statuses by name (FATROP reports a number and ``success``).
_STATUSES: dict[str, IpoptStatus] = {
    "Solve_Succeeded": IpoptStatus.SOLVED,
    "Solved_To_Acceptable_Level": IpoptStatus.ACCEPTABLE,
    "Maximum_Iterations_Exceeded": IpoptStatus.MAX_ITER,
}


def _solve(
    problem: TrajectoryProblem,
    guess: Trajectory,
    plugin: str,
    options: dict[str, Any],
    barrier: tuple[float, float] | None,
    hard_constraints: bool,
    *,
    compiled: bool,
    repeats: int = 1,
) -> IpoptResult:
    """Build the stage-ordered NLP (module notes) and solve it with CasADi's ``plugin``.

    ``repeats`` solves from the same start; ``solve_time`` is the fastest.
    """
    start = time.perf_counter()
    if problem.node_costs:
        raise InputError("the CasADi reference cannot include node costs (set them to none)")
    n_x, n_u, n_steps = problem.n_states, problem.n_inputs, problem.n_steps
    if guess.states.shape != (n_steps + 1, n_x) or guess.inputs.shape != (n_steps, n_u):
        raise InputError(
            f"guess must have states ({n_steps + 1}, {n_x}) and inputs ({n_steps}, {n_u})"
        )
    if barrier is not None and not (barrier[0] > 0 and barrier[1] > 0):
        raise InputError(f"barrier must be (epsilon > 0, delta > 0), got {barrier!r}")
    if repeats < 1:
        raise InputError(f"repeats must be at least 1, got {repeats!r}")
    model = discretize_rk4(
        problem.dynamics, problem.running_cost, problem.dt, n_substeps=problem.n_substeps
    )
    stage = _stage_function(problem, model)
    if compiled:
        stage = compile_functions(_with_derivatives(stage))["stage"]
    params = problem.parameters.T
    state_symbols = [ca.MX.sym(f"x{k}", n_x) for k in range(n_steps + 1)]
    input_symbols = [ca.MX.sym(f"u{k}", n_u) for k in range(n_steps)]
    states, inputs = ca.horzcat(*state_symbols), ca.horzcat(*input_symbols)
    current, following = states[:, :n_steps], states[:, 1:]
    next_states, stage_costs, all_slacks = stage.map(n_steps, "serial")(current, inputs, params)
    defects = following - next_states
    running = ca.sum2(stage_costs)
    terminal = problem.terminal_cost(states[:, n_steps])
    barrier_term: ca.MX = ca.MX(0)
    stage_rows: list[ca.MX] = [defects]  # (rows, N): column k holds stage k's rows
    final_rows: list[ca.MX] = []
    first_row = 0
    for constraint in problem.constraints:
        n_rows_i = int(constraint.function.size1_out(0))
        slacks = [all_slacks[first_row : first_row + n_rows_i, :]]
        first_row += n_rows_i
        final = np.flatnonzero(constraint.at_final_node).tolist()
        if final:  # the components free of u also hold at x_N (last input and parameters)
            at_end = constraint.function(
                states[:, n_steps], inputs[:, n_steps - 1], params[:, n_steps - 1]
            )
            slacks.append(ca.vertcat(*[at_end[i] for i in final]) / constraint.scale)
        if hard_constraints:
            stage_rows.append(slacks[0])
            final_rows.extend(slacks[1:])
        if barrier is not None:
            epsilon, delta = barrier
            is_hockey = constraint.kind is BarrierKind.HOCKEY
            for rows in slacks:
                terms = barrier_expression(rows, delta, is_hockey=is_hockey)
                barrier_term = barrier_term + epsilon * problem.dt * ca.sum1(ca.sum2(terms))
    stacked = ca.vertcat(*stage_rows)
    n_rows = stacked.size1()
    equality = np.zeros((n_rows, n_steps), dtype=bool)
    equality[:n_x] = True
    n_final = sum(int(g.numel()) for g in final_rows)
    constraints = ca.vertcat(ca.vec(stacked), *final_rows)
    equality_flags = np.concatenate([equality.ravel(order="F"), np.zeros(n_final, dtype=bool)])
    variables = ca.vertcat(
        *[v for k in range(n_steps) for v in (state_symbols[k], input_symbols[k])],
        state_symbols[n_steps],
    )
    x_init = np.concatenate(
        [np.hstack([guess.states[:-1], guess.inputs]).ravel(), guess.states[-1]]
    )
    x_init[:n_x] = problem.initial_state
    objective = running + terminal + barrier_term
    settings = {"print_time": False, **options}
    if plugin == "fatrop":
        settings["equality"] = equality_flags.tolist()
        objective = _objective_scale(objective, variables, x_init) * objective
    nlp: dict[str, Any] = {"x": variables, "f": objective, "g": constraints}
    solver = ca.nlpsol(f"auvplan_{plugin}", plugin, nlp, settings)
    lower = np.full(variables.numel(), -np.inf)
    upper = np.full(variables.numel(), np.inf)
    lower[:n_x] = upper[:n_x] = problem.initial_state
    lbg = np.zeros(constraints.numel())
    ubg = np.where(equality_flags, 0.0, np.inf)
    solve_time = np.inf
    for _ in range(repeats):
        solve_start = time.perf_counter()
        solution = solver(x0=x_init, lbx=lower, ubx=upper, lbg=lbg, ubg=ubg)
        solve_time = min(solve_time, time.perf_counter() - solve_start)
    stats = solver.stats()
    values = np.asarray(solution["x"].full(), dtype=np.float64).ravel()
    staged = values[: n_steps * (n_x + n_u)].reshape(n_steps, n_x + n_u)
    result_states = np.vstack([staged[:, :n_x], values[None, n_steps * (n_x + n_u) :]])
    result_inputs = staged[:, n_x:]
    evaluate = ca.Function("evaluate", [variables], [running + terminal, barrier_term, defects])
    cost, barrier_cost, defect = evaluate(values)
    return_status = str(stats.get("return_status", "unknown"))
    return IpoptResult(
        trajectory=Trajectory(result_states, result_inputs),
        status=_STATUSES.get(
            return_status, IpoptStatus.SOLVED if stats.get("success") else IpoptStatus.FAILED
        ),
        message=return_status,
        cost=float(cost),
        barrier_cost=float(barrier_cost),
        n_iter=int(stats.get("iter_count", -1)),
        wall_time=time.perf_counter() - start,
        solve_time=solve_time,
        max_defect=float(np.max(np.abs(np.asarray(defect.full())))),
    )


#: IPOPT's ``nlp_scaling_max_gradient``: the largest objective gradient left unscaled.
_MAX_GRADIENT = 100.0


def _objective_scale(objective: ca.MX, variables: ca.MX, start: np.ndarray) -> float:
    """IPOPT's gradient-based objective scaling ``σ_f = min(1, 100 / ‖∇f(w_0)‖_∞)``.

    FATROP scales nothing itself. From PRONTO's projected start on the energy-only crossing
    the objective's largest gradient component is 526 (``σ_f`` = 0.19): unscaled, FATROP's
    first step leaves the feasible start for good (no convergence in 300 iterations); scaled,
    it converges in 11 iterations to IPOPT's optimum. Scaling the objective leaves the
    optimum unchanged.
    """
    gradient = ca.Function("gradient", [variables], [ca.gradient(objective, variables)])
    largest = float(np.max(np.abs(np.asarray(gradient(start).full())), initial=0.0))
    return min(1.0, _MAX_GRADIENT / largest) if largest > 0 else 1.0


def _stage_function(problem: TrajectoryProblem, model: DiscreteModel) -> ca.Function:
    """``(x, u, p) -> (x_next, l, slacks)`` of one stage: ``F``, ``L`` and every ``c / scale``.

    ``slacks`` stacks the path constraints' rows in the order of ``problem.constraints``.
    The stage parameter ``p`` is declared not differentiable (``is_diff_in``): the NLP
    holds it fixed, so no derivative with respect to it is built or compiled.
    """
    functions = model.functions
    x, u, p = functions.x, functions.u, functions.p
    slacks = [c.function(x, u, p) / c.scale for c in problem.constraints]
    return ca.Function(
        "auvplan_nlp_stage",
        [x, u, p],
        [functions.x_next, functions.stage_cost, ca.vertcat(x[:0], *slacks)],  # x[:0]: 0 × 1
        ["x", "u", "p"],
        ["x_next", "l", "slacks"],
        {"is_diff_in": [True, True, False]},
    )


def _with_derivatives(stage: ca.Function) -> dict[str, ca.Function]:
    """``stage`` and the derivatives CasADi's AD of a mapped call asks of it (module notes).

    ``casadi.external`` finds them in the library by name: ``jac_<stage>`` (constraint
    Jacobian, objective gradient) and ``adj1_<stage>`` with its own ``jac_adj1_<stage>``
    (Hessian of the Lagrangian).
    """
    adjoint = stage.reverse(1)
    return {
        "stage": stage,
        "jacobian": stage.jacobian(),
        "adjoint": adjoint,
        "adjoint_jacobian": adjoint.jacobian(),
    }
