"""Exact CasADi derivatives of ``g(x, c)`` against central finite differences (any model size)."""

from __future__ import annotations

from collections.abc import Callable, Iterable

import casadi as ca
import numpy as np


def central_difference(
    function: Callable[[np.ndarray], np.ndarray], z: np.ndarray, step: float
) -> np.ndarray:
    """Columns ``(g(z + h e_i) - g(z - h e_i)) / 2h`` with ``h = step max(1, |z_i|)``."""
    columns = []
    for i in range(z.size):
        h = step * max(1.0, abs(z[i]))
        plus, minus = z.copy(), z.copy()
        plus[i] += h
        minus[i] -= h
        columns.append((function(plus) - function(minus)) / (2 * h))
    return np.column_stack(columns)


def check_derivatives(
    function: ca.Function,
    points: Iterable[tuple[str, np.ndarray, np.ndarray]],
    rng: np.random.Generator,
) -> None:
    """Jacobian and the Hessian of ``λ·g`` at each ``(label, x, c)`` vs finite differences."""
    n_x, n_u = function.size1_in(0), function.size1_in(1)
    n_out = function.size1_out(0)
    x, c, lam = ca.SX.sym("x", n_x), ca.SX.sym("c", n_u), ca.SX.sym("lam", n_out)
    z = ca.vertcat(x, c)
    out = function(x, c)
    hessian, gradient = ca.hessian(ca.dot(lam, out), z)
    jac = ca.Function("J", [x, c], [ca.jacobian(out, z)])
    grad = ca.Function("g", [x, c, lam], [gradient])
    hess = ca.Function("H", [x, c, lam], [hessian])

    def value(point: np.ndarray) -> np.ndarray:
        return np.asarray(function(point[:n_x], point[n_x:]), dtype=float).ravel()

    for label, state, inputs in points:
        point = np.concatenate([state, inputs])
        weights = rng.normal(size=n_out)
        exact_j = np.asarray(jac(state, inputs))
        exact_h = np.asarray(hess(state, inputs, weights))
        assert np.all(np.isfinite(exact_j)), label
        assert np.all(np.isfinite(exact_h)), label
        numeric_j = central_difference(value, point, 1e-6).reshape(n_out, n_x + n_u)
        np.testing.assert_allclose(exact_j, numeric_j, rtol=1e-5, atol=1e-6, err_msg=label)

        def gradient_at(p: np.ndarray, w: np.ndarray = weights) -> np.ndarray:
            return np.asarray(grad(p[:n_x], p[n_x:], w), dtype=float).ravel()

        numeric_h = central_difference(gradient_at, point, 1e-5)
        np.testing.assert_allclose(exact_h, numeric_h, rtol=1e-4, atol=1e-5, err_msg=label)
        np.testing.assert_allclose(exact_h, exact_h.T, atol=1e-12)
