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
(:meth:`~auvplan.optimization.block_kernels.BlockKernels.hessian`). The generated node
kernels return the products with ``D̃_n`` themselves (``J_n D̃_n``, ``D̃_nᵀ g_n`` and the upper
triangle of ``D̃_nᵀ ∇² D̃_n``: the model's sparsity is then spent symbolically, with no zero
multiplied); the kernels here accumulate them. Arrays are C-contiguous float64, points on
axis 0.
"""

from __future__ import annotations

import numba

from auvplan._typing import FloatArray


@numba.njit(cache=True, fastmath=True, nogil=True)
def advance_node(
    rate_d: FloatArray,
    grad_d: FloatArray,
    start: FloatArray,
    step_jac: FloatArray,
    cost_grad: FloatArray,
    factor: float,
    offset: float,
    next_carried: FloatArray,
) -> None:
    """Accumulate one node's first-order data at every point (in place).

    With ``R = ∂K/∂(x, u) = J D̃`` (``rate_d (B, n_x, n_z)``) and ``D̃ᵀ g`` (``grad_d (B, n_z)``):
    ``step_jac += factor · R`` (the substep's ``∂y_{j+1}/∂(x, u)``),
    ``cost_grad += factor · D̃ᵀ g`` and ``next_carried = start + offset · R`` (the next node's
    ``D``; ``start`` is the substep's ``∂y_j/∂(x, u)``).
    """
    n_points, n_x, n_z = rate_d.shape
    for b in range(n_points):
        rb, sj, st, nc, cg, gb = (
            rate_d[b], step_jac[b], start[b], next_carried[b], cost_grad[b], grad_d[b],
        )  # fmt: skip
        for c in range(n_z):
            cg[c] += factor * gb[c]
        for r in range(n_x):
            for c in range(n_z):
                sj[r, c] += factor * rb[r, c]
                nc[r, c] = st[r, c] + offset * rb[r, c]


@numba.njit(cache=True, fastmath=True, nogil=True)
def add_symmetric(total: FloatArray, upper: FloatArray) -> None:
    """``total += U + Uᵀ − diag U`` at every point, ``U`` given by its upper triangle.

    ``upper (B, n_z (n_z + 1) / 2)`` row by row (``(0, 0), (0, 1), …, (1, 1), …``);
    ``total (B, n_z, n_z)``.
    """
    n_points, n_z = total.shape[0], total.shape[1]
    for b in range(n_points):
        t, u = total[b], upper[b]
        k = 0
        for i in range(n_z):
            t[i, i] += u[k]
            k += 1
            for j in range(i + 1, n_z):
                t[i, j] += u[k]
                t[j, i] += u[k]
                k += 1
