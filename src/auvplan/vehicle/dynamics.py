"""Planar 3-DOF vehicle dynamics as CasADi functions (exact derivatives of any order).

State ``x = (north, east, ψ, u, v, r, n_<thruster>…, delta_<surface>…)`` [m, m, rad, m/s,
m/s, rad/s, rev/s…, rad…], input ``c = (c_<thruster>…, c_<surface>…)`` [-], the actuators in
the order of :class:`auvplan.vehicle.actuators.ActuatedVehicleParams`::

    η̇ = R(ψ) ν,                 R(ψ) = [[cψ, -sψ, 0], [sψ, cψ, 0], [0, 0, 1]]
    M ν̇ + C(ν) ν + (D(ν) + D_n(ν)) ν = τ_thrusters + τ_surfaces + τ_crossflow
    M = M_RB + M_A = diag(m - X_u̇, m - Y_v̇, I_z - N_ṙ)
    C(ν) = [[0, 0, -m_v v], [0, 0, m_u u], [m_v v, -m_u u, 0]]   (C_RB + C_A; m_u = m_v = m
                                                                  when C_A is left out)
    D = -diag(X_u f, Y_v f, N_r),  f = exp(-κ U),  U = sqrt(u² + v² + ε²)
    D_n = -diag(X_|u|u |u|_ε, Y_|v|v |v|_ε, N_|r|r |r|_ε)
    thruster i at (x, y), axis α:  v_a = (1 - w) (cα (u - y r) + sα (v + x r)),
                                   τ_i = (1 - t) T_i (cα, sα, x sα - y cα)
    surface j at (x, y):           q = ½ρ(u² + v²)A,  Y = -q C_Lδ δ,  X = -q C_Dδ δ²,
                                   τ_j = (X, Y, x Y - y X)
    ṅ_i = w_c,i tanh(c_i),  δ̇_j = w_δ,j tanh(c_j)

For the twin-thruster MEDUSA layout (``y = ∓l``) this is ``τ = (T_ps + T_sb, 0, l (T_ps -
T_sb))`` with ``v_a,ps = u + l r``, ``v_a,sb = u - l r``: port surplus turns the bow to
starboard (r > 0). ``|s|_ε = sqrt(s² + ε²)`` replaces ``|s|`` and the propellers use the smooth
forms of :mod:`auvplan.vehicle.propulsion`, so ``f`` is C^∞ everywhere, including at rest.

Electrical power (SPEC §4): ``P = Σ_i R_a I_i² + K_e ω_i I_i + P_b``, ``ω_i = 2π n_i``.

References
----------
.. [1] T. I. Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed.,
   Wiley 2021, eqs. 2.40, 6.43-6.46, 6.60, ch. 9.
.. [2] A. J. Häusler et al., OCEANS 2013, Sec. II-B (eqs. 1-8), II-C.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Final

import casadi as ca
import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.vehicle._forces import (
    advance_speed,
    crossflow_force,
    hull_damping,
    surface_force,
    thruster_force,
)
from auvplan.vehicle.actuators import ActuatedVehicleParams, actuated_vehicle
from auvplan.vehicle.params import PropellerParams, VehicleParams
from auvplan.vehicle.propulsion import (
    motor_current_expression,
    motor_power_expression,
    resolve_order,
    thrust_torque_expression,
)

#: Names of the pose and body-velocity states every vehicle starts with, in order.
BODY_STATE_NAMES: Final = ("north", "east", "psi", "u", "v", "r")
#: Names of the 8 states of the twin-thruster (MEDUSA) layout, in order.
STATE_NAMES: Final = (*BODY_STATE_NAMES, "n_ps", "n_sb")
#: Units of the 8 states of the twin-thruster layout, in order.
STATE_UNITS: Final = ("m", "m", "rad", "m/s", "m/s", "rad/s", "rev/s", "rev/s")
#: Names of the 2 inputs of the twin-thruster layout (dimensionless propeller commands).
INPUT_NAMES: Final = ("c_ps", "c_sb")


@dataclass(frozen=True, eq=False)
class VehicleModel:
    """A vehicle's continuous-time model as CasADi functions of SX graphs.

    Compare by identity (``eq=False``); the functions can be composed into larger CasADi
    graphs (RK4 steps, fleets) and differentiated to any order.
    """

    params: VehicleParams | ActuatedVehicleParams
    """The parameter set the functions were built from (as loaded)."""
    vehicle: ActuatedVehicleParams
    """The same vehicle as a hull and a list of actuators (the twin shorthand expanded)."""
    propeller_order: int
    """Harmonics of the four-quadrant ``C_T*``, ``C_Q*`` used (0 without such propellers) [-]."""
    dynamics: ca.Function
    """``f(x[n_x], c[n_u]) -> xdot[n_x]``, named ``"f"``."""
    power: ca.Function
    """``P(x, c) -> P`` electrical power of all motors plus hotel load [W]."""
    thrust_torque: ca.Function
    """``(x) -> (T_<thruster>…, Q_<thruster>…)`` [N…, N m…]."""
    current: ca.Function
    """``(x) -> (I_<thruster>…)`` motor currents [A]."""
    state_names: tuple[str, ...]
    """Names of the states, in order (the first six are ``north, east, psi, u, v, r``)."""
    input_names: tuple[str, ...]
    """Names of the inputs, in order."""

    @property
    def n_x(self) -> int:
        """Number of states [-]."""
        return len(self.state_names)

    @property
    def n_u(self) -> int:
        """Number of inputs [-]."""
        return len(self.input_names)

    def index(self, name: str) -> int:
        """Position of the state called ``name`` in the state vector.

        Examples
        --------
        >>> from auvplan.io.vehicles import load_vehicle
        >>> build_vehicle_model(load_vehicle("medusa")).index("u")
        3
        """
        return self.state_names.index(name)

    @cached_property
    def dynamics_in_current(self) -> ca.Function:
        r"""``f(x[n_x], c[n_u], v_c[2]) -> xdot[n_x]`` in a current, named ``"f_current"``.

        ``u, v, r`` are the velocities through the water ``ν_r = ν − ν_c``: drag, propeller
        inflow, control-surface lift and power see them (Fossen 2021, Sec. 10.3, for an
        irrotational current whose acceleration is negligible), and the position moves with
        the water, ``(ṅ, ė) = R(ψ) (u, v) + v_c`` with ``v_c = (v_N, v_E)`` [m/s] over ground.
        With ``v_c = 0`` it is :attr:`dynamics`.

        Examples
        --------
        >>> from auvplan.io.vehicles import load_vehicle
        >>> model = build_vehicle_model(load_vehicle("medusa"))
        >>> xdot = model.dynamics_in_current([0, 0, 0, 0.5, 0, 0, 40.0, 40.0], [0, 0], [-0.5, 0.1])
        >>> np.asarray(xdot).ravel()[:2].round(6).tolist()
        [0.0, 0.1]
        """
        x, c = ca.SX.sym("x", self.n_x), ca.SX.sym("c", self.n_u)
        current = ca.SX.sym("v_c", 2)
        drift = ca.SX.zeros(self.n_x)
        drift[self.index("north")] = current[0]
        drift[self.index("east")] = current[1]
        return ca.Function(
            "f_current", [x, c, current], [self.dynamics(x, c) + drift], ["x", "c", "v_c"], ["xdot"]
        )

    @property
    def thruster_states(self) -> tuple[str, ...]:
        """Names of the propeller-speed states ``n_<thruster>``, in state order [-]."""
        return tuple(thruster.state_name for thruster in self.vehicle.thrusters)

    @property
    def surface_states(self) -> tuple[str, ...]:
        """Names of the control-surface deflection states ``delta_<surface>`` [-]."""
        return tuple(surface.state_name for surface in self.vehicle.surfaces)

    @property
    def state_units(self) -> tuple[str, ...]:
        """Units of the states, in order.

        Examples
        --------
        >>> from auvplan.io.vehicles import load_vehicle
        >>> build_vehicle_model(load_vehicle("remus100")).state_units[6:]
        ('rev/s', 'rad')
        """
        return (
            *STATE_UNITS[: len(BODY_STATE_NAMES)],
            *("rev/s" for _ in self.vehicle.thrusters),
            *("rad" for _ in self.vehicle.surfaces),
        )

    @property
    def state_limits(self) -> tuple[tuple[str, float], ...]:
        """States with a symmetric bound ``|x| <= limit``, in state order.

        Propeller speeds [rev/s] and control-surface deflections [rad].
        """
        return tuple(
            [(thruster.state_name, thruster.n_max) for thruster in self.vehicle.thrusters]
            + [(surface.state_name, surface.delta_max) for surface in self.vehicle.surfaces]
        )


def _propeller_order(vehicle: ActuatedVehicleParams, order: int | None) -> tuple[int, ...]:
    return tuple(resolve_order(thruster.propeller, order) for thruster in vehicle.thrusters)


def build_vehicle_model(
    params: VehicleParams | ActuatedVehicleParams, *, propeller_order: int | None = None
) -> VehicleModel:
    """Build the CasADi dynamics, power and thrust functions of one vehicle.

    Parameters
    ----------
    params : VehicleParams or ActuatedVehicleParams
        Vehicle type (the twin shorthand or any actuator layout).
    propeller_order : int, optional
        Harmonics of the four-quadrant series; ``None`` uses ``propeller.order`` or the full
        table (order 30 for the Roddy series). A small integer gives the low-order (truncated,
        least-squares optimal) approximation. Propellers without harmonics accept only 0.

    Returns
    -------
    VehicleModel

    Raises
    ------
    InputError
        If ``propeller_order`` is outside ``[0, K]``.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> model = build_vehicle_model(load_vehicle("medusa"))
    >>> xdot = model.dynamics([0, 0, 0, 1.0, 0, 0, 50.0, 50.0], [0, 0])
    >>> xdot.shape, round(float(xdot[0]), 6)
    ((8, 1), 1.0)
    """
    vehicle = actuated_vehicle(params)
    orders = _propeller_order(vehicle, propeller_order)
    hull = vehicle.hull
    thrusters, surfaces = vehicle.thrusters, vehicle.surfaces
    state_names = (
        *BODY_STATE_NAMES,
        *(thruster.state_name for thruster in thrusters),
        *(surface.state_name for surface in surfaces),
    )
    input_names = (
        *(thruster.input_name for thruster in thrusters),
        *(surface.input_name for surface in surfaces),
    )
    x = ca.SX.sym("x", len(state_names))
    c = ca.SX.sym("c", len(input_names))
    psi, nu = x[2], x[3:6]
    speeds = [x[6 + i] for i in range(len(thrusters))]
    deflections = [x[6 + len(thrusters) + j] for j in range(len(surfaces))]

    thrusts, torques = [], []
    for thruster, n, order in zip(thrusters, speeds, orders, strict=True):
        thrust, torque = thrust_torque_expression(
            advance_speed(thruster, nu),
            n,
            thruster.propeller,
            hull.rho,
            order=order,
            eps_inflow=vehicle.eps_inflow,
            eps_n=vehicle.eps_sign_n,
        )
        thrusts.append(thrust)
        torques.append(torque)
    forces = [thruster_force(t, thrust) for t, thrust in zip(thrusters, thrusts, strict=True)]
    tau = ca.vertcat(*(sum(component[k] for component in forces) for k in range(3)))
    for surface, delta in zip(surfaces, deflections, strict=True):
        tau += surface_force(surface, hull.rho, nu, delta)
    tau += crossflow_force(hull, vehicle.eps_abs_speed, nu)

    m_u, m_v = hull.coriolis_masses
    u, v = nu[0], nu[1]
    coriolis = ca.vertcat(
        ca.horzcat(0.0, 0.0, -m_v * v),
        ca.horzcat(0.0, 0.0, m_u * u),
        ca.horzcat(m_v * v, -m_u * u, 0.0),
    )
    damping = hull_damping(hull, vehicle, nu)
    nu_dot = (tau - ca.mtimes(coriolis, nu) - damping * nu) / ca.vertcat(
        hull.m_u, hull.m_v, hull.m_r
    )
    eta_dot = ca.vertcat(
        u * ca.cos(psi) - v * ca.sin(psi), u * ca.sin(psi) + v * ca.cos(psi), nu[2]
    )
    rates = [
        actuator_rate * ca.tanh(c[k])
        for k, actuator_rate in enumerate(
            [t.w_c for t in thrusters] + [s.rate_max for s in surfaces]
        )
    ]
    xdot = ca.vertcat(eta_dot, nu_dot, *rates)

    currents = [
        motor_current_expression(torque, n, thruster.motor, eps_sign_n=vehicle.eps_sign_n)
        for thruster, torque, n in zip(thrusters, torques, speeds, strict=True)
    ]
    power = vehicle.hotel_power + sum(
        motor_power_expression(current, n, thruster.motor)
        for thruster, current, n in zip(thrusters, currents, speeds, strict=True)
    )
    names = [thruster.name for thruster in thrusters]
    return VehicleModel(
        params=params,
        vehicle=vehicle,
        propeller_order=next(
            (
                k
                for t, k in zip(thrusters, orders, strict=True)
                if isinstance(t.propeller, PropellerParams)
            ),
            0,
        ),
        dynamics=ca.Function("f", [x, c], [xdot], ["x", "c"], ["xdot"]),
        power=ca.Function("power", [x, c], [power], ["x", "c"], ["P"]),
        thrust_torque=ca.Function(
            "thrust_torque",
            [x],
            [*thrusts, *torques],
            ["x"],
            [*(f"T_{name}" for name in names), *(f"Q_{name}" for name in names)],
        ),
        current=ca.Function("current", [x], currents, ["x"], [f"I_{name}" for name in names]),
        state_names=state_names,
        input_names=input_names,
    )


def _as_grid(states: FloatArray, inputs: FloatArray, model: VehicleModel) -> tuple[int, ...]:
    states = np.asarray(states)
    inputs = np.asarray(inputs)
    if states.ndim != 2 or states.shape[1] != model.n_x:
        raise InputError(f"states must have shape (n_t, {model.n_x}), got {states.shape}")
    if inputs.shape != (states.shape[0], model.n_u):
        raise InputError(
            f"inputs must have shape ({states.shape[0]}, {model.n_u}), got {inputs.shape}"
        )
    return tuple(states.shape)


def vessel_dynamics(states: FloatArray, inputs: FloatArray, model: VehicleModel) -> FloatArray:
    """Evaluate ``ẋ = f(x, c)`` on a whole time grid in one batched CasADi call.

    Parameters
    ----------
    states : ndarray of shape (n_t, n_x)
        States (SI units, rev/s for the propellers).
    inputs : ndarray of shape (n_t, n_u)
        Inputs ``c`` [-].
    model : VehicleModel
        Model from :func:`build_vehicle_model`.

    Returns
    -------
    ndarray of shape (n_t, n_x)
        State derivatives.

    Raises
    ------
    InputError
        On mismatched shapes.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> model = build_vehicle_model(load_vehicle("medusa"))
    >>> vessel_dynamics(np.zeros((3, 8)), np.zeros((3, 2)), model).shape
    (3, 8)
    """
    n_t, _ = _as_grid(states, inputs, model)
    mapped = model.dynamics.map(n_t, "serial")
    result = mapped(np.asarray(states, dtype=np.float64).T, np.asarray(inputs, dtype=np.float64).T)
    return np.asarray(result, dtype=np.float64).T.reshape(n_t, model.n_x)


def electrical_power(states: FloatArray, inputs: FloatArray, model: VehicleModel) -> FloatArray:
    """Electrical power drawn from the battery at every grid point (batched) [W].

    Parameters
    ----------
    states : ndarray of shape (n_t, n_x)
        States.
    inputs : ndarray of shape (n_t, n_u)
        Inputs (the power does not depend on them; kept for the optimiser's signature).
    model : VehicleModel
        Model.

    Returns
    -------
    ndarray of shape (n_t,)
        ``P = Σ_i R_a I_i² + K_e 2π n_i I_i + P_b`` [W].

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> model = build_vehicle_model(load_vehicle("medusa"))
    >>> electrical_power(np.zeros((2, 8)), np.zeros((2, 2)), model).tolist()
    [40.0, 40.0]
    """
    n_t, _ = _as_grid(states, inputs, model)
    mapped = model.power.map(n_t, "serial")
    result = mapped(np.asarray(states, dtype=np.float64).T, np.asarray(inputs, dtype=np.float64).T)
    return np.asarray(result, dtype=np.float64).reshape(n_t)


def energy(time: FloatArray, states: FloatArray, inputs: FloatArray, model: VehicleModel) -> float:
    """Electrical energy ``E = ∫ P dt`` by the trapezoidal rule on the given grid [J].

    ``E = Σ_k ½ (P_k + P_{k+1}) (t_{k+1} - t_k)`` with ``P_k = P(x_k, c_k)``. For
    zero-order-hold inputs with one input fewer than states, pass the inputs padded with
    the last one (the power depends only on the state).

    Parameters
    ----------
    time : ndarray of shape (n_t,)
        Strictly increasing times [s].
    states : ndarray of shape (n_t, n_x)
        States.
    inputs : ndarray of shape (n_t, n_u)
        Inputs.
    model : VehicleModel
        Model.

    Returns
    -------
    float
        Energy [J].

    Raises
    ------
    InputError
        If ``time`` does not match ``states`` or is not increasing.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> model = build_vehicle_model(load_vehicle("medusa"))
    >>> energy(np.array([0.0, 10.0]), np.zeros((2, 8)), np.zeros((2, 2)), model)
    400.0
    """
    time = np.asarray(time, dtype=np.float64)
    if time.ndim != 1 or time.size != np.asarray(states).shape[0]:
        raise InputError(f"time must have shape ({np.asarray(states).shape[0]},), got {time.shape}")
    if np.any(np.diff(time) <= 0.0):
        raise InputError("time must be strictly increasing")
    power = electrical_power(states, inputs, model)
    return float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(time)))


__all__ = [
    "INPUT_NAMES",
    "STATE_NAMES",
    "STATE_UNITS",
    "VehicleModel",
    "build_vehicle_model",
    "electrical_power",
    "energy",
    "vessel_dynamics",
]
