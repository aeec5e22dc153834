"""Planar 3-DOF MEDUSA dynamics as CasADi functions (exact derivatives of any order).

State ``x = (north, east, ψ, u, v, r, n_ps, n_sb)`` [m, m, rad, m/s, m/s, rad/s, rev/s, rev/s],
input ``c = (c_ps, c_sb)`` [-]::

    η̇ = R(ψ) ν,                 R(ψ) = [[cψ, -sψ, 0], [sψ, cψ, 0], [0, 0, 1]]
    M ν̇ + C(ν) ν + (D + D_n(ν)) ν = τ
    M = M_RB + M_A = diag(m - X_u̇, m - Y_v̇, I_z - N_ṙ)
    C(ν) = C_RB(ν) + C_A(ν) = [[0, 0, -m_v v], [0, 0, m_u u], [m_v v, -m_u u, 0]]
    D = -diag(X_u, Y_v, N_r),   D_n = -diag(X_|u|u |u|_ε, Y_|v|v |v|_ε, N_|r|r |r|_ε)
    τ = (T_ps + T_sb, 0, l (T_ps - T_sb))    (port surplus turns the bow to starboard, r > 0)
    v_a,ps = u + l r,  v_a,sb = u - l r     (thrusters at y = ∓l)
    ṅ = w_c tanh(c)

``|s|_ε = sqrt(s² + ε²)`` replaces ``|s|`` and the propellers use the smooth four-quadrant form
of :mod:`auvplan.vehicle.propulsion`, so ``f`` is C^∞ everywhere, including at rest.

Electrical power (SPEC §4): ``P = Σ_i R_a I_i² + K_e ω_i I_i + P_b``, ``ω_i = 2π n_i``.

References
----------
.. [1] T. I. Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed.,
   Wiley 2021, eqs. 2.40, 6.43-6.46, 6.60.
.. [2] A. J. Häusler et al., OCEANS 2013, Sec. II-B (eqs. 1-8), II-C.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import casadi as ca
import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.vehicle.params import VehicleParams
from auvplan.vehicle.propulsion import (
    motor_current_expression,
    motor_power_expression,
    resolve_order,
    smooth_thrust_torque_expression,
)

#: Names of the 8 states, in order.
STATE_NAMES: Final = ("north", "east", "psi", "u", "v", "r", "n_ps", "n_sb")
#: Units of the 8 states, in order.
STATE_UNITS: Final = ("m", "m", "rad", "m/s", "m/s", "rad/s", "rev/s", "rev/s")
#: Names of the 2 inputs, in order (dimensionless propeller-acceleration commands).
INPUT_NAMES: Final = ("c_ps", "c_sb")
N_STATES: Final = 8
N_INPUTS: Final = 2


@dataclass(frozen=True, eq=False)
class VehicleModel:
    """A vehicle's continuous-time model as CasADi functions of SX graphs.

    Compare by identity (``eq=False``); the functions can be composed into larger CasADi
    graphs (RK4 steps, fleets) and differentiated to any order.
    """

    params: VehicleParams
    """The parameter set the functions were built from."""
    propeller_order: int
    """Harmonics of ``C_T*``, ``C_Q*`` used [-]."""
    dynamics: ca.Function
    """``f(x[8], c[2]) -> xdot[8]``, named ``"f"``."""
    power: ca.Function
    """``P(x[8], c[2]) -> P`` electrical power of both motors plus hotel load [W]."""
    thrust_torque: ca.Function
    """``(x[8]) -> (T_ps, T_sb, Q_ps, Q_sb)`` [N, N, N m, N m]."""
    current: ca.Function
    """``(x[8]) -> (I_ps, I_sb)`` motor currents [A]."""
    state_names: tuple[str, ...] = STATE_NAMES
    """Names of the states, in order (the first three are the pose ``north, east, psi``)."""
    input_names: tuple[str, ...] = INPUT_NAMES
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

    @property
    def state_limits(self) -> tuple[tuple[str, float], ...]:
        """States with a symmetric bound ``|x| <= limit``: the propeller speeds [rev/s]."""
        return (("n_ps", self.params.n_max), ("n_sb", self.params.n_max))


def _smooth_abs(value: ca.SX, eps: float) -> ca.SX:
    return ca.sqrt(value**2 + eps**2)


def build_vehicle_model(
    params: VehicleParams, *, propeller_order: int | None = None
) -> VehicleModel:
    """Build the CasADi dynamics, power and thrust functions of one vehicle.

    Parameters
    ----------
    params : VehicleParams
        Vehicle type.
    propeller_order : int, optional
        Harmonics of the four-quadrant series; ``None`` uses ``params.propeller.order`` or
        the full table (order 30 for the Roddy series). A small integer gives the low-order
        (truncated, least-squares optimal) approximation.

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
    order = resolve_order(params.propeller, propeller_order)
    hull = params.hull
    x = ca.SX.sym("x", N_STATES)
    c = ca.SX.sym("c", N_INPUTS)
    psi, u, v, r, n_ps, n_sb = x[2], x[3], x[4], x[5], x[6], x[7]

    thrust_ps, torque_ps = smooth_thrust_torque_expression(
        u + params.l * r,
        n_ps,
        params.propeller,
        hull.rho,
        order=order,
        eps_inflow=params.eps_inflow,
    )
    thrust_sb, torque_sb = smooth_thrust_torque_expression(
        u - params.l * r,
        n_sb,
        params.propeller,
        hull.rho,
        order=order,
        eps_inflow=params.eps_inflow,
    )
    tau = ca.vertcat(thrust_ps + thrust_sb, 0.0, params.l * (thrust_ps - thrust_sb))

    m_u, m_v, m_r = hull.m_u, hull.m_v, hull.m_r
    nu = ca.vertcat(u, v, r)
    coriolis = ca.vertcat(
        ca.horzcat(0.0, 0.0, -m_v * v),
        ca.horzcat(0.0, 0.0, m_u * u),
        ca.horzcat(m_v * v, -m_u * u, 0.0),
    )
    damping = ca.vertcat(
        -hull.X_u - hull.X_uu * _smooth_abs(u, params.eps_abs_speed),
        -hull.Y_v - hull.Y_vv * _smooth_abs(v, params.eps_abs_speed),
        -hull.N_r - hull.N_rr * _smooth_abs(r, params.eps_abs_rate),
    )
    nu_dot = (tau - ca.mtimes(coriolis, nu) - damping * nu) / ca.vertcat(m_u, m_v, m_r)
    eta_dot = ca.vertcat(u * ca.cos(psi) - v * ca.sin(psi), u * ca.sin(psi) + v * ca.cos(psi), r)
    n_dot = params.w_c * ca.tanh(c)
    xdot = ca.vertcat(eta_dot, nu_dot, n_dot)

    current_ps = motor_current_expression(
        torque_ps, n_ps, params.motor, eps_sign_n=params.eps_sign_n
    )
    current_sb = motor_current_expression(
        torque_sb, n_sb, params.motor, eps_sign_n=params.eps_sign_n
    )
    power = (
        motor_power_expression(current_ps, n_ps, params.motor)
        + motor_power_expression(current_sb, n_sb, params.motor)
        + params.hotel_power
    )
    return VehicleModel(
        params=params,
        propeller_order=order,
        dynamics=ca.Function("f", [x, c], [xdot], ["x", "c"], ["xdot"]),
        power=ca.Function("power", [x, c], [power], ["x", "c"], ["P"]),
        thrust_torque=ca.Function(
            "thrust_torque",
            [x],
            [thrust_ps, thrust_sb, torque_ps, torque_sb],
            ["x"],
            ["T_ps", "T_sb", "Q_ps", "Q_sb"],
        ),
        current=ca.Function("current", [x], [current_ps, current_sb], ["x"], ["I_ps", "I_sb"]),
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
    states : ndarray of shape (n_t, 8)
        States (SI units, rev/s for the propellers).
    inputs : ndarray of shape (n_t, 2)
        Inputs ``c`` [-].
    model : VehicleModel
        Model from :func:`build_vehicle_model`.

    Returns
    -------
    ndarray of shape (n_t, 8)
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
    mapped = model.dynamics.map(n_t)
    result = mapped(np.asarray(states, dtype=np.float64).T, np.asarray(inputs, dtype=np.float64).T)
    return np.asarray(result, dtype=np.float64).T.reshape(n_t, model.n_x)


def electrical_power(states: FloatArray, inputs: FloatArray, model: VehicleModel) -> FloatArray:
    """Electrical power drawn from the battery at every grid point (batched) [W].

    Parameters
    ----------
    states : ndarray of shape (n_t, 8)
        States.
    inputs : ndarray of shape (n_t, 2)
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
    mapped = model.power.map(n_t)
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
    states : ndarray of shape (n_t, 8)
        States.
    inputs : ndarray of shape (n_t, 2)
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
    "N_INPUTS",
    "N_STATES",
    "STATE_NAMES",
    "STATE_UNITS",
    "VehicleModel",
    "build_vehicle_model",
    "electrical_power",
    "energy",
    "vessel_dynamics",
]
