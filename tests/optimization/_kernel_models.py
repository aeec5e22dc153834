"""Small block models for the compiled-kernel tests (a few states, a few nonlinear operations).

Each returns ``f(x, u, p)`` and the cost rate ``l(x, u, p, w)`` of one block
(:class:`~auvplan.optimization.StageBlock`); numba compiles their kernels in seconds.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from auvplan.optimization import StageBlock

#: Sizes ``(n_x, n_u, n_p, n_w)`` of the two models.
PENDULUM_SIZES = (2, 1, 1, 2)
CART_SIZES = (3, 2, 0, 1)


def pendulum(gravity: float = 9.81) -> tuple[ca.Function, ca.Function]:
    """Damped pendulum with a saturating torque: ``x = (angle, rate)``, ``p`` = target angle.

    ``w = (tracking, effort)``; the cost couples state and input, so every Hessian block
    (``xx``, ``xu``, ``uu``) of the step is nonzero.
    """
    x, u = ca.SX.sym("x", 2), ca.SX.sym("u", 1)
    p, w = ca.SX.sym("p", 1), ca.SX.sym("w", 2)
    rate = ca.vertcat(
        x[1],
        -gravity * ca.sin(x[0])
        - 0.3 * x[1] * ca.sqrt(x[1] ** 2 + 0.1)
        + ca.tanh(u[0]) * (1.0 + 0.1 * x[1] ** 2),
    )
    cost = w[0] * (x[0] - p[0]) ** 2 * ca.exp(0.2 * x[1]) + w[1] * u[0] ** 2 * (1.0 + x[0] ** 2)
    return (
        ca.Function("pendulum_f", [x, u, p], [rate]),
        ca.Function("pendulum_l", [x, u, p, w], [cost]),
    )


def cart() -> tuple[ca.Function, ca.Function]:
    """Planar cart ``x = (position, heading, speed)``, ``u = (turn, thrust)``, no parameter."""
    x, u = ca.SX.sym("x", 3), ca.SX.sym("u", 2)
    p, w = ca.SX.sym("p", 0), ca.SX.sym("w", 1)
    rate = ca.vertcat(
        x[2] * ca.cos(x[1]),
        u[0] * x[2] / (1.0 + x[2] ** 2),
        u[1] - 0.2 * x[2] ** 3 - 0.1 * x[0],
    )
    cost = w[0] * (u[0] ** 2 + u[1] ** 2) + ca.log(1.0 + x[0] ** 2) * x[2] ** 2
    return ca.Function("cart_f", [x, u, p], [rate]), ca.Function("cart_l", [x, u, p, w], [cost])


def unicycle() -> tuple[ca.Function, ca.Function]:
    """Unicycle ``x = (north, east, heading, speed)``, ``u = (turn, thrust)``, a current ``p``.

    No rate depends on the position, as for a vehicle: the node derivatives ``D`` keep
    structural zeros (:func:`auvplan.optimization.block_kernels._carried_pattern`).
    """
    x, u = ca.SX.sym("x", 4), ca.SX.sym("u", 2)
    p, w = ca.SX.sym("p", 2), ca.SX.sym("w", 2)
    rate = ca.vertcat(
        x[3] * ca.cos(x[2]) + p[0],
        x[3] * ca.sin(x[2]) + p[1],
        u[0] * x[3] / (1.0 + x[3] ** 2),
        u[1] - 0.3 * x[3] * ca.fabs(x[3]),
    )
    cost = w[0] * (u[0] ** 2 + u[1] ** 2) + w[1] * x[3] ** 3 + 0.1 * (x[0] ** 2 + x[1] ** 2)
    return (
        ca.Function("unicycle_f", [x, u, p], [rate]),
        ca.Function("unicycle_l", [x, u, p, w], [cost]),
    )


def fixed_weights(running_cost: ca.Function, weights: np.ndarray) -> ca.Function:
    """``l(x, u, p)`` of the CasADi path: the cost rate with its weights ``w`` fixed."""
    x, u, p = (ca.SX.sym(name, running_cost.size_in(i)) for i, name in enumerate("xup"))
    return ca.Function("l_fixed", [x, u, p], [running_cost(x, u, p, ca.DM(weights))])


def three_blocks() -> tuple[tuple[StageBlock, ...], tuple[int, int, int]]:
    """Two pendulums (one model, different weights) and a cart, out of order in the stack.

    Stacked state ``(cart 0:3, pendulum B 3:5, pendulum A 5:7)``, input
    ``(pendulum A 0, pendulum B 1, cart 2:4)``, parameter ``(pendulum B 0, pendulum A 1)``
    (the cart has none: an empty slice).
    """
    blocks = (
        StageBlock(*pendulum(), np.array([1.0, 0.5]), slice(5, 7), slice(0, 1), slice(1, 2)),
        StageBlock(*cart(), np.array([0.3]), slice(0, 3), slice(2, 4), slice(1, 1)),
        StageBlock(*pendulum(), np.array([2.0, 0.1]), slice(3, 5), slice(1, 2), slice(0, 1)),
    )
    return blocks, (7, 4, 2)


def assert_close(actual: np.ndarray, expected: np.ndarray, rtol: float) -> None:
    """``max |actual − expected| <= rtol · max |expected|`` (same shapes)."""
    actual, expected = np.asarray(actual), np.asarray(expected)
    assert actual.shape == expected.shape, (actual.shape, expected.shape)
    scale = float(np.max(np.abs(expected), initial=0.0))
    error = float(np.max(np.abs(actual - expected), initial=0.0))
    assert error <= rtol * scale, f"max error {error:.3g} > {rtol:g} x {scale:.3g}"
