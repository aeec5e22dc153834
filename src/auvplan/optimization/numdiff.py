"""Finite-difference check of PRONTO's first and second derivatives along a direction.

trep's ``check_dcost``/``check_ddcost`` diagnostic (``reference/pronto.md`` §6.4): compare
``Dh·ζ`` and ``D²g(ζ, ζ)`` of the Newton model with central differences of
``g(γ) = h(P(ξ + γζ))``, the function the line search actually sees.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from auvplan.optimization import _kernels
from auvplan.optimization.linesearch import try_step
from auvplan.optimization.lq import directional_derivative, quadratic_form
from auvplan.optimization.model import ModelCache
from auvplan.optimization.options import ProntoOptions
from auvplan.optimization.problem import Trajectory, TrajectoryProblem
from auvplan.optimization.projection import project_guess
from auvplan.optimization.steps import compute_direction, local_model

__all__ = ["DerivativeCheck", "derivative_check"]


@dataclass(frozen=True)
class DerivativeCheck:
    """Analytic vs central-difference derivatives of ``g(γ) = h(P(ξ + γζ))`` at ``γ = 0``.

    Attributes
    ----------
    slope, slope_fd : float
        ``Dh·ζ`` and ``(g(s) − g(−s)) / 2s``.
    curvature, curvature_fd : float
        ``D²g(ζ, ζ)`` (exact weights) and ``(g(s) − 2g(0) + g(−s)) / s²``.
    slope_error, curvature_error : float
        Relative errors.
    """

    slope: float
    slope_fd: float
    curvature: float
    curvature_fd: float
    slope_error: float
    curvature_error: float


def derivative_check(
    problem: TrajectoryProblem,
    trajectory: Trajectory,
    direction: Trajectory | None = None,
    *,
    epsilon: float = 1.0,
    delta: float = 0.5,
    step: float = 1e-4,
    cache: ModelCache | None = None,
) -> DerivativeCheck:
    """Compare ``Dh·ζ`` and ``D²g(ζ,ζ)`` with central differences of ``g`` along ζ.

    Parameters
    ----------
    problem : TrajectoryProblem
        The problem.
    trajectory : Trajectory
        Point ξ (projected first, so it need not be a trajectory).
    direction : Trajectory, optional
        Only its ``inputs`` ``v (N, n_u)`` are used; the state part is the tangent response
        ``z_{k+1} = A_k z_k + B_k v_k``, ``z_0 = 0``. Default: the PRONTO search direction
        (:func:`~auvplan.optimization.steps.compute_direction` with default options).
    epsilon, delta : float
        Barrier weight and switching point (ignored without constraints).
    step : float
        Finite-difference step ``s`` in ``γ``.
    cache : ModelCache, optional
        Where to look up the problem's model; default: build it for this call.

    Returns
    -------
    DerivativeCheck
        Both derivatives and their relative errors.
    """
    model = (cache if cache is not None else ModelCache(max_entries=1)).get(problem)
    options = ProntoOptions()
    xi, _ = project_guess(model, trajectory, options)
    if direction is None:
        local, zeta = compute_direction(model, xi, epsilon, delta, options=options)
        z, v = zeta.z, zeta.v
    else:
        local = local_model(model, xi, epsilon, delta, options=options)
        lin = local.linearization
        v = np.asarray(direction.inputs, dtype=np.float64)
        z, v = _kernels.lq_forward(
            lin.A, lin.B, np.zeros((problem.n_steps, problem.n_inputs, problem.n_states)), v
        )
    slope = directional_derivative(local.linearization, z, v)
    curvature = quadratic_form(local.weights, z, v)

    def g(gamma: float) -> float:
        trial = try_step(model, xi, (z, v), local.gains, gamma, epsilon=epsilon, delta=delta)
        return trial.cost.total

    g_plus, g_zero, g_minus = g(step), g(0.0), g(-step)
    slope_fd = (g_plus - g_minus) / (2.0 * step)
    curvature_fd = (g_plus - 2.0 * g_zero + g_minus) / step**2
    return DerivativeCheck(
        slope=slope,
        slope_fd=slope_fd,
        curvature=curvature,
        curvature_fd=curvature_fd,
        slope_error=abs(slope - slope_fd) / max(abs(slope), 1e-300),
        curvature_error=abs(curvature - curvature_fd) / max(abs(curvature), 1e-300),
    )
