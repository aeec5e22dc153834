r"""Chain rule through the RK4 stages of a step (numba kernels, batched over points).

A step of ``m`` RK4 substeps evaluates the model at ``4m`` **nodes**
``(K_n, ℓ_n) = (f, l)(Y_n, u)``; every node's argument is linear in the substep's start
``y_j`` and the previous node's ``K`` (``Y_{j,0} = y_j``,
``Y_{j,i} = y_j + h a_i K_{j,i-1}``, ``a = (0, ½, ½, 1)``), and so are the step's results
``y_{j+1} = y_j + h Σ_i b_i K_{j,i}`` and ``L = h Σ_{j,i} b_i ℓ_{j,i}``, ``b = (1, 2, 2, 1)/6``.
With ``D_n = ∂Y_n/∂(x, u)`` (``n_x × n_z``, ``n_z = n_x + n_u``) and the node derivatives
``J_n = ∂f/∂(y, u)``, ``g_n = ∇_{(y,u)} l``, the first-order data follow forward,

.. math::

    ∂K_n/∂(x, u) = J_n \tilde D_n,\qquad \tilde D_n = \begin{bmatrix} D_n \\ 0\;\; I\end{bmatrix},
    \qquad ∇_{(x,u)} L = h \sum_n b_n \tilde D_n^T g_n,

and since only the nodes are nonlinear, the Hessian of ``ν L + λᵀ F`` is exactly

.. math::

    \sum_n \tilde D_n^T\, ∇^2_{(y,u)} \big(\bar K_n^T f + ν h b_n l\big)\big|_{Y_n}\, \tilde D_n

with the node adjoints ``K̄`` of a reverse sweep
(:meth:`~auvplan.optimization.block_kernels.BlockKernels.hessian`). Arrays are C-contiguous
float64, points on axis 0.
"""

from __future__ import annotations

import numba
import numpy as np

from auvplan._typing import FloatArray


@numba.njit(cache=True, fastmath=True, nogil=True)
def advance_node(
    jac: FloatArray,
    grad: FloatArray,
    carried: FloatArray,
    start: FloatArray,
    step_jac: FloatArray,
    cost_grad: FloatArray,
    factor: float,
    offset: float,
    next_carried: FloatArray,
) -> None:
    """Accumulate one node's first-order data at every point (in place).

    With ``R = ∂K/∂(x, u) = J D̃`` (``jac (B, n_x, n_z)``, ``carried`` = ``D``):
    ``step_jac += factor · R`` (the substep's ``∂y_{j+1}/∂(x, u)``),
    ``cost_grad += factor · D̃ᵀ g`` and ``next_carried = start + offset · R`` (the next node's
    ``D``; ``start`` is the substep's ``∂y_j/∂(x, u)``).
    """
    n_points, n_x, n_z = carried.shape
    rate_d = np.empty((n_x, n_z))
    for b in range(n_points):
        jb, db, gb = jac[b], carried[b], grad[b]
        for r in range(n_x):  # rate_d = J D̃ (i-k-j order: the inner loop runs along rows)
            for c in range(n_x):
                rate_d[r, c] = 0.0
            for c in range(n_x, n_z):
                rate_d[r, c] = jb[r, c]
            for k in range(n_x):
                a = jb[r, k]
                if a != 0.0:  # the model's Jacobians are sparse (e.g. positions enter no rate)
                    for c in range(n_z):
                        rate_d[r, c] += a * db[k, c]
        cg = cost_grad[b]
        for c in range(n_x, n_z):
            cg[c] += factor * gb[c]
        for r in range(n_x):
            a = factor * gb[r]
            if a != 0.0:
                for c in range(n_z):
                    cg[c] += a * db[r, c]
        sj, st, nc = step_jac[b], start[b], next_carried[b]
        for r in range(n_x):
            for c in range(n_z):
                sj[r, c] += factor * rate_d[r, c]
                nc[r, c] = st[r, c] + offset * rate_d[r, c]


@numba.njit(cache=True, fastmath=True, nogil=True)
def add_hessian(total: FloatArray, local: FloatArray, carried: FloatArray) -> None:
    """``total += D̃ᵀ local D̃`` at every point (in place; ``total``, ``local`` ``(B, n_z, n_z)``).

    Node Hessians are mostly zero (about 3/4 of the entries for a MEDUSA: positions enter no
    rate, and each rate few states), and so are many entries of ``D``: products with an exact
    zero are skipped (the same sums), and so are the rows of ``local D̃`` that are zero.
    """
    n_points, n_x, n_z = carried.shape
    right = np.empty((n_z, n_z))
    live = np.empty(n_x, dtype=np.bool_)  # rows of `right` not all zero
    for b in range(n_points):
        e, h, t = carried[b], local[b], total[b]
        for r in range(n_z):  # right = local D̃ (i-k-j order)
            nonzero = False
            for c in range(n_x):
                right[r, c] = 0.0
            for c in range(n_x, n_z):
                right[r, c] = h[r, c]
                nonzero = nonzero or h[r, c] != 0.0
            for k in range(n_x):
                a = h[r, k]
                if a != 0.0:
                    nonzero = True
                    for c in range(n_z):
                        right[r, c] += a * e[k, c]
            if r < n_x:
                live[r] = nonzero
        for r in range(n_x, n_z):  # total += D̃ᵀ right: the identity rows of D̃ …
            for c in range(n_z):
                t[r, c] += right[r, c]
        for k in range(n_x):  # … and the rows of D
            if not live[k]:
                continue
            for r in range(n_z):
                a = e[k, r]
                if a != 0.0:
                    for c in range(n_z):
                        t[r, c] += a * right[k, c]


@numba.njit(cache=True, fastmath=True, nogil=True)
def node_adjoint(
    k_bar: FloatArray, jac: FloatArray, grad: FloatArray, cost_weight: float
) -> FloatArray:
    """``Ȳ = J_yᵀ K̄ + w g_y`` at every point (``k_bar (B, n_x)``, ``w`` the node's cost weight)."""
    n_points, n_x = k_bar.shape
    out = np.empty((n_points, n_x))
    for b in range(n_points):
        for c in range(n_x):
            s = cost_weight * grad[b, c]
            for r in range(n_x):
                s += jac[b, r, c] * k_bar[b, r]
            out[b, c] = s
    return out
