r"""The fastest mode of a vehicle, and the largest stable explicit integration step.

Classical RK4 is stable for a linear mode ``ẋ = λ x`` only while ``h λ`` lies in its stability
region, which reaches ``|h λ| ≈ 2.78`` on the negative real axis and ``≈ 2.83`` on the
imaginary axis. Along a trajectory the modes are the eigenvalues of the Jacobian ``∂f/∂x``;
the quadratic damping makes them grow with the body velocities, so a step that is stable in
straight cruise can be unstable during a turn, and an unstable discrete model *amplifies* a mode
that the real vehicle damps. The bound here samples ``∂f/∂x`` over the vehicle's whole
operating envelope (surge from slow astern to top speed, sway, yaw rate up to the steady
maximum, every actuator over its range: propeller speeds up to ``n_max``, control surfaces up
to ``δ_max``) and returns

.. math::

    h_{max} = \frac{\rho_{RK4}}{\max |\lambda(\partial f/\partial x)|}, \qquad
    \rho_{RK4} = 2.5 \;(\text{a margin inside } 2.78).
"""

from __future__ import annotations

import itertools
from functools import cache
from typing import Final

import casadi as ca
import numpy as np

from auvplan.vehicle.dynamics import VehicleModel
from auvplan.vehicle.trim import max_yaw_rate, top_speed

#: Radius |h λ| kept inside RK4's stability region (its real-axis limit is 2.785).
RK4_STABLE_RADIUS: Final = 2.5
#: Samples per axis of the operating envelope.
ENVELOPE_SAMPLES: Final = 5


@cache
def fastest_mode(model: VehicleModel) -> float:
    """Largest eigenvalue modulus [1/s] of ``∂f/∂x`` over the operating envelope.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> from auvplan.vehicle.dynamics import build_vehicle_model
    >>> 4.0 < fastest_mode(build_vehicle_model(load_vehicle("medusa"))) < 10.0
    True
    """
    fastest_u = top_speed(model)
    fastest_r = max_yaw_rate(model)
    axes = {
        "u": np.linspace(-0.3 * fastest_u, 1.05 * fastest_u, ENVELOPE_SAMPLES + 2),
        "v": np.linspace(-0.4 * fastest_u, 0.4 * fastest_u, ENVELOPE_SAMPLES),
        "r": np.linspace(-1.2 * fastest_r, 1.2 * fastest_r, ENVELOPE_SAMPLES),
    }
    for name, limit in model.state_limits:
        axes[name] = np.linspace(-limit, limit, ENVELOPE_SAMPLES)
    points = np.array(list(itertools.product(*axes.values())))
    states = np.zeros((points.shape[0], model.n_x))
    for k, name in enumerate(axes):
        states[:, model.index(name)] = points[:, k]
    x = ca.SX.sym("x", model.n_x)
    c = ca.SX.sym("c", model.n_u)
    jacobian = ca.Function("f_x", [x, c], [ca.jacobian(model.dynamics(x, c), x)])
    batched = jacobian.map(points.shape[0], "serial")
    matrices = np.asarray(batched(states.T, np.zeros((model.n_u, points.shape[0]))))
    stacked = matrices.T.reshape(points.shape[0], model.n_x, model.n_x).transpose(0, 2, 1)
    return float(np.max(np.abs(np.linalg.eigvals(stacked))))


def stable_rk4_step(model: VehicleModel) -> float:
    """Largest RK4 step [s] stable on the whole operating envelope (module notes)."""
    return RK4_STABLE_RADIUS / fastest_mode(model)


__all__ = ["RK4_STABLE_RADIUS", "fastest_mode", "stable_rk4_step"]
