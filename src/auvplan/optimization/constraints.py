"""Path constraints ``c(x_k, u_k, p_k) >= 0`` with exact derivatives, batched over stages."""

from __future__ import annotations

from dataclasses import dataclass, field

import casadi as ca
import numba
import numpy as np

from auvplan._typing import FloatArray, IntArray
from auvplan.errors import InputError
from auvplan.optimization._casadi import (
    StageEvaluator,
    Symbol,
    dense_function,
    entries,
    nonzeros,
    signature_sizes,
    symbols,
    with_symbol_fallback,
)

__all__ = ["ConstraintModel", "discretize_constraints"]

_ARGS = ["x", "u", "p"]


@dataclass(frozen=True, eq=False)
class ConstraintModel:
    """Path constraints ``c(x_k, u_k, p_k) >= 0`` evaluated in batch over the stages.

    Build with :func:`discretize_constraints`. ``n_c`` is the total number of constraint
    components (all constraint functions stacked).
    """

    n_x: int
    n_u: int
    n_p: int
    n_c: int
    function: ca.Function
    _jacobians: ca.Function = field(repr=False)
    """``(c, nonzeros of ∂c/∂(x, u))`` at one stage."""
    _hessian: ca.Function = field(repr=False)
    """Nonzeros of ``∇²_{(x, u)} (wᵀc)`` at one stage."""
    jacobian_entries: tuple[IntArray, IntArray] = field(repr=False)
    """Row and column in ``∂c/∂(x, u)`` of each Jacobian nonzero (CasADi's order)."""
    hessian_entries: tuple[IntArray, IntArray] = field(repr=False)
    """Row and column in ``∇²_{(x, u)}`` of each Hessian nonzero."""
    row_start: IntArray = field(repr=False)
    """Row ``j`` of ``∂c/∂(x, u)`` has its structural nonzeros in
    ``columns[row_start[j]:row_start[j + 1]]`` (compressed rows)."""
    columns: IntArray = field(repr=False)
    _stages: StageEvaluator = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_stages", StageEvaluator(self.n_x, self.n_u, self.n_p))

    def values(self, states: FloatArray, inputs: FloatArray, parameters: FloatArray) -> FloatArray:
        """Constraint values, shape ``(N, n_c)`` (``>= 0`` feasible)."""
        (out,) = self._stages(self.function, states, inputs, parameters, [(self.n_c,)])
        return out

    def jacobians(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Values ``(N, n_c)`` and Jacobians ``c_x (N, n_c, n_x)``, ``c_u (N, n_c, n_u)``.

        Only the structural nonzeros are evaluated (a separation touches four states).
        """
        rows, columns = self.jacobian_entries
        c, nonzeros = self._stages(
            self._jacobians, states, inputs, parameters, [(self.n_c,), (rows.size,)]
        )
        full = _scattered(nonzeros, rows, columns, (self.n_c, self.n_x + self.n_u))
        return (
            c,
            np.ascontiguousarray(full[:, :, : self.n_x]),
            np.ascontiguousarray(full[:, :, self.n_x :]),
        )

    def weighted_hessians(
        self,
        states: FloatArray,
        inputs: FloatArray,
        parameters: FloatArray,
        weights: FloatArray,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Blocks of ``Σ_j w_{k,j} ∇²c_j(x_k, u_k, p_k)``; ``weights`` has shape ``(N, n_c)``.

        Only the structural nonzeros are evaluated (those of the positions in a separation).
        """
        rows, columns = self.hessian_entries
        (nonzeros,) = self._stages(
            self._hessian, states, inputs, parameters, [(rows.size,)],
            ("weights", weights, self.n_c),
        )  # fmt: skip
        n_x, n_z = self.n_x, self.n_x + self.n_u
        full = _scattered(nonzeros, rows, columns, (n_z, n_z))
        return (
            np.ascontiguousarray(full[:, :n_x, :n_x]),
            np.ascontiguousarray(full[:, :n_x, n_x:]),
            np.ascontiguousarray(full[:, n_x:, n_x:]),
        )

    def add_outer_products(
        self,
        weights: FloatArray,
        c_x: FloatArray,
        c_u: FloatArray,
        blocks: tuple[FloatArray, FloatArray, FloatArray],
    ) -> None:
        """Add ``Σ_j w_{k,j} ∇c_j ∇c_jᵀ`` to the blocks ``(H_xx, H_xu, H_uu)`` in place.

        Only the structural nonzeros of each gradient are visited (a separation touches four
        states of a fleet), so the cost does not grow with ``n_x²``.
        """
        _add_outer_products(weights, c_x, c_u, self.row_start, self.columns, *blocks)


def _scattered(
    nonzeros: FloatArray, rows: IntArray, columns: IntArray, shape: tuple[int, int]
) -> FloatArray:
    """``(N, *shape)`` zeros with ``nonzeros (N, nnz)`` placed at ``(rows, columns)``."""
    full = np.zeros((nonzeros.shape[0], *shape))
    full[:, rows, columns] = nonzeros
    return full


@numba.njit(cache=True)
def _add_outer_products(
    weights: FloatArray,
    c_x: FloatArray,
    c_u: FloatArray,
    row_start: IntArray,
    columns: IntArray,
    h_xx: FloatArray,
    h_xu: FloatArray,
    h_uu: FloatArray,
) -> None:
    n_stages, n_c, n_x = c_x.shape
    for k in range(n_stages):
        for j in range(n_c):
            w = weights[k, j]
            if w == 0.0:
                continue
            for a in range(row_start[j], row_start[j + 1]):
                col_a = columns[a]
                g_a = w * (c_x[k, j, col_a] if col_a < n_x else c_u[k, j, col_a - n_x])
                for b in range(row_start[j], row_start[j + 1]):
                    col_b = columns[b]
                    g_b = c_x[k, j, col_b] if col_b < n_x else c_u[k, j, col_b - n_x]
                    if col_a < n_x and col_b < n_x:
                        h_xx[k, col_a, col_b] += g_a * g_b
                    elif col_a < n_x:
                        h_xu[k, col_a, col_b - n_x] += g_a * g_b
                    elif col_b >= n_x:
                        h_uu[k, col_a - n_x, col_b - n_x] += g_a * g_b


def discretize_constraints(
    functions: tuple[ca.Function, ...], n_x: int, n_u: int, n_p: int
) -> ConstraintModel:
    """Stack path-constraint functions ``c_i(x, u, p) -> (n_ci,)`` into one batched model.

    Parameters
    ----------
    functions : tuple of casadi.Function
        Each ``c(x[n_x], u[n_u], p[n_p]) -> column of n_c values``, feasible when ``>= 0``.
    n_x, n_u, n_p : int
        Dimensions the functions must accept.

    Returns
    -------
    ConstraintModel
        Values, exact Jacobians and weighted Hessians, batched over stages.

    Raises
    ------
    InputError
        If a function has the wrong arity or input sizes.
    """
    for i, function in enumerate(functions):
        sizes = signature_sizes(function, f"constraint {i}", 3, 1)
        if sizes != [n_x, n_u, n_p]:
            raise InputError(f"constraint {i} input sizes {sizes} differ from {[n_x, n_u, n_p]}")

    def build(use_sx: bool) -> ConstraintModel:
        x, u, p = symbols([n_x, n_u, n_p], _ARGS, use_sx)
        kind: Symbol = ca.SX if use_sx else ca.MX
        parts = [ca.reshape(function(x, u, p), -1, 1) for function in functions]
        c: Symbol = ca.vertcat(*parts) if parts else kind(0, 1)
        n_c = int(c.numel())
        weights = kind.sym("w", n_c)
        args = [x, u, p]
        jacobian = ca.jacobian(c, ca.vertcat(x, u))
        hessian, _ = ca.hessian(ca.dot(weights, c), ca.vertcat(x, u))
        row_start, columns = jacobian.sparsity().get_crs()
        return ConstraintModel(
            n_x,
            n_u,
            n_p,
            n_c,
            dense_function("constraints", args, [c], _ARGS, ["c"]),
            dense_function("constraint_jac", args, [c, nonzeros(jacobian)], _ARGS, ["c", "c_xu"]),
            dense_function(
                "constraint_hess", [*args, weights], [nonzeros(hessian)], [*_ARGS, "w"], ["h"]
            ),
            entries(jacobian),
            entries(hessian),
            np.asarray(row_start, dtype=np.int64),
            np.asarray(columns, dtype=np.int64),
        )

    return with_symbol_fallback(build)
