r"""The fleet: stacked states of several vehicles, and the stage-3 problem as CasADi functions.

:class:`FleetLayout` is the one owner of how vehicles are stacked: vehicle ``i`` occupies
``state_slice(i)`` of the stacked state ``x = (x_1, …, x_N)`` and ``input_slice(i)`` of
``c = (c_1, …, c_N)``, each of the size its own model declares (vehicle types may differ).
Named states come from the vehicle models (:meth:`auvplan.vehicle.VehicleModel.index`).

The dynamics are block-diagonal. The per-stage parameter ``p`` holds every vehicle's desired
state (stacked like ``x``), so the running cost

.. math::

    l(x, c, p) = \sum_i \left[ w_E P_i(x_i, c_i)
                 + \tfrac{w_T}{2} \|x_i - p_i\|^2_{Q} + \tfrac{1}{2} \|c_i\|^2_{R} \right]

is a rate in watts (energy weight ``w_E``, terrain weight ``w_T``), and the terminal cost
``m(x) = ½ Σ_i (k_p ‖pos_i − goal_i‖² + k_ψ (ψ_i − ψ_goal,i)²)`` is in joules. Constraints
follow SPEC §5 (feasible when ``c >= 0``): inter-vehicle collision
``‖p_i − p_j‖²/(2 r_c + margin)² − 1`` and circular obstacles
``‖p_i − o‖²/(r_c + r_o + margin)² − 1`` with the hockey stick; communication range
``1 − ‖p_i − p_j‖²/d_max²`` and state limits ``1 − (x/x_max)²`` plain (convex sets).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Final, Literal

import casadi as ca
import numpy as np

from auvplan._typing import FloatArray
from auvplan.ocean import CurrentField
from auvplan.optimization import StageBlock, stack_blocks
from auvplan.record.labels import Pair
from auvplan.vehicle import VehicleModel

#: Desired-state weights Q of the tracking term per unit of ``terrain`` weight, by state name:
#: position [W/m²], heading [W/rad²], surge [W/(m/s)²]; thruster (propeller-speed) states get
#: :data:`THRUSTER_WEIGHT`, others 0 (see :func:`tracking_weights`).
TRACKING_WEIGHTS: Final = {"north": 1.0, "east": 1.0, "psi": 20.0, "u": 20.0}
#: Weights of the projection regulator (PRONTO's tracking LQR), by state name; thruster states
#: get :data:`THRUSTER_WEIGHT`, others 1 (see :func:`regulator_weights`).
REGULATOR_WEIGHTS: Final = {"north": 1.0, "east": 1.0, "psi": 10.0, "u": 10.0, "v": 1.0, "r": 10.0}
#: Weight of every thruster (propeller-speed) state in both [per (rev/s)²].
THRUSTER_WEIGHT: Final = 1e-3


def tracking_weights(model: VehicleModel) -> dict[str, float]:
    """Tracking weights of ``model``'s states by name (:data:`TRACKING_WEIGHTS`)."""
    return {**TRACKING_WEIGHTS, **dict.fromkeys(model.thruster_states, THRUSTER_WEIGHT)}


def regulator_weights(model: VehicleModel) -> dict[str, float]:
    """Projection-regulator weights of ``model``'s states by name (:data:`REGULATOR_WEIGHTS`).

    A control-surface deflection gets ``1 / δ_max²`` (Bryson's rule: full deflection weighs
    like a metre of position error), so that the projection steers within the surface's range
    rather than past it.
    """
    limits = dict(model.state_limits)
    surfaces = {name: 1.0 / limits[name] ** 2 for name in model.surface_states}
    thrusters = dict.fromkeys(model.thruster_states, THRUSTER_WEIGHT)
    return {**REGULATOR_WEIGHTS, **thrusters, **surfaces}


#: Input regularisation R [W per unit c²] (keeps the LQ subproblem strongly convex in c).
INPUT_WEIGHT: Final = 1e-2
#: Terminal stiffness per unit of ``terminal`` weight: position [J/m²], heading [J/rad²].
TERMINAL_POSITION_WEIGHT: Final = 2e3
TERMINAL_HEADING_WEIGHT: Final = 2e3


#: Stage-parameter entries of the current model per vehicle: ``v_c,k`` (2) and ``G_k`` (4).
N_CURRENT_PARAMETERS: Final = 6


#: The running-cost terms of a vehicle, in the order of :func:`vehicle_cost_terms`' output.
RUNNING_TERMS: Final = ("energy", "tracking", "input")
#: Every named term of the fleet's cost: the running terms, the information reward (a
#: :class:`~auvplan.optimization.NodeCost`, negative) and the terminal cost.
COST_TERMS: Final = (*RUNNING_TERMS, "information", "terminal")


@dataclass(frozen=True)
class StageWeights:
    """The runtime weights ``w`` of one vehicle's cost rate, by name.

    The one owner of their order in ``w = (w_E, w_T, r, q_1, …, q_{n_x})``: :meth:`vector` packs
    numbers, :meth:`of` names the entries of a symbol, so no index is spelt elsewhere.

    Attributes
    ----------
    energy : float
        ``w_E``, multiplier of the propulsive power [-].
    tracking : float
        ``w_T``, multiplier of the desired-state tracking (the terrain weight; 0 for a vehicle
        whose route is not tracked) [-].
    input : float
        ``r``, input regularisation [W per unit c²].
    per_state : tuple of float
        ``q_s``, tracking weight of each state [W per unit state²] (:func:`tracking_weights`).
    """

    energy: Any
    tracking: Any
    input: Any
    per_state: Any

    @staticmethod
    def size(n_x: int) -> int:
        """Length of ``w`` for a model of ``n_x`` states."""
        return 3 + n_x

    @classmethod
    def of(cls, w: ca.SX) -> StageWeights:
        """The named entries of a symbol ``w`` of :meth:`size`."""
        return cls(energy=w[0], tracking=w[1], input=w[2], per_state=w[3:])

    def vector(self) -> FloatArray:
        """``w`` as numbers."""
        return np.array([self.energy, self.tracking, self.input, *self.per_state], dtype=float)


def vehicle_cost_terms(model: VehicleModel, *, has_current: bool = False) -> ca.Function:
    r"""The running-cost terms of one vehicle: ``terms(x, c, p, w) -> (3,)`` rates [W].

    ``(w_E P(x, c), ½ w_T Σ_s q_s (x_s − x_{d,s})², ½ r ‖c‖²)`` named by
    :data:`RUNNING_TERMS`, with ``w`` as :class:`StageWeights` and ``p`` as in
    :func:`vehicle_stage_functions`.
    """
    x, c = ca.SX.sym("x", model.n_x), ca.SX.sym("c", model.n_u)
    n_p = model.n_x + (N_CURRENT_PARAMETERS if has_current else 0)
    p, w = ca.SX.sym("p", n_p), ca.SX.sym("w", StageWeights.size(model.n_x))
    weights = StageWeights.of(w)
    error = x - p[: model.n_x]
    terms = ca.vertcat(
        weights.energy * model.power(x, c),
        0.5 * weights.tracking * ca.dot(weights.per_state * error, error),
        0.5 * weights.input * ca.dot(c, c),
    )
    return ca.Function("vehicle_terms", [x, c, p, w], [terms])


def vehicle_stage_functions(
    model: VehicleModel, *, has_current: bool = False
) -> tuple[ca.Function, ca.Function]:
    r"""One vehicle's block of the fleet problem: ``f(x, c, p)`` and cost rate ``l(x, c, p, w)``.

    ``l`` is the sum of :func:`vehicle_cost_terms`:
    ``l = w_E P(x, c) + ½ w_T Σ_s q_s (x_s − x_{d,s})² + ½ r ‖c‖²`` [W], ``w`` as
    :class:`StageWeights`. With ``has_current``, ``p = (x_d, v_c,k, vec(G_k))``
    (:data:`N_CURRENT_PARAMETERS` more, ``G_k`` row-major) and the dynamics are
    :attr:`~auvplan.vehicle.VehicleModel.dynamics_in_current` with the current linearised
    about the desired position ``p_d``: ``v_c(p) ≈ v_c,k + G_k (p − p_d)``.
    """
    x, c = ca.SX.sym("x", model.n_x), ca.SX.sym("c", model.n_u)
    n_p = model.n_x + (N_CURRENT_PARAMETERS if has_current else 0)
    p, w = ca.SX.sym("p", n_p), ca.SX.sym("w", StageWeights.size(model.n_x))
    rate = ca.sum1(vehicle_cost_terms(model, has_current=has_current)(x, c, p, w))
    if has_current:
        rows = [model.index("north"), model.index("east")]
        offset = p[model.n_x : model.n_x + 2]
        jacobian = ca.reshape(p[model.n_x + 2 :], 2, 2).T  # row-major G
        drift = offset + ca.mtimes(jacobian, x[rows] - p[rows])
        xdot = model.dynamics_in_current(x, c, drift)
    else:
        xdot = model.dynamics(x, c)
    return (
        ca.Function("vehicle_f", [x, c, p], [xdot]),
        ca.Function("vehicle_l", [x, c, p, w], [rate]),
    )


def current_parameters(
    model: VehicleModel, desired: FloatArray, time: FloatArray, current: CurrentField
) -> FloatArray:
    """Per-stage ``(v_c,k, vec(G_k))`` of shape ``(n_t, 6)`` at the desired positions and times."""
    north, east = desired[:, model.index("north")], desired[:, model.index("east")]
    velocity = np.column_stack(current.velocity(north, east, time))
    jacobian = current.gradient(north, east, time).reshape(-1, 4)
    return np.hstack([velocity, jacobian])


@dataclass(frozen=True, eq=False)
class FleetLayout:
    """How the vehicles' states and inputs are stacked into one system."""

    names: tuple[str, ...]
    models: tuple[VehicleModel, ...]

    @property
    def n_vehicles(self) -> int:
        """Number of vehicles."""
        return len(self.models)

    @property
    def n_x(self) -> int:
        """Stacked state dimension."""
        return sum(model.n_x for model in self.models)

    @property
    def n_u(self) -> int:
        """Stacked input dimension."""
        return sum(model.n_u for model in self.models)

    def state_slice(self, i: int) -> slice:
        """Rows of vehicle ``i`` in the stacked state."""
        start = sum(model.n_x for model in self.models[:i])
        return slice(start, start + self.models[i].n_x)

    def input_slice(self, i: int) -> slice:
        """Rows of vehicle ``i`` in the stacked input."""
        start = sum(model.n_u for model in self.models[:i])
        return slice(start, start + self.models[i].n_u)

    def n_p(self, *, has_current: bool) -> int:
        """Stacked stage-parameter dimension (desired states, plus the current model)."""
        return self.n_x + (N_CURRENT_PARAMETERS * self.n_vehicles if has_current else 0)

    def parameter_slice(self, i: int, *, has_current: bool) -> slice:
        """Rows of vehicle ``i`` in the stacked stage parameters (``vehicle_stage_functions``)."""
        extra = N_CURRENT_PARAMETERS if has_current else 0
        start = sum(model.n_x + extra for model in self.models[:i])
        return slice(start, start + self.models[i].n_x + extra)

    def stack(self, per_vehicle: Sequence[FloatArray]) -> FloatArray:
        """Per-vehicle arrays ``(n_t, n_x_i)`` (or ``(n_t, n_u_i)``) side by side."""
        return np.ascontiguousarray(np.concatenate(per_vehicle, axis=-1))

    def unstack_states(self, stacked: FloatArray) -> tuple[FloatArray, ...]:
        """Per-vehicle views ``(n_t, n_x_i)`` of stacked states ``(n_t, n_x)``."""
        return tuple(stacked[..., self.state_slice(i)] for i in range(self.n_vehicles))

    def unstack_inputs(self, stacked: FloatArray) -> tuple[FloatArray, ...]:
        """Per-vehicle views ``(n_t, n_u_i)`` of stacked inputs ``(n_t, n_u)``."""
        return tuple(stacked[..., self.input_slice(i)] for i in range(self.n_vehicles))

    def gains_of(self, gains: FloatArray, i: int) -> FloatArray:
        """Vehicle ``i``'s own block ``(N, n_u_i, n_x_i)`` of stacked gains ``(N, n_u, n_x)``."""
        return gains[:, self.input_slice(i), self.state_slice(i)]

    def per_state(
        self,
        values: Mapping[str, float] | Callable[[VehicleModel], Mapping[str, float]],
        default: float,
    ) -> FloatArray:
        """A stacked vector from values by state name (or a model's own), ``default`` elsewhere."""
        return np.concatenate(
            [
                [(values(model) if callable(values) else values).get(name, default)
                 for name in model.state_names]
                for model in self.models
            ]
        )  # fmt: skip


@dataclass(frozen=True)
class FleetConstraint:
    """One block of path constraints ``c(x, u, p) >= 0`` of the stacked fleet system.

    ``kind`` is ``"hockey"`` (non-convex, barrier composed with the hockey stick) or
    ``"plain"``; ``labels`` name each row by its :class:`~auvplan.record.labels.Pair`
    (two vehicles, a vehicle and an obstacle, a vehicle and a limited state).
    """

    name: str
    function: ca.Function
    kind: Literal["plain", "hockey"]
    labels: tuple[Pair, ...]


@dataclass(frozen=True)
class FleetProblemFunctions:
    """CasADi functions of the fleet problem; see the module docstring for the equations."""

    layout: FleetLayout
    blocks: tuple[StageBlock, ...]
    dynamics: ca.Function
    running_cost: ca.Function
    power: ca.Function
    terminal_cost: ca.Function
    constraints: tuple[FleetConstraint, ...]


@dataclass(frozen=True)
class FleetWeights:
    """Trade-off multipliers (see :class:`auvplan.mission.config.WeightsConfig`).

    ``tracked`` says, per vehicle, whether its desired trajectory is tracked (with weight
    ``terrain``) or not (0: its plan is energy-optimal); empty: every vehicle is.
    """

    terrain: float
    energy: float
    terminal: float
    tracked: tuple[bool, ...] = ()

    def terrain_of(self, index: int) -> float:
        """The tracking weight of vehicle ``index``."""
        return self.terrain if not self.tracked or self.tracked[index] else 0.0

    def stage_weights(self, index: int, model: VehicleModel) -> StageWeights:
        """The :class:`StageWeights` of vehicle ``index`` of type ``model``."""
        per_state = tracking_weights(model)
        return StageWeights(
            energy=self.energy,
            tracking=self.terrain_of(index),
            input=INPUT_WEIGHT,
            per_state=tuple(per_state.get(name, 0.0) for name in model.state_names),
        )


@dataclass(frozen=True)
class FleetLimits:
    """Separation and range limits of the fleet problem.

    ``obstacles`` ``(n_obstacles, 3)``: circles ``north, east, radius`` [m] labelled by
    ``obstacle_names``; ``comm_pairs``: vehicle index pairs and their range [m].
    ``separation_margin`` [m] is added to ``2 r_c`` and ``r_c + r_o``: the constraints are imposed
    at the grid nodes only, and it covers the largest dip of a distance between two nodes.
    ``corridors`` (empty: none): per vehicle the half-width ``w`` [m] of the corridor around
    its desired position it keeps, ``|p_k − p_d,k| ≤ w`` (``inf``: no corridor), for routes
    certified by a navigation budget (:func:`auvplan.mission.assembly.navigation_corridors`).
    ``neighbours`` and ``neighbour_ranges`` are vehicles outside the layout whose positions
    ``(north, east)`` [m] are appended to the stage parameters, in this order: every vehicle of
    the layout keeps ``2 r_c + margin`` from the first ``neighbours`` of them (hockey stick) and
    within range ``d_max`` [m] of the next ``len(neighbour_ranges)`` (plain); a vehicle's own
    problem in the decomposed solve (:mod:`auvplan.mission.decomposition`).
    """

    safety_radius: float
    separation_margin: float
    obstacles: FloatArray
    obstacle_names: tuple[str, ...]
    comm_pairs: tuple[tuple[int, int, float], ...]
    corridors: tuple[float, ...] = ()
    neighbours: int = 0
    neighbour_ranges: tuple[float, ...] = ()

    @property
    def n_neighbour_parameters(self) -> int:
        """Stage parameters the neighbours' positions take (after the layout's own)."""
        return 2 * (self.neighbours + len(self.neighbour_ranges))


def build_fleet_functions(
    layout: FleetLayout,
    goals: FloatArray,
    weights: FleetWeights,
    limits: FleetLimits,
    *,
    has_current: bool = False,
) -> FleetProblemFunctions:
    """Stack the vehicle models into the fleet problem.

    Parameters
    ----------
    layout : FleetLayout
        The vehicles and their models.
    goals : ndarray of shape (n_vehicles, 3)
        Goal ``north, east`` [m] and heading [rad] (unwrapped next to the arrival heading).
    weights : FleetWeights
        Cost multipliers.
    limits : FleetLimits
        Safety radius, obstacles, communication pairs.
    has_current : bool
        Whether the stage parameters carry the current model (:func:`vehicle_stage_functions`).
    """
    own_p = layout.n_p(has_current=has_current)
    n_p = own_p + limits.n_neighbour_parameters
    x = ca.SX.sym("x", layout.n_x)
    c = ca.SX.sym("c", layout.n_u)
    p = ca.SX.sym("p", n_p)
    xs = [x[layout.state_slice(i)] for i in range(layout.n_vehicles)]
    cs = [c[layout.input_slice(i)] for i in range(layout.n_vehicles)]
    models = layout.models

    blocks = tuple(
        StageBlock(
            *vehicle_stage_functions(model, has_current=has_current),
            weights=weights.stage_weights(i, model).vector(),
            states=layout.state_slice(i),
            inputs=layout.input_slice(i),
            parameters=layout.parameter_slice(i, has_current=has_current),
        )
        for i, model in enumerate(models)
    )
    dynamics, running_cost = stack_blocks(blocks, layout.n_x, layout.n_u, n_p)
    powers = ca.vertcat(*[model.power(xs[i], cs[i]) for i, model in enumerate(models)])

    terminal = 0.0
    for i, model in enumerate(models):
        pose = [xs[i][model.index(name)] for name in ("north", "east", "psi")]
        terminal += (
            0.5
            * weights.terminal
            * (
                TERMINAL_POSITION_WEIGHT
                * ((pose[0] - goals[i, 0]) ** 2 + (pose[1] - goals[i, 1]) ** 2)
                + TERMINAL_HEADING_WEIGHT * (pose[2] - goals[i, 2]) ** 2
            )
        )
    return FleetProblemFunctions(
        layout=layout,
        blocks=blocks,
        dynamics=dynamics,
        running_cost=running_cost,
        power=ca.Function("fleet_power", [x, c], [powers]),
        terminal_cost=ca.Function("fleet_m", [x], [terminal]),
        constraints=_constraints(
            layout,
            (x, c, p),
            xs,
            [p[layout.parameter_slice(i, has_current=has_current)] for i in range(len(models))],
            [(p[k], p[k + 1]) for k in range(own_p, n_p, 2)],
            limits,
        ),
    )


def _constraints(
    layout: FleetLayout,
    arguments: tuple[ca.SX, ca.SX, ca.SX],
    xs: list[ca.SX],
    desired: list[ca.SX],
    neighbours: list[tuple[ca.SX, ca.SX]],
    limits: FleetLimits,
) -> tuple[FleetConstraint, ...]:
    """The path constraint blocks ``c ≥ 0``.

    ``desired`` holds each vehicle's stage parameters (its desired state first);
    ``neighbours`` the positions of the vehicles outside the layout (:class:`FleetLimits`).
    """
    names, models = layout.names, layout.models
    blocks: list[FleetConstraint] = []

    def add(
        name: str, rows: list[ca.SX], labels: list[Pair], kind: Literal["plain", "hockey"]
    ) -> None:
        if rows:
            function = ca.Function(name, list(arguments), [ca.vertcat(*rows)])
            blocks.append(FleetConstraint(name, function, kind, tuple(labels)))

    def position(i: int) -> tuple[ca.SX, ca.SX]:
        return xs[i][models[i].index("north")], xs[i][models[i].index("east")]

    def squared_distance(i: int, north: ca.SX, east: ca.SX) -> ca.SX:
        own_north, own_east = position(i)
        return (own_north - north) ** 2 + (own_east - east) ** 2

    pairs = [(i, j) for i in range(layout.n_vehicles) for j in range(i + 1, layout.n_vehicles)]
    separation = 2 * limits.safety_radius + limits.separation_margin
    vehicles = range(layout.n_vehicles)
    close = [(i, m) for i in vehicles for m in range(limits.neighbours)]
    add(
        "collision",
        [squared_distance(i, *position(j)) / separation**2 - 1 for i, j in pairs]
        + [squared_distance(i, *neighbours[m]) / separation**2 - 1 for i, m in close],
        [Pair(names[i], names[j]) for i, j in pairs]
        + [Pair(names[i], f"neighbour {m}") for i, m in close],
        "hockey",
    )
    circles = np.asarray(limits.obstacles).reshape(-1, 3)
    reach = limits.safety_radius + limits.separation_margin
    add(
        "obstacle",
        [
            squared_distance(i, north, east) / (reach + radius) ** 2 - 1
            for i in range(layout.n_vehicles)
            for north, east, radius in circles
        ],
        [
            Pair(names[i], label)
            for i in range(layout.n_vehicles)
            for label in limits.obstacle_names
        ],
        "hockey",
    )
    ranged = [
        (i, limits.neighbours + m, d_max)
        for i in vehicles
        for m, d_max in enumerate(limits.neighbour_ranges)
    ]
    add(
        "communication",
        [1 - squared_distance(i, *position(j)) / d_max**2 for i, j, d_max in limits.comm_pairs]
        + [1 - squared_distance(i, *neighbours[m]) / d_max**2 for i, m, d_max in ranged],
        [Pair(names[i], names[j]) for i, j, _ in limits.comm_pairs]
        + [Pair(names[i], f"neighbour {m}") for i, m, _ in ranged],
        "plain",
    )
    corridors = [(i, w) for i, w in enumerate(limits.corridors) if np.isfinite(w)]
    add(
        "corridor",
        [
            1
            - squared_distance(
                i, desired[i][models[i].index("north")], desired[i][models[i].index("east")]
            )
            / w**2
            for i, w in corridors
        ],
        [Pair(names[i], "corridor") for i, _ in corridors],
        "hockey",
    )
    add(
        "state_limits",
        [
            1 - (xs[i][model.index(state)] / limit) ** 2
            for i, model in enumerate(models)
            for state, limit in model.state_limits
        ],
        [
            Pair(names[i], state)
            for i, model in enumerate(models)
            for state, _ in model.state_limits
        ],
        "plain",
    )
    return tuple(blocks)
