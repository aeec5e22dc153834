"""PRONTO vs CasADi+IPOPT (MUMPS, exact Hessian) on identical discretised problems.

Run once and print the comparison table::

    .venv/bin/python benchmarks/bench_pronto.py            # toy problems + MEDUSA crossing
    .venv/bin/python benchmarks/bench_pronto.py --quick    # toy problems only
    .venv/bin/python benchmarks/bench_pronto.py --profile  # + cProfile of the MEDUSA solve
    .venv/bin/python benchmarks/bench_pronto.py --substeps # stage-function cost per RK4 substeps

Also usable with asv (classes with ``setup``, ``time_*`` and ``track_*``).

Both solvers get the same problem (same RK4 grid, same stage cost, same constraints) and the
same initial trajectory: the PRONTO projection of the initial guess (a dynamically feasible
trajectory, possibly violating the constraints). IPOPT solves (a) the hard-constrained problem
and (b) the barrier-augmented problem at PRONTO's final ``(ε, δ)``; costs are compared with
(a) for the original objective and with (b) for the barrier-augmented one.
"""

from __future__ import annotations

import argparse
import cProfile
import dataclasses
import io
import os
import pstats
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass

import casadi as ca
import numpy as np

from auvplan.optimization import (
    DiscreteModel,
    IpoptResult,
    ModelCache,
    PathConstraint,
    ProntoOptions,
    ProntoResult,
    Trajectory,
    TrajectoryProblem,
    discretize_rk4,
    project_guess,
    solve_ipopt,
    solve_pronto,
)
from auvplan.optimization.stage_functions import SOLVER_FUNCTIONS

# ---------------------------------------------------------------------------------------------
# problems


def _unicycle_dynamics() -> tuple[ca.SX, ca.SX, ca.SX, ca.Function]:
    x = ca.SX.sym("x", 4)
    u = ca.SX.sym("u", 2)
    p = ca.SX.sym("p", 0)
    f = ca.Function(
        "unicycle", [x, u, p], [ca.vertcat(x[3] * ca.cos(x[2]), x[3] * ca.sin(x[2]), u[0], u[1])]
    )
    return x, u, p, f


def unicycle_obstacle(n_steps: int = 400) -> tuple[TrajectoryProblem, ProntoOptions]:
    """Unicycle past a circular obstacle (hockey-stick barrier), 20 s horizon."""
    x, u, p, f = _unicycle_dynamics()
    dt = 20.0 / n_steps
    goal = np.array([10.0, 0.0, 0.0, 0.0])
    cost = ca.Function("l", [x, u, p], [ca.sumsqr(u) + 0.1 * x[3] ** 2])
    m = ca.Function("m", [x], [50.0 * ca.sumsqr(x - goal)])
    obstacle = ca.Function(
        "obstacle", [x, u, p], [((x[0] - 5.0) ** 2 + (x[1] - 0.3) ** 2) / 1.5**2 - 1.0]
    )
    problem = TrajectoryProblem(
        f,
        cost,
        m,
        np.zeros(4),
        dt,
        n_steps,
        constraints=(PathConstraint(obstacle, "hockey", 1.0, "obstacle"),),
    )
    return problem, ProntoOptions()


def pendulum_swing_up(n_steps: int = 400) -> tuple[TrajectoryProblem, ProntoOptions]:
    """Pendulum swing-up (unconstrained, strongly nonlinear), 8 s horizon."""
    x = ca.SX.sym("x", 2)
    u = ca.SX.sym("u", 1)
    p = ca.SX.sym("p", 0)
    f = ca.Function(
        "pendulum", [x, u, p], [ca.vertcat(x[1], -9.81 * ca.sin(x[0]) - 0.1 * x[1] + u)]
    )
    cost = ca.Function("l", [x, u, p], [0.05 * ca.sumsqr(u) + 0.01 * x[1] ** 2])
    m = ca.Function("m", [x], [20.0 * ((x[0] - np.pi) ** 2 + 0.1 * x[1] ** 2)])
    problem = TrajectoryProblem(
        f,
        cost,
        m,
        np.zeros(2),
        8.0 / n_steps,
        n_steps,
        regulator_Q=np.array([10.0, 1.0]),
        regulator_R=np.array([0.1]),
    )
    return problem, ProntoOptions(tol=1e-8)


def kinematic_crossing(n_steps: int = 600) -> tuple[TrajectoryProblem, ProntoOptions]:
    """Two kinematic vehicles whose desired straight paths cross at the same time."""
    x = ca.SX.sym("x", 4)
    u = ca.SX.sym("u", 4)
    p = ca.SX.sym("p", 4)
    f = ca.Function("pair", [x, u, p], [u])
    cost = ca.Function("l", [x, u, p], [0.5 * ca.sumsqr(u) + 0.5 * ca.sumsqr(x - p)])
    dt = 60.0 / n_steps
    s = np.arange(n_steps) / n_steps
    desired = np.stack([-30 + 60 * s, 0 * s, 0 * s + 0.5, -30 + 60 * s], axis=1)
    goal = np.array([30.0, 0.0, 0.5, 30.0])
    m = ca.Function("m", [x], [5.0 * ca.sumsqr(x - goal)])
    separation = ca.Function(
        "separation", [x, u, p], [((x[0] - x[2]) ** 2 + (x[1] - x[3]) ** 2) / 5.0**2 - 1.0]
    )
    problem = TrajectoryProblem(
        f,
        cost,
        m,
        np.array([-30.0, 0.0, 0.5, -30.0]),
        dt,
        n_steps,
        stage_parameters=desired,
        constraints=(PathConstraint(separation, "hockey", 1.0, "separation"),),
    )
    return problem, ProntoOptions()


def medusa_crossing(
    horizon: float = 600.0,
    dt: float = 0.5,
    safety_radius: float = 5.0,
    propeller_order: int | None = 4,
) -> tuple[TrajectoryProblem, ProntoOptions, Trajectory]:
    """Two MEDUSA vehicles crossing (16 states, 4 inputs), separation ``≥ 2 r_c``.

    Cost rate: electrical power of both vehicles [W] + quadratic tracking of straight
    desired paths + small input penalty; terminal cost to the goals. The desired paths cross
    with the second vehicle 5 m behind, so the straight-line initial guess violates the
    separation (3.5 m apart) without the degenerate exactly-coincident crossing, where the
    constraint gradient vanishes. ``propeller_order`` is the low-order propeller series of the
    planning model (``None``: full table).
    """
    from auvplan.io.vehicles import load_vehicle
    from auvplan.vehicle import build_vehicle_model
    from auvplan.vehicle.trim import trim_surge

    vehicle = build_vehicle_model(load_vehicle("medusa"), propeller_order=propeller_order)
    n_steps = round(horizon / dt)
    starts = np.array([[0.0, -50.0], [-5.0, 50.0]])
    goals = np.array([[300.0, 50.0], [295.0, -50.0]])
    x = ca.SX.sym("x", 16)
    c = ca.SX.sym("c", 4)
    p = ca.SX.sym("p", 4)  # desired (north, east) of both vehicles at t_k
    xs, cs = [x[:8], x[8:]], [c[:2], c[2:]]
    f = ca.Function(
        "fleet",
        [x, c, p],
        [ca.vertcat(*(vehicle.dynamics(xi, ci) for xi, ci in zip(xs, cs, strict=True)))],
    )
    tracking = 0.05 * (ca.sumsqr(x[0:2] - p[0:2]) + ca.sumsqr(x[8:10] - p[2:4]))
    power = sum(vehicle.power(xi, ci) for xi, ci in zip(xs, cs, strict=True))
    cost = ca.Function("l", [x, c, p], [power + tracking + 1.0 * ca.sumsqr(c)])
    terminal = 50.0 * (ca.sumsqr(x[0:2] - goals[0]) + ca.sumsqr(x[8:10] - goals[1]))
    m = ca.Function("m", [x], [terminal])
    separation = ca.Function(
        "separation",
        [x, c, p],
        [((x[0] - x[8]) ** 2 + (x[1] - x[9]) ** 2) / (2 * safety_radius) ** 2 - 1.0],
    )
    time_fraction = np.arange(n_steps) / n_steps
    desired = np.concatenate(
        [starts[i] + np.outer(time_fraction, goals[i] - starts[i]) for i in range(2)], axis=1
    )
    length = float(np.linalg.norm(goals[0] - starts[0]))
    speed = length / horizon
    n_trim = trim_surge(vehicle, speed).n
    # heading from north clockwise: atan2(east, north)
    headings = [
        float(np.arctan2(goals[i][1] - starts[i][1], goals[i][0] - starts[i][0])) for i in range(2)
    ]
    x0 = np.concatenate(
        [[*starts[i], headings[i], speed, 0.0, 0.0, n_trim, n_trim] for i in range(2)]
    )
    q_r = np.tile([1e-2, 1e-2, 10.0, 10.0, 10.0, 10.0, 1e-3, 1e-3], 2)
    problem = TrajectoryProblem(
        f,
        cost,
        m,
        x0,
        dt,
        n_steps,
        stage_parameters=desired,
        constraints=(PathConstraint(separation, "hockey", 1.0, "separation"),),
        regulator_Q=q_r,
        regulator_R=np.full(4, 1.0),
    )
    states = np.empty((n_steps + 1, 16))
    full_time = np.arange(n_steps + 1) / n_steps
    for i in range(2):
        block = slice(8 * i, 8 * i + 8)
        states[:, block] = x0[block]
        states[:, 8 * i : 8 * i + 2] = starts[i] + np.outer(full_time, goals[i] - starts[i])
    guess = Trajectory(states, np.zeros((n_steps, 4)))
    options = ProntoOptions(tol=1e-3, inner_tol=1e-1, eps_initial=1.0, eps_final=1e-2)
    return problem, options, guess


# ---------------------------------------------------------------------------------------------
# comparison


@dataclass(frozen=True)
class Comparison:
    """One problem: PRONTO and IPOPT runs from the same initial trajectory (times in s)."""

    name: str
    n_x: int
    n_u: int
    n_steps: int
    pronto: ProntoResult
    pronto_time: float
    pronto_cold_time: float
    pronto_threads_time: float
    pronto_c_time: float
    pronto_c_cold_time: float
    pronto_c_cost: float
    ipopt: IpoptResult
    ipopt_mx: IpoptResult
    ipopt_barrier: IpoptResult | None


def _zero_guess(problem: TrajectoryProblem) -> Trajectory:
    return Trajectory(
        np.tile(problem.initial_state, (problem.n_steps + 1, 1)),
        np.zeros((problem.n_steps, problem.n_inputs)),
    )


def compare(
    name: str,
    problem: TrajectoryProblem,
    options: ProntoOptions,
    guess: Trajectory | None = None,
) -> Comparison:
    """Solve with PRONTO and IPOPT from the same projected initial trajectory.

    PRONTO: first call (``cold``: CasADi derivative construction + numba cache load), second
    call (warm), and with 2 threads. IPOPT: expanded SX NLP (fast evaluation, slow to build),
    unexpanded MX NLP (fast to build), and the barrier-augmented objective at PRONTO's final
    ``(ε, δ)`` for the cost check.
    """
    guess = _zero_guess(problem) if guess is None else guess
    cache = ModelCache()
    start = time.perf_counter()
    model = cache.get(problem)  # CasADi derivative functions, kept in the cache
    cold_build = time.perf_counter() - start
    initial, _ = project_guess(model, guess, options)
    start = time.perf_counter()
    solve_pronto(problem, initial, options=options, cache=cache)  # + maps, numba cache load
    pronto_cold_time = cold_build + time.perf_counter() - start
    start = time.perf_counter()
    pronto = solve_pronto(problem, initial, options=options, cache=cache)
    pronto_time = time.perf_counter() - start
    threaded = dataclasses.replace(options, n_threads=2)
    solve_pronto(problem, initial, options=threaded, cache=cache)
    start = time.perf_counter()
    solve_pronto(problem, initial, options=threaded, cache=cache)
    pronto_threads_time = time.perf_counter() - start
    compiled = dataclasses.replace(options, compile_c=True)
    start = time.perf_counter()
    solve_pronto(problem, initial, options=compiled, cache=cache)  # + the one-off C compilation
    pronto_c_cold_time = time.perf_counter() - start
    start = time.perf_counter()
    pronto_c = solve_pronto(problem, initial, options=compiled, cache=cache)
    pronto_c_time = time.perf_counter() - start
    ipopt = solve_ipopt(problem, initial)
    ipopt_mx = solve_ipopt(problem, initial, expand=False)
    ipopt_barrier = None
    if problem.constraints:
        ipopt_barrier = solve_ipopt(
            problem, initial, barrier=(pronto.epsilon, pronto.delta), expand=False
        )
    return Comparison(
        name=name,
        n_x=problem.n_states,
        n_u=problem.n_inputs,
        n_steps=problem.n_steps,
        pronto=pronto,
        pronto_time=pronto_time,
        pronto_cold_time=pronto_cold_time,
        pronto_threads_time=pronto_threads_time,
        pronto_c_time=pronto_c_time,
        pronto_c_cold_time=pronto_c_cold_time,
        pronto_c_cost=pronto_c.cost,
        ipopt=ipopt,
        ipopt_mx=ipopt_mx,
        ipopt_barrier=ipopt_barrier,
    )


def format_tables(rows: list[Comparison]) -> str:
    """Markdown tables: timings, then costs."""
    timing = [
        (
            "| problem | n_x | n_u | N | PRONTO it | PRONTO s warm / cold / 2 threads | "
            "PRONTO compiled s warm (first, incl. C compile) | "
            "IPOPT it | IPOPT SX s total (build + solve) | IPOPT MX s total (solve) | "
            "speed-up vs best IPOPT total: VM (compiled) | vs IPOPT solve only: VM (compiled) |"
        ),
        "|" + "---|" * 12,
    ]
    costs = [
        (
            "| problem | PRONTO status | cost PRONTO (compiled) | cost IPOPT (hard) | rel. diff | "
            "barrier objective rel. diff (PRONTO vs IPOPT at same ε, δ) | final ε | min slack |"
        ),
        "|" + "---|" * 8,
    ]
    for row in rows:
        pr, ip, mx = row.pronto, row.ipopt, row.ipopt_mx
        best_total = min(ip.wall_time, mx.wall_time)
        best_solve = min(ip.solve_time, mx.solve_time)
        timing.append(
            f"| {row.name} | {row.n_x} | {row.n_u} | {row.n_steps} | {len(pr.history)} | "
            f"{row.pronto_time:.2f} / {row.pronto_cold_time:.2f} / {row.pronto_threads_time:.2f} | "
            f"{row.pronto_c_time:.2f} ({row.pronto_c_cold_time:.1f}) | "
            f"{ip.n_iter} | {ip.wall_time:.2f} ({ip.wall_time - ip.solve_time:.2f} + "
            f"{ip.solve_time:.2f}) | {mx.wall_time:.2f} ({mx.solve_time:.2f}) | "
            f"{best_total / row.pronto_time:.1f}x ({best_total / row.pronto_c_time:.1f}x) | "
            f"{best_solve / row.pronto_time:.1f}x ({best_solve / row.pronto_c_time:.1f}x) |"
        )
        rel = (pr.cost - ip.cost) / abs(ip.cost)
        barrier = "-"
        if row.ipopt_barrier is not None:
            rel_b = (pr.objective - row.ipopt_barrier.objective) / abs(row.ipopt_barrier.objective)
            barrier = f"{rel_b:+.1e}"
        costs.append(
            f"| {row.name} | {pr.status.value} | {pr.cost:.8g} ({row.pronto_c_cost:.8g}) | "
            f"{ip.cost:.8g} | {rel:+.1e} | "
            f"{barrier} | {pr.epsilon:.0e} | {pr.min_slack:.2e} |"
        )
    return "\n".join(timing) + "\n\n" + "\n".join(costs)


# ---------------------------------------------------------------------------------------------
# asv-style classes


class ToyProblems:
    """asv: PRONTO on the toy problems (time and iteration counts)."""

    params = ("pendulum", "unicycle_obstacle", "kinematic_crossing")
    param_names = ("problem",)

    def setup(self, name: str) -> None:
        builder = {
            "pendulum": pendulum_swing_up,
            "unicycle_obstacle": unicycle_obstacle,
            "kinematic_crossing": kinematic_crossing,
        }[name]
        self.problem, self.options = builder()
        self.guess = _zero_guess(self.problem)
        self.cache = ModelCache()
        self._solve()

    def _solve(self) -> ProntoResult:
        return solve_pronto(self.problem, self.guess, options=self.options, cache=self.cache)

    def time_pronto(self, name: str) -> None:  # noqa: ARG002
        self._solve()

    def track_pronto_iterations(self, name: str) -> int:  # noqa: ARG002
        return len(self._solve().history)

    def track_pronto_cost(self, name: str) -> float:  # noqa: ARG002
        return self._solve().cost


class MedusaCrossing:
    """asv: the 2-vehicle MEDUSA crossing (T = 600 s, dt = 0.5 s)."""

    timeout = 600.0

    def setup(self) -> None:
        self.problem, self.options, guess = medusa_crossing()
        self.cache = ModelCache()
        self.guess, _ = project_guess(self.cache.get(self.problem), guess, self.options)
        self._solve()

    def _solve(self) -> ProntoResult:
        return solve_pronto(self.problem, self.guess, options=self.options, cache=self.cache)

    def time_pronto(self) -> None:
        self._solve()

    def track_pronto_iterations(self) -> int:
        return len(self._solve().history)

    def time_ipopt(self) -> None:
        solve_ipopt(self.problem, self.guess)


SUBSTEPS = (1, 2, 4, 8)


def _stage_points(
    problem: TrajectoryProblem, guess: Trajectory
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Stage points near the guess (seeded), and costates, for timing the stage functions."""
    rng = np.random.default_rng(0)
    shape = (problem.n_steps, problem.n_states)
    states = guess.states[:-1] + 0.01 * rng.standard_normal(shape)
    inputs = 0.1 * rng.standard_normal((problem.n_steps, problem.n_inputs))
    return states, inputs, problem.parameters, rng.standard_normal(shape)


def _cpu_time(evaluate: Callable[[], object], repeats: int) -> float:
    """Smallest CPU time of ``repeats`` calls (after one warm-up call) [s]."""
    evaluate()
    times = []
    for _ in range(repeats):
        start = time.process_time()
        evaluate()
        times.append(time.process_time() - start)
    return min(times)


def substep_timings(substeps: tuple[int, ...] = SUBSTEPS, repeats: int = 5) -> str:
    """Cost of the stage functions of the MEDUSA crossing per number of RK4 substeps ``m``.

    Build: ``discretize_rk4`` and the Functions a solve uses (CasADi graph, derivatives,
    common-subexpression elimination; wall time).
    Evaluation: CPU time of one batched call over all ``N`` stages (``process_time``, smallest
    of ``repeats``), for the λ-weighted Lagrangian Hessians (``Q, S, R``), the first-order data
    and the step.
    """
    problem, _, guess = medusa_crossing(propeller_order=3)
    states, inputs, params, costates = _stage_points(problem, guess)
    lines = [
        (
            f"MEDUSA crossing, 2 vehicles (n_x = {problem.n_states}, n_u = {problem.n_inputs}), "
            f"N = {problem.n_steps}, dt = {problem.dt} s"
        ),
        "",
        "| m | build s | Hessians s (µs/stage) | first order s | step s |",
        "|---|---|---|---|---|",
    ]
    for m in substeps:
        start = time.perf_counter()
        model: DiscreteModel = discretize_rk4(
            problem.dynamics, problem.running_cost, problem.dt, n_substeps=m
        )
        for name in SOLVER_FUNCTIONS:  # built on first use: build them here
            getattr(model.functions, name)
        build = time.perf_counter() - start
        hessians = _cpu_time(
            lambda model=model: model.lagrangian_hessians(states, inputs, params, costates),
            repeats,
        )
        first = _cpu_time(lambda model=model: model.first_order(states, inputs, params), repeats)
        step = _cpu_time(lambda model=model: model.step(states, inputs, params), repeats)
        lines.append(
            f"| {m} | {build:.2f} | {hessians:.3f} ({1e6 * hessians / problem.n_steps:.0f}) | "
            f"{first:.3f} | {step:.4f} |"
        )
    return "\n".join(lines)


class SubstepHessians:
    """asv: the MEDUSA crossing's λ-weighted Hessians per number of RK4 substeps."""

    params = SUBSTEPS
    param_names = ("n_substeps",)
    timeout = 600.0

    def setup(self, n_substeps: int) -> None:
        problem, _, guess = medusa_crossing(propeller_order=3)
        self.points = _stage_points(problem, guess)
        self.model = discretize_rk4(
            problem.dynamics, problem.running_cost, problem.dt, n_substeps=n_substeps
        )

    def time_lagrangian_hessians(self, n_substeps: int) -> None:  # noqa: ARG002
        self.model.lagrangian_hessians(*self.points)


def _profile(problem: TrajectoryProblem, guess: Trajectory, options: ProntoOptions) -> str:
    cache = ModelCache()
    solve_pronto(problem, guess, options=options, cache=cache)  # warm
    profiler = cProfile.Profile()
    profiler.enable()
    solve_pronto(problem, guess, options=options, cache=cache)
    profiler.disable()
    stream = io.StringIO()
    pstats.Stats(profiler, stream=stream).sort_stats("tottime").print_stats(12)
    return stream.getvalue()


def main(argv: list[str]) -> int:
    # a fresh cache folder, so that the "first" compiled time includes the C compilation
    os.environ["AUVPLAN_CACHE_DIR"] = tempfile.mkdtemp(prefix="auvplan_bench_")
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="toy problems only")
    parser.add_argument("--profile", action="store_true", help="profile the MEDUSA solve")
    parser.add_argument(
        "--substeps", action="store_true", help="only the stage-function cost per RK4 substeps"
    )
    args = parser.parse_args(argv)
    if args.substeps:
        print(substep_timings())
        return 0
    rows = []
    for name, builder in (
        ("pendulum swing-up", pendulum_swing_up),
        ("unicycle + obstacle", unicycle_obstacle),
        ("kinematic 2-vehicle crossing", kinematic_crossing),
    ):
        problem, options = builder()
        rows.append(compare(name, problem, options))
        print(f"{name}: done", flush=True)
    if not args.quick:
        problem, options, guess = medusa_crossing()
        rows.append(compare("MEDUSA 2-vehicle crossing", problem, options, guess))
        if args.profile:
            initial, _ = project_guess(ModelCache().get(problem), guess, options)
            print("profile, CasADi virtual machine:")
            print(_profile(problem, initial, options))
            print("profile, compiled stage functions:")
            print(_profile(problem, initial, dataclasses.replace(options, compile_c=True)))
    print()
    print(format_tables(rows))
    for row in rows:
        history = row.pronto.history
        print(
            f"\n{row.name}: -Dh·ζ per iteration: " + " ".join(f"{h.decrement:.1e}" for h in history)
        )
        print("  direction: " + "".join(h.direction.value[0] for h in history))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
