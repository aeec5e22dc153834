"""The RK4 step bound: stable for every mode met inside the operating envelope."""

from __future__ import annotations

import numpy as np
import pytest

from auvplan.io.vehicles import load_vehicle
from auvplan.vehicle import VehicleModel, build_vehicle_model, max_yaw_rate, top_speed
from auvplan.vehicle.stiffness import fastest_mode, stable_rk4_step


def _rk4_amplification(z: np.ndarray) -> np.ndarray:
    return np.abs(1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24)


def _jacobian_fd(model: VehicleModel, x: np.ndarray, step: float = 1e-6) -> np.ndarray:
    columns = []
    for k in range(x.size):
        dx = np.zeros_like(x)
        dx[k] = step
        plus = np.asarray(model.dynamics(x + dx, np.zeros(model.n_u))).ravel()
        minus = np.asarray(model.dynamics(x - dx, np.zeros(model.n_u))).ravel()
        columns.append((plus - minus) / (2 * step))
    return np.column_stack(columns)


@pytest.mark.parametrize("order", [3, None])
def test_step_bound_keeps_every_damped_mode_stable(order: int | None) -> None:
    model = build_vehicle_model(load_vehicle("medusa"), propeller_order=order)
    h = stable_rk4_step(model)
    assert 0.3 < h < 0.6  # ~0.44 s for MEDUSA: the fast sway-yaw mode at speed
    rng = np.random.default_rng(3)
    u_max, r_max, n_max = top_speed(model), max_yaw_rate(model), model.params.n_max
    largest = 0.0
    for _ in range(60):  # random points inside the envelope, not the sampling grid
        x = np.zeros(model.n_x)
        x[model.index("u")] = rng.uniform(-0.3 * u_max, u_max)
        x[model.index("v")] = rng.uniform(-0.4 * u_max, 0.4 * u_max)
        x[model.index("r")] = rng.uniform(-1.2 * r_max, 1.2 * r_max)
        x[model.index("n_ps")], x[model.index("n_sb")] = rng.uniform(-n_max, n_max, 2)
        eigenvalues = np.linalg.eigvals(_jacobian_fd(model, x))
        largest = max(largest, float(np.max(np.abs(eigenvalues))))
        damped = eigenvalues[eigenvalues.real <= 0.0]
        assert np.all(_rk4_amplification(h * damped) <= 1.0 + 1e-9)
    assert largest <= fastest_mode(model) * (1 + 1e-6)
    # the bound is not loose: twice the step leaves RK4's stability region somewhere
    assert largest * 2 * h > 2.785
