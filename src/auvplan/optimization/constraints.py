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

__all__ = ["ConstraintModel", "SparseJacobians", "discretize_constraints"]

_ARGS = ["x", "u", "p"]


@dataclass(frozen=True, eq=False)
class SparseJacobians:
    """Constraint Jacobians ``∂c/∂(x, u)`` at ``N`` points, kept as their structural nonzeros.

    A fleet's separations touch four states each, so the dense ``(N, n_c, n_x + n_u)`` array
    would be almost all zeros and grow with the cube of the fleet. Row ``j``'s nonzeros
    are ``values[:, row_start[j]:row_start[j + 1]]`` at the columns
    ``columns[row_start[j]:row_start[j + 1]]`` of ``z = (x, u)`` (compressed rows).
    """

    values: FloatArray
    """Nonzeros, shape ``(N, nnz)``, in compressed-row order."""
    row_start: IntArray = field(repr=False)
    columns: IntArray = field(repr=False)
    n_z: int
    """Size of ``z = (x, u)``."""

    def __getitem__(self, points: slice) -> SparseJacobians:
        """The Jacobians at a slice of the points."""
        return SparseJacobians(self.values[points], self.row_start, self.columns, self.n_z)

    def weighted_sum(self, weights: FloatArray) -> FloatArray:
        """``Σ_j w_{k,j} ∇c_j(z_k)``, shape ``(N, n_z)``; ``weights`` has shape ``(N, n_c)``."""
        return _weighted_rows(weights, self.values, self.row_start, self.columns, self.n_z)

    def add_outer_products(
        self, weights: FloatArray, blocks: tuple[FloatArray, FloatArray, FloatArray]
    ) -> None:
        """Add ``Σ_j w_{k,j} ∇c_j ∇c_jᵀ`` to the blocks ``(H_xx, H_xu, H_uu)`` in place.

        Only the structural nonzeros of each gradient are visited (a separation touches four
        states of a fleet), so the cost does not grow with ``n_x²``.
        """
        _add_outer_products(weights, self.values, self.row_start, self.columns, *blocks)


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
    """``(c, nonzeros of ∂c/∂(x, u) in compressed-row order)`` at one stage."""
    _hessian: ca.Function = field(repr=False)
    """Nonzeros of ``∇²_{(x, u)} (wᵀc)`` at one stage."""
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
    ) -> tuple[FloatArray, SparseJacobians]:
        """Values ``(N, n_c)`` and the Jacobians ``∂c/∂(x, u)`` by their nonzeros."""
        c, nonzeros = self._stages(
            self._jacobians, states, inputs, parameters, [(self.n_c,), (self.columns.size,)]
        )
        return c, SparseJacobians(nonzeros, self.row_start, self.columns, self.n_x + self.n_u)

    def add_weighted_hessians(
        self,
        states: FloatArray,
        inputs: FloatArray,
        parameters: FloatArray,
        weights: FloatArray,
        blocks: tuple[FloatArray, FloatArray, FloatArray],
    ) -> None:
        """Add ``Σ_j w_{k,j} ∇²c_j(x_k, u_k, p_k)`` to the blocks ``(H_xx, H_xu, H_uu)`` in place.

        ``weights`` has shape ``(N, n_c)``. Only the structural nonzeros are evaluated and
        added (those of the positions in a separation).
        """
        (nonzeros,) = self._stages(
            self._hessian, states, inputs, parameters, [(self.hessian_entries[0].size,)],
            ("weights", weights, self.n_c),
        )  # fmt: skip
        _add_entries(nonzeros, *self.hessian_entries, *blocks)


@numba.njit(cache=True)
def _weighted_rows(
    weights: FloatArray, values: FloatArray, row_start: IntArray, columns: IntArray, n_z: int
) -> FloatArray:
    n_points, n_c = weights.shape
    out = np.zeros((n_points, n_z))
    for k in range(n_points):
        for j in range(n_c):
            w = weights[k, j]
            if w == 0.0:
                continue
            for a in range(row_start[j], row_start[j + 1]):
                out[k, columns[a]] += w * values[k, a]
    return out


@numba.njit(cache=True)
def _block_of(
    row: int, column: int, h_xx: FloatArray, h_xu: FloatArray, h_uu: FloatArray
) -> tuple[FloatArray, int, int, bool]:
    """Where ``(row, column)`` of ``[[H_xx, H_xu], [·, H_uu]]`` is kept: the block and its entry.

    The last value is False for an entry of ``H_ux``, which is not kept.
    """
    n_x = h_xx.shape[1]
    if row < n_x and column < n_x:
        return h_xx, row, column, True
    if row < n_x:
        return h_xu, row, column - n_x, True
    return h_uu, row - n_x, column - n_x, column >= n_x


@numba.njit(cache=True)
def _add_entries(
    nonzeros: FloatArray, rows: IntArray, columns: IntArray, h_xx: FloatArray,
    h_xu: FloatArray, h_uu: FloatArray,
) -> None:  # fmt: skip
    """``H[k] += nonzeros[k, e]`` at ``(rows[e], columns[e])``, entry by entry over the stages.

    For each stage the entries arrive in the order of ``e``, as from a loop over the stages.
    """
    for e in range(rows.size):
        block, row, column, kept = _block_of(rows[e], columns[e], h_xx, h_xu, h_uu)
        if kept:
            for k in range(nonzeros.shape[0]):
                block[k, row, column] += nonzeros[k, e]


@numba.njit(cache=True)
def _add_outer_products(
    weights: FloatArray,
    values: FloatArray,
    row_start: IntArray,
    columns: IntArray,
    h_xx: FloatArray,
    h_xu: FloatArray,
    h_uu: FloatArray,
) -> None:
    """``H[k] += w_kj g_a g_b`` for every row ``j``'s nonzeros ``a``, ``b`` (``g = values[k]``).

    Pair by pair over the stages (rows with ``w_kj = 0`` skipped); for each stage the terms
    arrive in the order of ``(j, a, b)``, as from a loop over the stages.
    """
    n_points, n_c = weights.shape
    for j in range(n_c):
        for a in range(row_start[j], row_start[j + 1]):
            for b in range(row_start[j], row_start[j + 1]):
                block, row, column, kept = _block_of(columns[a], columns[b], h_xx, h_xu, h_uu)
                if not kept:
                    continue
                for k in range(n_points):
                    w = weights[k, j]
                    if w != 0.0:
                        block[k, row, column] += w * values[k, a] * values[k, b]


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
        # the transpose's nonzeros (column-major) are the Jacobian's in compressed-row order
        return ConstraintModel(
            n_x,
            n_u,
            n_p,
            n_c,
            dense_function("constraints", args, [c], _ARGS, ["c"]),
            dense_function("constraint_jac", args, [c, nonzeros(jacobian.T)], _ARGS, ["c", "c_xu"]),
            dense_function(
                "constraint_hess", [*args, weights], [nonzeros(hessian)], [*_ARGS, "w"], ["h"]
            ),
            entries(hessian),
            np.asarray(row_start, dtype=np.int64),
            np.asarray(columns, dtype=np.int64),
        )

    return with_symbol_fallback(build)
