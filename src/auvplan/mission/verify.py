r"""Independent checks of an optimised plan: flying it with its tracking regulator.

The MEDUSA hull is directionally unstable in open loop (with DSOR's parameters the
linearised sway-yaw dynamics at 0.7 m/s have an eigenvalue of about +0.03 1/s, an e-folding
time of ~30 s), so replaying the optimal inputs open loop diverges from *any* integrator's
trajectory within minutes; a real vehicle flies the plan with a tracking controller. PRONTO
provides one: the projection regulator ``K_k`` of its last iteration. The replay here is that
digital controller sampled at the solver's rate,

.. math::

    c(t) = \mu_k + K_k (\alpha_k - x(t_k)), \qquad t \in [t_k, t_{k+1}),

with the plant integrated by RK4 on a grid ``refinement`` times finer than the solver's (the
vehicle's compiled model kernels, :mod:`auvplan.optimization.block_kernels`).
Because the plan is a trajectory of the solver's discrete dynamics, the replay differs from
it only by the integration error of the coarse grid, kept small by the feedback.
"""

from __future__ import annotations

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.mission.fleet import current_parameters, vehicle_stage_functions
from auvplan.ocean import CurrentField
from auvplan.optimization import block_kernels
from auvplan.vehicle import VehicleModel


def replay_closed_loop(
    model: VehicleModel,
    states: FloatArray,
    inputs: FloatArray,
    gains: FloatArray,
    dt: float,
    *,
    refinement: int = 10,
    current: CurrentField | None = None,
) -> FloatArray:
    """Fly a planned trajectory with its sampled tracking regulator on a finer grid.

    Parameters
    ----------
    model : VehicleModel
        The vehicle model the plan was optimised with.
    states : ndarray of shape (N + 1, 8)
        Planned states ``α_k``.
    inputs : ndarray of shape (N, 2)
        Planned inputs ``μ_k``.
    gains : ndarray of shape (N, 2, 8)
        Regulator gains ``K_k``.
    dt : float
        Solver step [s].
    refinement : int
        Integration sub-steps per solver step.
    current : CurrentField, optional
        The ocean current (None: still water), linearised on each step about the planned
        position at its start, as the optimiser sees it
        (:func:`auvplan.mission.fleet.current_parameters`).

    Returns
    -------
    ndarray of shape (N * refinement + 1, 8)
        The flown states on the fine grid ``t = j dt / refinement``.
    """
    n_steps = inputs.shape[0]
    if states.shape != (n_steps + 1, model.n_x) or gains.shape != (n_steps, model.n_u, model.n_x):
        raise InputError(
            f"inconsistent plan shapes: states {states.shape}, inputs {inputs.shape}, "
            f"gains {gains.shape}"
        )
    kernels = block_kernels(*vehicle_stage_functions(model, has_current=current is not None))
    parameters = np.zeros((n_steps, model.n_x))
    if current is not None:
        time = dt * np.arange(n_steps, dtype=np.float64)
        drift = current_parameters(model, states[:-1], time, current)
        parameters = np.hstack([parameters, drift])
    path, _, _ = kernels.closed_loop(
        states[:1],
        states[None, :-1],
        inputs[None],
        gains[None],
        np.ascontiguousarray(parameters[None]),
        np.zeros((1, kernels.n_w)),
        dt / refinement,
        refinement,
    )
    flown: FloatArray = path[0]
    return flown
