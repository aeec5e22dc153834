r"""The fleet optimal-control problem of stage 3 (SPEC §5), as CasADi functions.

All vehicles are stacked into one system, ``x = (x_1, …, x_N)`` with 8 states each and
``c = (c_1, …, c_N)`` with 2 inputs each; the dynamics are block-diagonal. The per-stage
parameter vector ``p`` holds every vehicle's desired state (8 per vehicle), so the running cost

.. math::

    l(x, c, p) = \sum_i \left[ w_E P_i(x_i, c_i)
                 + \tfrac{w_T}{2} \|x_i - p_i\|^2_{Q} + \tfrac{1}{2} \|c_i\|^2_{R} \right]

is a rate in watts (energy weight ``w_E``, terrain weight ``w_T``), and the terminal cost
``m(x) = ½ Σ_i (k_p ‖pos_i − goal_i‖² + k_ψ (ψ_i − ψ_goal,i)²)`` is in joules. Constraints
follow SPEC §5 (feasible when ``c >= 0``): inter-vehicle collision
``‖p_i − p_j‖²/(2 r_c)² − 1`` and circular obstacles ``‖p_i − o‖²/(r_c + r_o)² − 1`` with the
hockey stick; communication range ``1 − ‖p_i − p_j‖²/d_max²`` and propeller-speed limits
``1 − (n/n_max)²`` plain (both define convex sets).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final, Literal

import casadi as ca
import numpy as np

from auvplan._typing import FloatArray

N_STATES: Final = 8
N_INPUTS: Final = 2

#: Desired-state weights Q (diagonal) of the tracking term, per unit of ``terrain`` weight:
#: position [W/m²], heading [W/rad²], surge/sway [W/(m/s)²], yaw rate [W/(rad/s)²],
#: propeller speeds [W/(rev/s)²].
TRACKING_WEIGHTS: Final = (1.0, 1.0, 20.0, 20.0, 0.0, 0.0, 1e-3, 1e-3)
#: Input regularisation R [W per unit c²] (keeps the LQ subproblem strongly convex in c).
INPUT_WEIGHT: Final = 1e-2
#: Terminal stiffness per unit of ``terminal`` weight: position [J/m²], heading [J/rad²].
TERMINAL_POSITION_WEIGHT: Final = 2e3
TERMINAL_HEADING_WEIGHT: Final = 2e3


@dataclass(frozen=True)
class FleetConstraint:
    """One block of path constraints ``c(x, u, p) >= 0`` of the stacked fleet system.

    ``kind`` is ``"hockey"`` (non-convex, barrier composed with the hockey stick) or
    ``"plain"``; ``labels`` name each row (``"blue-green"``, ``"blue-obstacle0"``, …).
    """

    name: str
    function: ca.Function
    kind: Literal["plain", "hockey"]
    labels: tuple[str, ...]


@dataclass(frozen=True)
class FleetProblemFunctions:
    """CasADi functions of the fleet problem; see the module docstring for the equations."""

    n_vehicles: int
    dynamics: ca.Function
    running_cost: ca.Function
    power: ca.Function
    terminal_cost: ca.Function
    constraints: tuple[FleetConstraint, ...]

    @property
    def n_x(self) -> int:
        """Stacked state dimension (8 per vehicle)."""
        return N_STATES * self.n_vehicles

    @property
    def n_u(self) -> int:
        """Stacked input dimension (2 per vehicle)."""
        return N_INPUTS * self.n_vehicles


def build_fleet_functions(
    dynamics: list[ca.Function],
    power: list[ca.Function],
    names: list[str],
    goals: FloatArray,
    *,
    safety_radius: float,
    separation_margin: float,
    max_propeller_speeds: FloatArray,
    obstacles: FloatArray,
    comm_pairs: list[tuple[int, int, float]],
    terrain_weight: float,
    energy_weight: float,
    terminal_weight: float,
) -> FleetProblemFunctions:
    """Stack per-vehicle models into the fleet problem.

    Parameters
    ----------
    dynamics, power : list of casadi.Function
        Per vehicle ``f(x[8], c[2]) -> xdot[8]`` and ``P(x[8], c[2]) -> W``.
    names : list of str
        Vehicle names (for constraint labels).
    goals : ndarray of shape (n_vehicles, 3)
        Goal ``north, east`` [m] and heading [rad] (already unwrapped next to the arrival heading).
    safety_radius : float
        ``r_c`` [m]; pairs keep ``>= 2 r_c``.
    separation_margin : float
        Added to ``2 r_c`` and to ``r_c + r_o`` [m] in the constraints, which are imposed at
        the grid nodes only: it covers the largest dip of a distance between two nodes.
    max_propeller_speeds : ndarray of shape (n_vehicles,)
        ``n_max`` [rev/s] per vehicle.
    obstacles : ndarray of shape (n_obstacles, 3)
        Circular obstacles ``north, east, radius`` [m].
    comm_pairs : list of (int, int, float)
        Vehicle index pairs that must stay within the given range [m].
    terrain_weight, energy_weight, terminal_weight : float
        Trade-off multipliers (see :class:`auvplan.mission.config.WeightsConfig`).
    """
    n_vehicles = len(dynamics)
    x = ca.SX.sym("x", N_STATES * n_vehicles)
    c = ca.SX.sym("c", N_INPUTS * n_vehicles)
    p = ca.SX.sym("p", N_STATES * n_vehicles)
    xs = [x[N_STATES * i : N_STATES * (i + 1)] for i in range(n_vehicles)]
    cs = [c[N_INPUTS * i : N_INPUTS * (i + 1)] for i in range(n_vehicles)]
    ps = [p[N_STATES * i : N_STATES * (i + 1)] for i in range(n_vehicles)]

    xdot = ca.vertcat(*[dynamics[i](xs[i], cs[i]) for i in range(n_vehicles)])
    powers = ca.vertcat(*[power[i](xs[i], cs[i]) for i in range(n_vehicles)])
    q = ca.DM(TRACKING_WEIGHTS)
    rate = energy_weight * ca.sum1(powers)
    for i in range(n_vehicles):
        error = xs[i] - ps[i]
        rate += 0.5 * terrain_weight * ca.dot(q * error, error)
        rate += 0.5 * INPUT_WEIGHT * ca.dot(cs[i], cs[i])

    terminal = 0.0
    for i in range(n_vehicles):
        d_north = xs[i][0] - goals[i, 0]
        d_east = xs[i][1] - goals[i, 1]
        d_psi = xs[i][2] - goals[i, 2]
        terminal += (
            0.5
            * terminal_weight
            * (
                TERMINAL_POSITION_WEIGHT * (d_north**2 + d_east**2)
                + TERMINAL_HEADING_WEIGHT * d_psi**2
            )
        )

    constraints = _constraints(
        x, c, p, xs, names, safety_radius, separation_margin, max_propeller_speeds, obstacles,
        comm_pairs,
    )  # fmt: skip
    return FleetProblemFunctions(
        n_vehicles=n_vehicles,
        dynamics=ca.Function("fleet_f", [x, c, p], [xdot]),
        running_cost=ca.Function("fleet_l", [x, c, p], [rate]),
        power=ca.Function("fleet_power", [x, c], [powers]),
        terminal_cost=ca.Function("fleet_m", [x], [terminal]),
        constraints=constraints,
    )


def _constraints(
    x: ca.SX,
    c: ca.SX,
    p: ca.SX,
    xs: list[ca.SX],
    names: list[str],
    safety_radius: float,
    margin: float,
    max_propeller_speeds: FloatArray,
    obstacles: FloatArray,
    comm_pairs: list[tuple[int, int, float]],
) -> tuple[FleetConstraint, ...]:
    n_vehicles = len(xs)
    blocks: list[FleetConstraint] = []

    def add(
        name: str, rows: list[ca.SX], labels: list[str], kind: Literal["plain", "hockey"]
    ) -> None:
        if rows:
            function = ca.Function(name, [x, c, p], [ca.vertcat(*rows)])
            blocks.append(FleetConstraint(name, function, kind, tuple(labels)))

    def squared_distance(i: int, north: ca.SX, east: ca.SX) -> ca.SX:
        return (xs[i][0] - north) ** 2 + (xs[i][1] - east) ** 2

    pairs = [(i, j) for i in range(n_vehicles) for j in range(i + 1, n_vehicles)]
    add(
        "collision",
        [
            squared_distance(i, xs[j][0], xs[j][1]) / (2 * safety_radius + margin) ** 2 - 1
            for i, j in pairs
        ],
        [f"{names[i]}-{names[j]}" for i, j in pairs],
        "hockey",
    )
    add(
        "obstacle",
        [
            squared_distance(i, north, east) / (safety_radius + radius + margin) ** 2 - 1
            for i in range(n_vehicles)
            for north, east, radius in np.asarray(obstacles).reshape(-1, 3)
        ],
        [f"{names[i]}-obstacle{k}" for i in range(n_vehicles) for k in range(len(obstacles))],
        "hockey",
    )
    add(
        "communication",
        [1 - squared_distance(i, xs[j][0], xs[j][1]) / d_max**2 for i, j, d_max in comm_pairs],
        [f"{names[i]}-{names[j]}" for i, j, _ in comm_pairs],
        "plain",
    )
    add(
        "propeller",
        [1 - (xs[i][k] / max_propeller_speeds[i]) ** 2 for i in range(n_vehicles) for k in (6, 7)],
        [f"{names[i]}-{side}" for i in range(n_vehicles) for side in ("n_ps", "n_sb")],
        "plain",
    )
    return tuple(blocks)
