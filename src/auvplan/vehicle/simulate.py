"""Simulation of the vehicle model: fixed-step RK4 (the optimiser's grid) and an adaptive reference.

Inputs are held constant over each step (zero-order hold), as in the optimiser's
discretisation. The RK4 step ``F(x, c) = x + dt/6 (k1 + 2 k2 + 2 k3 + k4)`` is one CasADi
function, so its Jacobians and Hessians are exact; a whole trajectory is one
``Function.mapaccum`` call (no Python loop per step).
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

import casadi as ca
import numpy as np
from scipy.integrate import solve_ivp

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.vehicle.dynamics import VehicleModel

#: A control law ``c(t)`` for the adaptive simulation: time [s] -> inputs of shape (n_u,).
ControlLaw = Callable[[float], FloatArray]


def _check_step(dt: float) -> float:
    if not np.isfinite(dt) or dt <= 0.0:
        raise InputError(f"time step dt must be > 0, got {dt!r}")
    return float(dt)


@lru_cache(maxsize=64)
def rk4_step_function(model: VehicleModel, dt: float) -> ca.Function:
    """One classical Runge-Kutta step of ``ẋ = f(x, c)`` with ``c`` held constant.

    Parameters
    ----------
    model : VehicleModel
        Continuous model.
    dt : float
        Step [s].

    Returns
    -------
    casadi.Function
        ``"F"(x[n_x], c[n_u]) -> x_next[n_x]``, an SX graph (exact derivatives).

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> step = rk4_step_function(build_vehicle_model(load_vehicle("medusa")), 0.5)
    >>> round(float(step([0, 0, 0, 1.0, 0, 0, 50.0, 50.0], [0, 0])[0]), 3)
    0.499
    """
    dt = _check_step(dt)
    x = ca.SX.sym("x", model.n_x)
    c = ca.SX.sym("c", model.n_u)
    f = model.dynamics
    k1 = f(x, c)
    k2 = f(x + 0.5 * dt * k1, c)
    k3 = f(x + 0.5 * dt * k2, c)
    k4 = f(x + dt * k3, c)
    x_next = x + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return ca.Function("F", [x, c], [x_next], ["x", "c"], ["x_next"])


@lru_cache(maxsize=64)
def _rk4_rollout(model: VehicleModel, dt: float, n_steps: int) -> ca.Function:
    return rk4_step_function(model, dt).mapaccum("rollout", n_steps)


def _initial_state(model: VehicleModel, x0: FloatArray) -> FloatArray:
    state = np.asarray(x0, dtype=np.float64)
    if state.shape != (model.n_x,) or not np.all(np.isfinite(state)):
        raise InputError(f"initial state must be finite with shape ({model.n_x},), got {state!r}")
    return state


def rk4_simulate(model: VehicleModel, x0: FloatArray, inputs: FloatArray, dt: float) -> FloatArray:
    """Simulate with fixed-step RK4 and zero-order-hold inputs.

    Parameters
    ----------
    model : VehicleModel
        Continuous model.
    x0 : ndarray of shape (n_x,)
        Initial state.
    inputs : ndarray of shape (N, n_u)
        Input ``c_k`` held on ``[k dt, (k + 1) dt)``.
    dt : float
        Step [s].

    Returns
    -------
    ndarray of shape (N + 1, n_x)
        States at ``t_k = k dt``, ``k = 0..N``.

    Raises
    ------
    InputError
        On bad shapes or a non-positive step.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> model = build_vehicle_model(load_vehicle("medusa"))
    >>> rk4_simulate(model, np.zeros(8), np.ones((4, 2)), 0.5).shape
    (5, 8)
    """
    state = _initial_state(model, x0)
    controls = np.asarray(inputs, dtype=np.float64)
    if controls.ndim != 2 or controls.shape[1] != model.n_u or controls.shape[0] == 0:
        raise InputError(f"inputs must have shape (N, {model.n_u}), got {controls.shape}")
    rollout = _rk4_rollout(model, _check_step(dt), controls.shape[0])
    trajectory = np.asarray(rollout(state, controls.T), dtype=np.float64).T
    return np.vstack([state[np.newaxis, :], trajectory])


class SimulationStatus(enum.Enum):
    """Outcome of an adaptive simulation."""

    SUCCESS = "success"
    FAILED = "failed"


@dataclass(frozen=True)
class AdaptiveSimulation:
    """Result of :func:`simulate_adaptive`."""

    time: FloatArray
    """Sample times, shape ``(n_t,)`` [s]."""
    states: FloatArray
    """States at ``time``, shape ``(n_t, n_x)``."""
    status: SimulationStatus
    """Whether every integration interval succeeded."""
    message: str
    """The integrator's message (first failure, if any)."""
    n_evaluations: int
    """Number of right-hand-side evaluations [-]."""

    @property
    def success(self) -> bool:
        """``status is SimulationStatus.SUCCESS``."""
        return self.status is SimulationStatus.SUCCESS


def simulate_adaptive(
    model: VehicleModel,
    x0: FloatArray,
    control: FloatArray | ControlLaw,
    t_span: tuple[float, float],
    *,
    t_eval: FloatArray | None = None,
    rtol: float = 1e-10,
    atol: float = 1e-10,
) -> AdaptiveSimulation:
    """Reference simulation with scipy's adaptive ``solve_ivp`` (DOP853, tight tolerances).

    Parameters
    ----------
    model : VehicleModel
        Continuous model.
    x0 : ndarray of shape (n_x,)
        Initial state.
    control : ndarray of shape (N, n_u) or callable
        Either inputs held constant on ``N`` equal intervals of ``t_span`` (the integrator
        restarts at each interval boundary, so the discontinuities are resolved exactly and
        the samples are the ``N + 1`` grid times), or a law ``c(t)`` (one integration; samples
        at ``t_eval`` or at the solver's steps).
    t_span : (float, float)
        Start and end time [s].
    t_eval : ndarray, optional
        Sample times for a control law (ignored for input arrays).
    rtol, atol : float
        Integrator tolerances.

    Returns
    -------
    AdaptiveSimulation

    Raises
    ------
    InputError
        On bad shapes or an empty time span.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> model = build_vehicle_model(load_vehicle("medusa"))
    >>> result = simulate_adaptive(model, np.zeros(8), np.ones((2, 2)), (0.0, 1.0))
    >>> result.success, result.states.shape
    (True, (3, 8))
    """
    state = _initial_state(model, x0)
    t_start, t_end = float(t_span[0]), float(t_span[1])
    if not t_end > t_start:
        raise InputError(f"t_span must be increasing, got {t_span!r}")
    evaluations = 0

    def rhs_with(law: Callable[[float], FloatArray]) -> Callable[[float, FloatArray], FloatArray]:
        def rhs(t: float, x: FloatArray) -> FloatArray:
            nonlocal evaluations
            evaluations += 1
            return np.asarray(model.dynamics(x, law(t)), dtype=np.float64).ravel()

        return rhs

    if callable(control):
        solution = solve_ivp(
            rhs_with(control),
            (t_start, t_end),
            state,
            method="DOP853",
            t_eval=t_eval,
            rtol=rtol,
            atol=atol,
        )
        status = SimulationStatus.SUCCESS if solution.success else SimulationStatus.FAILED
        return AdaptiveSimulation(
            time=np.asarray(solution.t, dtype=np.float64),
            states=np.asarray(solution.y, dtype=np.float64).T,
            status=status,
            message=str(solution.message),
            n_evaluations=evaluations,
        )

    controls = np.asarray(control, dtype=np.float64)
    if controls.ndim != 2 or controls.shape[1] != model.n_u or controls.shape[0] == 0:
        raise InputError(f"inputs must have shape (N, {model.n_u}), got {controls.shape}")
    time = np.linspace(t_start, t_end, controls.shape[0] + 1)
    states = np.empty((time.size, model.n_x))
    states[0] = state
    status, message = SimulationStatus.SUCCESS, "all intervals integrated"
    for k, held in enumerate(controls):

        def hold(_t: float, value: FloatArray = held) -> FloatArray:
            return value

        solution = solve_ivp(
            rhs_with(hold),
            (time[k], time[k + 1]),
            states[k],
            method="DOP853",
            rtol=rtol,
            atol=atol,
        )
        states[k + 1] = solution.y[:, -1]
        if not solution.success and status is SimulationStatus.SUCCESS:
            status, message = SimulationStatus.FAILED, f"interval {k}: {solution.message}"
    return AdaptiveSimulation(
        time=time, states=states, status=status, message=message, n_evaluations=evaluations
    )


__all__ = [
    "AdaptiveSimulation",
    "ControlLaw",
    "SimulationStatus",
    "rk4_simulate",
    "rk4_step_function",
    "simulate_adaptive",
]
