r"""The discrete step: RK4 substeps over one control interval, and choosing their number.

``dt`` is the control (and output) interval: the input ``u`` and the stage parameter ``p`` are
held over it (zero-order hold). The step ``F`` integrates ``ẋ = f(x, u, p)`` over ``dt`` with
``m`` classical Runge–Kutta substeps of length ``h = dt / m``; one substep from ``y`` is

.. math::

    k_1 = f(y, u, p),\; k_2 = f(y + \tfrac h2 k_1, u, p),\; k_3 = f(y + \tfrac h2 k_2, u, p),\;
    k_4 = f(y + h k_3, u, p),\quad y^+ = y + \tfrac h6 (k_1 + 2k_2 + 2k_3 + k_4),

and the running cost is the quadrature state integrated along the same stages,
``L = Σ_substeps \tfrac h6 (q_1 + 2q_2 + 2q_3 + q_4)`` with ``q_i = l`` at the ``i``-th stage
point. The composed expression is inlined (CasADi SX), so its derivatives are exact and its
evaluation is as fast as CasADi's virtual machine allows (the MX alternatives, ``fold`` or
calls of one substep Function, evaluate the Hessians about 2.2 times slower).

:func:`choose_substeps` picks ``m`` from a step-doubling estimate of the integration error.
"""

from __future__ import annotations

from collections.abc import Callable

import casadi as ca
import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError, SolverError
from auvplan.optimization._casadi import (
    StageEvaluator,
    Symbol,
    signature_sizes,
    symbols,
    with_symbol_fallback,
)

__all__ = ["check_substeps", "choose_substeps", "rk4_step", "rk4_substep"]


def check_substeps(n_substeps: int) -> None:
    """Check a substep count.

    Raises
    ------
    InputError
        Unless ``n_substeps`` is a positive integer.
    """
    if not (isinstance(n_substeps, int | np.integer) and n_substeps >= 1):
        raise InputError(f"n_substeps must be a positive integer, got {n_substeps!r}")


def rk4_substep(
    dynamics: ca.Function,
    running_cost: ca.Function | Callable[[Symbol, Symbol, Symbol], Symbol] | None,
    x: Symbol,
    u: Symbol,
    p: Symbol,
    h: Symbol | float,
) -> tuple[Symbol, Symbol]:
    """One RK4 substep of length ``h`` from ``x`` and its cost quadrature (0 without a cost).

    ``dynamics`` and ``running_cost`` are called as ``g(x, u, p)`` on symbols (a CasADi
    Function or any callable building an expression).
    """

    def rate(state: Symbol) -> tuple[Symbol, Symbol]:
        cost = 0 if running_cost is None else running_cost(state, u, p)
        return dynamics(state, u, p), cost

    k1, q1 = rate(x)
    k2, q2 = rate(x + h / 2 * k1)
    k3, q3 = rate(x + h / 2 * k2)
    k4, q4 = rate(x + h * k3)
    return x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), h / 6 * (q1 + 2 * q2 + 2 * q3 + q4)


def rk4_step(
    dynamics: ca.Function,
    running_cost: ca.Function,
    x: Symbol,
    u: Symbol,
    p: Symbol,
    dt: float,
    n_substeps: int = 1,
) -> tuple[Symbol, Symbol]:
    """Symbolic step ``F(x, u, p)`` over ``dt`` and its stage cost ``L`` (module equations).

    Parameters
    ----------
    dynamics, running_cost : casadi.Function
        ``f(x, u, p) -> ẋ`` and ``l(x, u, p) -> scalar`` (cost per second).
    x, u, p : casadi.SX or casadi.MX
        State, input and stage-parameter symbols.
    dt : float
        Control interval [s].
    n_substeps : int, optional
        Number ``m`` of RK4 substeps of length ``dt / m``.

    Returns
    -------
    x_next, stage_cost : casadi.SX or casadi.MX
        ``F`` and ``L``.
    """
    h = dt / n_substeps
    x_next, stage_cost = rk4_substep(dynamics, running_cost, x, u, p, h)
    for _ in range(n_substeps - 1):
        x_next, cost = rk4_substep(dynamics, running_cost, x_next, u, p, h)
        stage_cost = stage_cost + cost
    return x_next, stage_cost


def choose_substeps(
    dynamics: ca.Function,
    states: FloatArray,
    inputs: FloatArray,
    parameters: FloatArray,
    dt: float,
    *,
    tolerance: float,
    max_substeps: int = 64,
    weights: FloatArray | None = None,
) -> int:
    r"""Smallest number of RK4 substeps whose step-doubling error estimate meets a tolerance.

    For ``m`` substeps the estimate at a sampled stage is ``‖w ⊙ (F_m(x_k) − F_{2m}(x_k))‖₂``
    (with ``u_k``, ``p_k`` held over ``dt``): RK4 is fourth order, so ``F_{2m}`` is about 16
    times more accurate and the difference estimates the error of ``F_m`` (it is
    ``15/16`` of it asymptotically).

    Parameters
    ----------
    dynamics : casadi.Function
        ``f(x[n_x], u[n_u], p[n_p]) -> ẋ[n_x]``.
    states, inputs, parameters : ndarray of shape (N, n_x), (N, n_u), (N, n_p)
        A representative trajectory (e.g. the desired one): ``x_k``, ``u_k``, ``p_k``.
    dt : float
        Control interval [s].
    tolerance : float
        Largest accepted estimate (units of the weighted states, e.g. metres).
    max_substeps : int, optional
        Upper bound on ``m``.
    weights : ndarray of shape (n_x,), optional
        Row weights ``w`` (e.g. 1 on the position rows, 0 elsewhere); default all ones.

    Returns
    -------
    int
        ``m``: its estimate is at most ``tolerance`` at every stage and that of ``m − 1`` is
        not (found by doubling, then bisection between the last two powers of two).

    Raises
    ------
    InputError
        On inconsistent shapes or non-positive ``dt``, ``tolerance`` or ``max_substeps``.
    SolverError
        If even ``max_substeps`` substeps miss the tolerance.

    Examples
    --------
    >>> import casadi as ca, numpy as np
    >>> x, u, p = ca.SX.sym("x"), ca.SX.sym("u"), ca.SX.sym("p", 0)
    >>> f = ca.Function("f", [x, u, p], [-20.0 * x + u])
    >>> choose_substeps(f, np.ones((1, 1)), np.zeros((1, 1)), np.zeros((1, 0)), 0.5,
    ...                 tolerance=1e-6)
    16
    """
    n_x, n_u, n_p = signature_sizes(dynamics, "dynamics", 3, 1)
    if not (np.isfinite(dt) and dt > 0.0):
        raise InputError(f"dt must be a positive number of seconds, got {dt!r}")
    if not (np.isfinite(tolerance) and tolerance > 0.0):
        raise InputError(f"tolerance must be positive, got {tolerance!r}")
    check_substeps(max_substeps)
    row_weights = np.ones(n_x) if weights is None else np.asarray(weights, dtype=np.float64)
    if row_weights.shape != (n_x,):
        raise InputError(f"weights must have shape ({n_x},), got {row_weights.shape}")
    evaluator = StageEvaluator(n_x, n_u, n_p)

    def build(use_sx: bool) -> ca.Function:
        x, u, p, h = symbols([n_x, n_u, n_p, 1], ["x", "u", "p", "h"], use_sx)
        x_next, _ = rk4_substep(dynamics, None, x, u, p, h)
        return ca.Function("rk4_substep", [x, u, p, h], [x_next])

    substep = with_symbol_fallback(build)
    start = np.asarray(states, dtype=np.float64)
    n_stages = start.shape[0] if start.ndim == 2 else 0
    propagated: dict[int, FloatArray] = {}

    def propagate(m: int) -> FloatArray:
        if m not in propagated:
            step = ("h", np.full((n_stages, 1), dt / m), 1)
            x = start
            with np.errstate(all="ignore"):
                for _ in range(m):
                    (x,) = evaluator(substep, x, inputs, parameters, [(n_x,)], step)
            propagated[m] = x
        return propagated[m]

    def meets(m: int) -> bool:
        with np.errstate(all="ignore"):
            defect = np.linalg.norm(row_weights * (propagate(m) - propagate(2 * m)), axis=1)
        return bool(np.all(defect <= tolerance))  # NaN (diverged) fails

    failed, m = 0, 1
    while not meets(m):
        if m >= max_substeps:
            raise SolverError(
                f"{max_substeps} RK4 substeps of dt = {dt:g} s miss the integration "
                f"tolerance {tolerance:g}; use a smaller dt or a larger max_substeps"
            )
        failed, m = m, min(2 * m, max_substeps)
    while m - failed > 1:
        middle = (failed + m) // 2
        if meets(middle):
            m = middle
        else:
            failed = middle
    return m
