"""choose_substeps: a stiff linear system with a known answer and the MEDUSA vehicle model."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
import scipy.linalg
from scipy.integrate import solve_ivp

from auvplan.errors import InputError, SolverError
from auvplan.io.vehicles import load_vehicle
from auvplan.optimization import choose_substeps, discretize_rk4
from auvplan.vehicle import build_vehicle_model

A_STIFF = np.array([[-60.0, 5.0], [2.0, -0.4]])  # eigenvalues ≈ -60.2 and -0.23
B_STIFF = np.array([[1.0], [0.5]])


def _stiff_linear() -> ca.Function:
    """``ẋ = A x + B u + p``."""
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p", 2)
    return ca.Function("f", [x, u, p], [A_STIFF @ x + B_STIFF @ u + p])


def _rk4_linear(states, inputs, parameters, dt: float, m: int) -> np.ndarray:
    """Independent oracle: ``m`` RK4 substeps of the linear system as matrix polynomials."""
    m_h = A_STIFF * dt / m
    phi = np.eye(2) + m_h + m_h @ m_h / 2 + m_h @ m_h @ m_h / 6 + m_h @ m_h @ m_h @ m_h / 24
    gamma = dt / m * (np.eye(2) + m_h / 2 + m_h @ m_h / 6 + m_h @ m_h @ m_h / 24)
    forcing = inputs @ B_STIFF.T + parameters
    out = np.array(states, dtype=np.float64)
    for _ in range(m):
        out = out @ phi.T + forcing @ gamma.T
    return out


def test_stiff_linear_system_gets_the_smallest_sufficient_substep_count(
    rng: np.random.Generator,
) -> None:
    dt, tolerance = 0.5, 1e-6
    states, inputs, parameters = (
        rng.normal(size=(5, 2)),
        rng.normal(size=(5, 1)),
        rng.normal(size=(5, 2)),
    )
    chosen = choose_substeps(_stiff_linear(), states, inputs, parameters, dt, tolerance=tolerance)

    def estimate(m: int) -> float:
        difference = _rk4_linear(states, inputs, parameters, dt, m) - _rk4_linear(
            states, inputs, parameters, dt, 2 * m
        )
        return float(np.max(np.linalg.norm(difference, axis=1)))

    # brute force over every m: the smallest one whose estimate meets the tolerance
    assert chosen == min(m for m in range(1, 65) if estimate(m) <= tolerance)
    assert chosen > 9  # RK4 is unstable for h·60 > 2.78: the stiff mode sets m
    # the chosen step is accurate against the exact flow (matrix exponential, u and p held)
    flow = scipy.linalg.expm(A_STIFF * dt)
    forcing = inputs @ B_STIFF.T + parameters
    exact = states @ flow.T + np.linalg.solve(A_STIFF, (flow - np.eye(2)) @ forcing.T).T
    error = np.linalg.norm(_rk4_linear(states, inputs, parameters, dt, chosen) - exact, axis=1)
    assert np.max(error) <= 16 / 15 * tolerance * 1.01
    error_fewer = np.linalg.norm(
        _rk4_linear(states, inputs, parameters, dt, chosen - 1) - exact, axis=1
    )
    assert np.max(error_fewer) > tolerance


def _medusa() -> ca.Function:
    model = build_vehicle_model(load_vehicle("medusa"), propeller_order=3)
    x, c, p = ca.SX.sym("x", 8), ca.SX.sym("c", 2), ca.SX.sym("p", 0)
    return ca.Function("f", [x, c, p], [model.dynamics(x, c)])


def _manoeuvre(dynamics: ca.Function, dt: float, horizon: float = 40.0):
    """From rest: spin up, turn (propeller difference), slow down (DOP853, rtol 1e-10).

    Inputs are held over each ``dt`` and steer the propeller speeds towards a target profile,
    so the trajectory spans rest, spin-up, turns and cruise. Returns the sampled states
    ``(N + 1, 8)``, which are the exact flow of the held inputs ``(N, 2)``.
    """
    n_steps = round(horizon / dt)
    t = np.arange(n_steps) * dt
    knots = [0.0, 10.0, 20.0, 30.0, 40.0]
    targets = np.stack(
        [np.interp(t, knots, [0, 45, 30, 60, 10]), np.interp(t, knots, [0, 45, 60, 30, 10])], 1
    )
    states, inputs = [np.zeros(8)], []
    for k in range(n_steps):
        command = 2.0 * np.clip((targets[k] - states[-1][6:8]) / (150.0 * dt), -3.0, 3.0)
        inputs.append(command)
        solution = solve_ivp(
            lambda _t, y, c=command: np.asarray(dynamics(y, c, np.zeros(0))).ravel(),
            (0.0, dt),
            states[-1],
            method="DOP853",
            rtol=1e-10,
            atol=1e-10,
        )
        states.append(solution.y[:, -1])
    return np.array(states), np.array(inputs)


@pytest.mark.parametrize("dt", [0.5, 1.0, 2.0])
def test_medusa_per_step_position_defect_below_10_mm(dt: float) -> None:
    dynamics = _medusa()
    states, inputs = _manoeuvre(dynamics, dt)
    parameters = np.zeros((inputs.shape[0], 0))
    position = np.zeros(8)
    position[:2] = 1.0
    chosen = choose_substeps(
        dynamics, states[:-1], inputs, parameters, dt, tolerance=5e-3, weights=position
    )
    cost = ca.Function("l", [*dynamics.sx_in()], [0])

    def position_defect(m: int) -> float:
        step = discretize_rk4(dynamics, cost, dt, n_substeps=m).step(
            states[:-1], inputs, parameters
        )
        return float(np.max(np.linalg.norm(step[:, :2] - states[1:, :2], axis=1)))

    assert position_defect(chosen) < 10e-3
    if dt == 2.0:  # one RK4 step of 2 s misses the flow by decimetres
        assert chosen > 1
        assert position_defect(1) > 0.1


def test_rejects_bad_arguments_and_reports_an_unreachable_tolerance() -> None:
    dynamics = _stiff_linear()
    states, inputs, parameters = np.ones((2, 2)), np.zeros((2, 1)), np.zeros((2, 2))
    with pytest.raises(SolverError, match="max_substeps"):
        choose_substeps(dynamics, states, inputs, parameters, 0.5, tolerance=1e-6, max_substeps=8)
    with pytest.raises(InputError, match="tolerance"):
        choose_substeps(dynamics, states, inputs, parameters, 0.5, tolerance=0.0)
    with pytest.raises(InputError, match="weights"):
        choose_substeps(
            dynamics, states, inputs, parameters, 0.5, tolerance=1e-3, weights=np.ones(3)
        )
    with pytest.raises(InputError, match="U"):
        choose_substeps(dynamics, states, np.zeros((3, 1)), parameters, 0.5, tolerance=1e-3)
