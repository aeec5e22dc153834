r"""The RK4 step of the discrete dynamics and its running-cost quadrature (expressions).

One classical Runge–Kutta step of length ``h`` with ``u`` and ``p`` held:

.. math::

    k_1 = f(x, u, p),\; k_2 = f(x + \tfrac h2 k_1, u, p),\; k_3 = f(x + \tfrac h2 k_2, u, p),\;
    k_4 = f(x + h k_3, u, p),\quad x^+ = x + \tfrac h6 (k_1 + 2k_2 + 2k_3 + k_4),

and the running cost as a quadrature state along the same stages,
``L = \tfrac h6 (q_1 + 2q_2 + 2q_3 + q_4)`` with ``q_i = l`` at the ``i``-th stage point.
"""

from __future__ import annotations

import casadi as ca

from auvplan.optimization._casadi import Symbol

__all__ = ["rk4_step"]


def rk4_step(
    dynamics: ca.Function,
    running_cost: ca.Function,
    x: Symbol,
    u: Symbol,
    p: Symbol,
    dt: float,
) -> tuple[Symbol, Symbol]:
    """Symbolic RK4 step ``F(x, u, p)`` and its stage cost ``L(x, u, p)`` (module equations).

    Parameters
    ----------
    dynamics, running_cost : casadi.Function
        ``f(x, u, p) -> ẋ`` and ``l(x, u, p) -> scalar`` (cost per second).
    x, u, p : casadi.SX or casadi.MX
        State, input and stage-parameter symbols.
    dt : float
        Step length [s].

    Returns
    -------
    x_next, stage_cost : casadi.SX or casadi.MX
        ``F`` and ``L``.
    """

    def rate(state: Symbol) -> tuple[Symbol, Symbol]:
        return dynamics(state, u, p), running_cost(state, u, p)

    k1, q1 = rate(x)
    k2, q2 = rate(x + dt / 2 * k1)
    k3, q3 = rate(x + dt / 2 * k2)
    k4, q4 = rate(x + dt * k3)
    x_next = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    stage_cost = dt / 6 * (q1 + 2 * q2 + 2 * q3 + q4)
    return x_next, stage_cost
