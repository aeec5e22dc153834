"""
Discrete-time PRONTO with an approximate-barrier obstacle constraint
=====================================================================

A unicycle (north, east, heading, speed; inputs yaw rate and acceleration) must reach a goal
pose in 4 s with minimum effort, while a circular obstacle sits almost on the straight line.
The obstacle is a path constraint ``c(x) = d^2 / r^2 - 1 >= 0`` handled by the approximate
log barrier composed with the hockey stick; the initial guess (standing still) is projected
onto the dynamics, the barrier weight ``epsilon`` is reduced from 1 to 1e-4 with warm starts,
and ``delta`` is shrunk once the trajectory is strictly feasible (reference/pronto.md §7.5).

The same discretised problem is handed to CasADi + IPOPT (multiple shooting, MUMPS, exact
Hessian) as an independent check. The right panel shows the Newton decrement ``-Dh·zeta`` per
iteration: within each barrier level it falls quadratically.

Run ``python examples/plot_04_pronto.py [OUTPUT.png]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import casadi as ca
import matplotlib.pyplot as plt
import numpy as np

from auvplan.optimization import (
    PathConstraint,
    Trajectory,
    TrajectoryProblem,
    solve_ipopt,
    solve_pronto,
)

x = ca.SX.sym("x", 4)  # north [m], east [m], heading [rad], speed [m/s]
u = ca.SX.sym("u", 2)  # yaw rate [rad/s], acceleration [m/s^2]
p = ca.SX.sym("p", 0)
dynamics = ca.Function(
    "unicycle", [x, u, p], [ca.vertcat(x[3] * ca.cos(x[2]), x[3] * ca.sin(x[2]), u[0], u[1])]
)
running_cost = ca.Function("effort", [x, u, p], [ca.sumsqr(u) + 0.1 * x[3] ** 2])
goal = np.array([4.0, 0.0, 0.0, 0.0])
terminal_cost = ca.Function("arrival", [x], [50.0 * ca.sumsqr(x - goal)])
center, radius = np.array([2.0, 0.15]), 0.6
obstacle = ca.Function("obstacle", [x, u, p], [ca.sumsqr(x[:2] - center) / radius**2 - 1.0])
n_steps = 80
problem = TrajectoryProblem(
    dynamics,
    running_cost,
    terminal_cost,
    np.zeros(4),
    4.0 / n_steps,
    n_steps,
    constraints=(PathConstraint(obstacle, "hockey", 1.0, "obstacle"),),
)
guess = Trajectory(np.zeros((n_steps + 1, 4)), np.zeros((n_steps, 2)))

result = solve_pronto(problem, guess)
reference = solve_ipopt(problem, result.trajectory, barrier=(result.epsilon, result.delta))
print(f"PRONTO: {result.status.value}, {len(result.history)} iterations, cost {result.cost:.6f}")
print(
    f"IPOPT (same barrier objective): relative difference "
    f"{(result.objective - reference.objective) / reference.objective:+.1e}"
)
print(f"smallest scaled slack {result.min_slack:.2e} (feasible when > 0)")

figure, (ax_path, ax_conv) = plt.subplots(1, 2, figsize=(11, 4.2))
angle = np.linspace(0, 2 * np.pi, 200)
ax_path.fill(
    center[1] + radius * np.sin(angle),
    center[0] + radius * np.cos(angle),
    color="0.8",
    label="obstacle",
)
states = result.trajectory.states
ax_path.plot(states[:, 1], states[:, 0], "C0.-", ms=3, label="PRONTO")
ax_path.plot(
    reference.trajectory.states[:, 1], reference.trajectory.states[:, 0], "C1--", label="IPOPT"
)
ax_path.plot(goal[1], goal[0], "k*", ms=10, label="goal")
ax_path.set_xlabel("east [m]")
ax_path.set_ylabel("north [m]")
ax_path.set_aspect("equal")
ax_path.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize="small")
ax_path.set_title("optimised trajectory")

decrements = np.array([record.decrement for record in result.history])
epsilons = np.array([record.epsilon for record in result.history])
for level in np.unique(epsilons)[::-1]:
    index = np.flatnonzero(epsilons == level)
    ax_conv.semilogy(index, decrements[index], "o-", label=f"ε = {level:.0e}")
ax_conv.set_xlabel("iteration")
ax_conv.set_ylabel("−Dh·ζ")
ax_conv.set_title("Newton decrement per barrier level")
ax_conv.legend()
figure.tight_layout()
output = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("plot_04_pronto.png")
figure.savefig(output, dpi=120)
print(f"wrote {output}")
