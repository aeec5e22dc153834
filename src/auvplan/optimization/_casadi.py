"""CasADi plumbing shared by the stage models: building, mapping and evaluating Functions.

Array layout: the stage models take and return **time-major** numpy arrays (stage on axis 0).
CasADi's ``map`` works on column-major ``(n, N)`` matrices, which is the very same memory as a
C-contiguous ``(N, n)`` array, so inputs are passed as they are and each flat output reshapes
to ``(N, ...)`` without copying. Matrices are flattened row-major per stage inside CasADi
(:func:`row_major`), so ``out.reshape(N, n, m)`` recovers them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal, TypeAlias, TypeVar

import casadi as ca
import numpy as np

from auvplan._typing import FloatArray, IntArray
from auvplan.errors import InputError

__all__ = [
    "Parallelization",
    "StageEvaluator",
    "Symbol",
    "check_rollout",
    "check_stages",
    "dense_function",
    "evaluate",
    "hessian_blocks",
    "hessian_shapes",
    "row_major",
    "signature_sizes",
    "symbols",
    "with_symbol_fallback",
]

Parallelization = Literal["serial", "thread"]
#: CasADi symbolic expression (SX or MX).
Symbol: TypeAlias = Any
_Built = TypeVar("_Built")


def signature_sizes(function: ca.Function, name: str, n_in: int, n_out: int) -> list[int]:
    """Check a CasADi Function's arity and return the sizes of its (column) inputs.

    Raises
    ------
    InputError
        If ``function`` is not a CasADi Function, has another arity, or a matrix input.
    """
    if not isinstance(function, ca.Function):
        raise InputError(f"{name} must be a casadi.Function, got {type(function).__name__}")
    if function.n_in() != n_in or function.n_out() != n_out:
        raise InputError(
            f"{name} must have {n_in} inputs and {n_out} outputs, "
            f"got {function.n_in()} inputs and {function.n_out()} outputs"
        )
    sizes = []
    for i in range(n_in):
        rows, cols = function.size_in(i)
        if cols != 1 and rows * cols != 0:
            raise InputError(f"{name} input {i} must be a column vector, got {rows}x{cols}")
        sizes.append(rows * cols)
    return sizes


def symbols(sizes: list[int], names: list[str], use_sx: bool) -> list[Symbol]:
    """Column symbols of the given sizes (SX or MX)."""
    kind: Symbol = ca.SX if use_sx else ca.MX
    return [kind.sym(name, size) for name, size in zip(names, sizes, strict=True)]


def with_symbol_fallback(build: Callable[[bool], _Built]) -> _Built:
    """``build(use_sx=True)``, or ``build(False)`` (MX) when the user functions reject SX."""
    try:
        return build(True)
    except RuntimeError:  # a user function cannot be evaluated on SX symbols
        return build(False)


def row_major(matrix: Symbol) -> Symbol:
    """Flatten a matrix row by row into a column (so numpy's C-order reshape restores it)."""
    return ca.reshape(matrix.T, -1, 1)


def hessian_blocks(expression: Symbol, x: Symbol, u: Symbol) -> list[Symbol]:
    """Row-major blocks ``[H_xx, H_xu, H_uu]`` of the Hessian of a scalar in ``(x, u)``."""
    n_x = int(x.numel())
    hessian, _ = ca.hessian(expression, ca.vertcat(x, u))
    return [
        row_major(hessian[:n_x, :n_x]),
        row_major(hessian[:n_x, n_x:]),
        row_major(hessian[n_x:, n_x:]),
    ]


def nonzeros(matrix: Symbol) -> Symbol:
    """The structural nonzeros of a sparse matrix as a column (CasADi's column-major order)."""
    return matrix[matrix.sparsity().find()] if matrix.nnz() else type(matrix)(0, 1)


def entries(matrix: Symbol) -> tuple[IntArray, IntArray]:
    """Row and column of each of :func:`nonzeros`' entries."""
    rows, columns = matrix.sparsity().get_triplet()
    return np.asarray(rows, dtype=np.int64), np.asarray(columns, dtype=np.int64)


def hessian_shapes(n_x: int, n_u: int) -> list[tuple[int, ...]]:
    """Per-stage shapes of the blocks returned by :func:`hessian_blocks`."""
    return [(n_x, n_x), (n_x, n_u), (n_u, n_u)]


def dense_function(
    name: str,
    inputs: list[Symbol],
    outputs: list[Symbol],
    in_names: list[str],
    out_names: list[str],
) -> ca.Function:
    """A CasADi Function with dense outputs and common subexpressions merged.

    Dense outputs let raw buffers hold every entry; ``casadi.cse`` merges common subexpressions
    (e.g. between the RK4 stages of the dynamics and of the running cost), which makes the
    Hessians about 10–15 % cheaper to evaluate.
    """
    dense = [ca.densify(out) for out in outputs]
    if dense and all(isinstance(out, ca.SX) for out in dense):
        dense = ca.cse(dense)
    return ca.Function(name, inputs, dense, in_names, out_names)


def evaluate(function: ca.Function, args: list[FloatArray]) -> list[FloatArray]:
    """Evaluate a (mapped) Function on numpy buffers, without DM conversion.

    Raises
    ------
    InputError
        If an argument has the wrong number of values.
    """
    buffer, run = function.buffer()
    arrays = [np.ascontiguousarray(arg, dtype=np.float64) for arg in args]
    for i, array in enumerate(arrays):
        if array.size != function.nnz_in(i):
            raise InputError(
                f"{function.name()} input {i} needs {function.nnz_in(i)} values, got {array.size}"
            )
        buffer.set_arg(i, array.data)  # type: ignore[call-arg]  # SWIG typemap: (ptr, size)
    outputs = [np.empty(function.nnz_out(i)) for i in range(function.n_out())]
    for i, output in enumerate(outputs):
        buffer.set_res(i, output.data)  # type: ignore[call-arg]
    run()
    return outputs


def check_stages(array: FloatArray, n_cols: int, name: str, n_stages: int | None) -> FloatArray:
    """An ``(N, n_cols)`` float array (``N = n_stages`` when given).

    Raises
    ------
    InputError
        On another shape.
    """
    array = np.asarray(array, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != n_cols:
        raise InputError(f"{name} must have shape (N, {n_cols}), got {array.shape}")
    if n_stages is not None and array.shape[0] != n_stages:
        raise InputError(f"{name} must have {n_stages} rows, got {array.shape[0]}")
    return array


def check_rollout(
    sizes: tuple[int, int, int],
    initial_state: FloatArray,
    reference_states: FloatArray,
    reference_inputs: FloatArray,
    gains: FloatArray,
    parameters: FloatArray,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """A closed-loop rollout's arguments as float arrays of one horizon ``N``.

    ``sizes`` is ``(n_x, n_u, n_p)``. Returns ``x0 (n_x,)``, ``α (N, n_x)`` (rows beyond ``N``
    dropped), ``μ (N, n_u)``, ``K (N, n_u, n_x)`` and ``P (N, n_p)``.

    Raises
    ------
    InputError
        If the arrays do not describe the same ``N`` stages.
    """
    n_x, n_u, n_p = sizes
    mu = check_stages(reference_inputs, n_u, "reference_inputs", None)
    n_stages = mu.shape[0]
    alpha = np.asarray(reference_states, dtype=np.float64)[:n_stages]
    alpha = check_stages(alpha, n_x, "reference_states", n_stages)
    params = check_stages(parameters, n_p, "parameters", n_stages)
    gains = np.asarray(gains, dtype=np.float64)
    if gains.shape != (n_stages, n_u, n_x):
        raise InputError(f"gains must have shape {(n_stages, n_u, n_x)}")
    x0 = np.asarray(initial_state, dtype=np.float64).reshape(n_x)
    return x0, alpha, mu, gains, params


@dataclass(frozen=True, eq=False)
class StageEvaluator:
    """Evaluates single-stage Functions ``g(x, u, p[, w])`` over ``N`` stages in one call.

    ``(n_x, n_u, n_p)`` are the sizes of ``(x, u, p)``. The mapped Functions
    (``g.map(N, "serial")``, or with ``n_threads`` threads when ``parallelization ==
    "thread"``) are built on first use and kept per ``(name, N)``.
    """

    n_x: int
    n_u: int
    n_p: int
    parallelization: Parallelization = "serial"
    n_threads: int = 1
    maps: dict[tuple[str, int], ca.Function] = field(default_factory=dict, repr=False)

    def mapped(self, function: ca.Function, n_stages: int) -> ca.Function:
        """``function.map(n_stages, "serial")`` (built once per name and horizon)."""
        key = (function.name(), n_stages)
        mapped = self.maps.get(key)
        if mapped is None:
            if self.parallelization == "thread" and self.n_threads > 1:
                mapped = function.map(n_stages, "thread", self.n_threads)
            else:  # "serial" explicitly: map(n) alone takes seconds to build for n ~ 1e3
                mapped = function.map(n_stages, "serial")
            self.maps[key] = mapped
        return mapped

    def accumulated(self, function: ca.Function, n_stages: int) -> ca.Function:
        """``function.mapaccum(n_stages)``: a sequential recursion over the stages."""
        key = (f"{function.name()}_accumulated", n_stages)
        accumulated = self.maps.get(key)
        if accumulated is None:
            accumulated = function.mapaccum(key[0], n_stages)
            self.maps[key] = accumulated
        return accumulated

    def __call__(
        self,
        function: ca.Function,
        states: FloatArray,
        inputs: FloatArray,
        parameters: FloatArray,
        shapes: list[tuple[int, ...]],
        weights: tuple[str, FloatArray, int] | None = None,
    ) -> list[FloatArray]:
        """Evaluate ``function`` at every stage and reshape its outputs to ``(N, *shape)``.

        Parameters
        ----------
        function : casadi.Function
            Single-stage ``g(x, u, p)`` or ``g(x, u, p, w)``.
        states, inputs, parameters : ndarray of shape (N, n_x), (N, n_u), (N, n_p)
            Stage points (``parameters`` may have zero columns).
        shapes : list of tuple of int
            Per-stage shape of each output.
        weights : tuple, optional
            ``(name, array (N, n_w), n_w)``: the fourth, per-stage argument ``w``.

        Returns
        -------
        list of ndarray
            One ``(N, *shape)`` array per output.

        Raises
        ------
        InputError
            If the arrays do not describe the same ``N`` stages.
        """
        states = check_stages(states, self.n_x, "X", None)
        n_stages = states.shape[0]
        args = [
            states,
            check_stages(inputs, self.n_u, "U", n_stages),
            check_stages(parameters, self.n_p, "P", n_stages),
        ]
        if weights is not None:
            name, values, n_cols = weights
            args.append(check_stages(values, n_cols, name, n_stages))
        outputs = evaluate(self.mapped(function, n_stages), args)
        return [out.reshape((n_stages, *shape)) for out, shape in zip(outputs, shapes, strict=True)]
