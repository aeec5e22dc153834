"""Small test problems for the optimiser (CasADi models)."""

from __future__ import annotations

import casadi as ca
import numpy as np

from auvplan.optimization import PathConstraint, Trajectory, TrajectoryProblem


def lq_problem(n_steps: int = 30, dt: float = 0.1) -> TrajectoryProblem:
    """Double integrator (2 axes) with quadratic costs: its discretisation is exactly LQ."""
    x = ca.SX.sym("x", 4)
    u = ca.SX.sym("u", 2)
    p = ca.SX.sym("p", 2)
    a = np.array([[0, 0, 1, 0], [0, 0, 0, 1], [0, 0, -0.3, 0], [0, 0, 0, -0.1]])
    b = np.array([[0, 0], [0, 0], [1, 0.2], [0, 1]])
    f = ca.Function("f", [x, u, p], [a @ x + b @ u])
    cost = ca.Function(
        "l", [x, u, p], [ca.sumsqr(x[:2] - p) + 0.1 * ca.sumsqr(x[2:]) + 0.5 * ca.sumsqr(u)]
    )
    m = ca.Function("m", [x], [10.0 * ca.sumsqr(x - np.array([1.0, -1.0, 0.0, 0.0]))])
    t = np.arange(n_steps) * dt
    params = np.stack([np.sin(t), np.cos(t)], axis=1)
    return TrajectoryProblem(
        f, cost, m, np.array([0.5, 0.0, 0.0, 0.2]), dt, n_steps, stage_parameters=params
    )


def _unicycle() -> tuple[ca.SX, ca.SX, ca.SX, ca.Function]:
    x = ca.SX.sym("x", 4)  # north, east, heading, speed
    u = ca.SX.sym("u", 2)  # yaw rate, acceleration
    p = ca.SX.sym("p", 0)
    f = ca.Function(
        "unicycle", [x, u, p], [ca.vertcat(x[3] * ca.cos(x[2]), x[3] * ca.sin(x[2]), u[0], u[1])]
    )
    return x, u, p, f


def unicycle_problem(n_steps: int = 60, dt: float = 0.05) -> TrajectoryProblem:
    """Unicycle to a goal pose, quadratic effort (unconstrained, nonlinear)."""
    x, u, p, f = _unicycle()
    goal = np.array([2.0, 1.0, 0.5, 0.0])
    cost = ca.Function("l", [x, u, p], [ca.sumsqr(u) + 0.1 * x[3] ** 2])
    m = ca.Function("m", [x], [20.0 * ca.sumsqr(x - goal)])
    return TrajectoryProblem(f, cost, m, np.zeros(4), dt, n_steps)


def obstacle_problem(n_steps: int = 80, dt: float = 0.05) -> TrajectoryProblem:
    """Unicycle past a circular obstacle (hockey-stick barrier) and an input bound (plain)."""
    x, u, p, f = _unicycle()
    goal = np.array([4.0, 0.0, 0.0, 0.0])
    cost = ca.Function("l", [x, u, p], [ca.sumsqr(u) + 0.1 * x[3] ** 2])
    m = ca.Function("m", [x], [50.0 * ca.sumsqr(x - goal)])
    obstacle = ca.Function(
        "obstacle", [x, u, p], [((x[0] - 2.0) ** 2 + (x[1] - 0.15) ** 2) / 0.6**2 - 1.0]
    )
    bound = ca.Function("turn", [x, u, p], [ca.vertcat(4.0 - u[0], 4.0 + u[0])])
    return TrajectoryProblem(
        f,
        cost,
        m,
        np.zeros(4),
        dt,
        n_steps,
        constraints=(
            PathConstraint(obstacle, "hockey", 1.0, "obstacle"),
            PathConstraint(bound, "plain", 4.0, "turn rate"),
        ),
    )


def crossing_problem(n_steps: int = 60, dt: float = 0.1, radius: float = 0.5) -> TrajectoryProblem:
    """Two kinematic vehicles (velocity inputs) crossing, separation as a hockey-stick barrier.

    State (north_1, east_1, north_2, east_2), inputs the four velocities; the desired paths
    (stage parameters) cross at the same time, so the separation constraint is active.
    """
    x = ca.SX.sym("x", 4)
    u = ca.SX.sym("u", 4)
    p = ca.SX.sym("p", 4)
    f = ca.Function("pair", [x, u, p], [u])
    cost = ca.Function("l", [x, u, p], [0.5 * ca.sumsqr(u) + 0.5 * ca.sumsqr(x - p)])
    horizon = n_steps * dt
    t = np.arange(n_steps) * dt / horizon
    desired = np.stack([-3 + 6 * t, 0 * t, 0 * t + 0.05, -3 + 6 * t], axis=1)
    goal = np.array([3.0, 0.0, 0.05, 3.0])
    m = ca.Function("m", [x], [5.0 * ca.sumsqr(x - goal)])
    separation = ca.Function(
        "separation",
        [x, u, p],
        [((x[0] - x[2]) ** 2 + (x[1] - x[3]) ** 2) / (2 * radius) ** 2 - 1.0],
    )
    return TrajectoryProblem(
        f,
        cost,
        m,
        np.array([-3.0, 0.0, 0.05, -3.0]),
        dt,
        n_steps,
        stage_parameters=desired,
        constraints=(PathConstraint(separation, "hockey", 1.0, "separation"),),
    )


def pendulum_problem(n_steps: int = 80, dt: float = 0.05) -> TrajectoryProblem:
    """Pendulum swing-up with a torque-rate cost (non-convex, needs the fallback ladder)."""
    x = ca.SX.sym("x", 2)
    u = ca.SX.sym("u", 1)
    p = ca.SX.sym("p", 0)
    f = ca.Function(
        "pendulum", [x, u, p], [ca.vertcat(x[1], -9.81 * ca.sin(x[0]) - 0.1 * x[1] + u)]
    )
    cost = ca.Function("l", [x, u, p], [0.05 * ca.sumsqr(u) + 0.01 * x[1] ** 2])
    m = ca.Function("m", [x], [20.0 * ((x[0] - np.pi) ** 2 + 0.1 * x[1] ** 2)])
    return TrajectoryProblem(
        f, cost, m, np.zeros(2), dt, n_steps, regulator_Q=np.array([10.0, 1.0]), regulator_R=[0.1]
    )


def zero_guess(problem: TrajectoryProblem) -> Trajectory:
    """States equal to x0, zero inputs."""
    states = np.tile(problem.initial_state, (problem.n_steps + 1, 1))
    return Trajectory(states, np.zeros((problem.n_steps, problem.n_inputs)))


def random_guess(
    problem: TrajectoryProblem, rng: np.random.Generator, scale: float = 0.3
) -> Trajectory:
    """Random curve (not a trajectory)."""
    states = problem.initial_state + scale * rng.standard_normal(
        (problem.n_steps + 1, problem.n_states)
    )
    inputs = scale * rng.standard_normal((problem.n_steps, problem.n_inputs))
    return Trajectory(states, inputs)
