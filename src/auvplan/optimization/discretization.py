r"""RK4 discretisation of a continuous-time model with exact, batched derivatives.

A continuous model ``ẋ = f(x, u, p)`` with running-cost rate ``l(x, u, p)`` becomes the
discrete-time map of one classical Runge–Kutta step of length ``dt`` with the input ``u`` and
the stage parameter ``p`` held constant over the step (zero-order hold). The running cost is
integrated **as an extra RK4 quadrature state** that does not feed back into the dynamics, so
the discrete stage cost is the RK4 quadrature of ``l`` along the same four stages:

.. math::

    k_1 &= f(x, u, p), & q_1 &= l(x, u, p) \
    k_2 &= f(x + \tfrac{dt}{2} k_1, u, p), & q_2 &= l(x + \tfrac{dt}{2} k_1, u, p) \
    k_3 &= f(x + \tfrac{dt}{2} k_2, u, p), & q_3 &= l(x + \tfrac{dt}{2} k_2, u, p) \
    k_4 &= f(x + dt\, k_3, u, p),       & q_4 &= l(x + dt\, k_3, u, p) \
    F(x, u, p) &= x + \tfrac{dt}{6}(k_1 + 2k_2 + 2k_3 + k_4), &
    L(x, u, p) &= \tfrac{dt}{6}(q_1 + 2q_2 + 2q_3 + q_4).

All derivatives (``F_x``, ``F_u``, the costate-weighted Hessians ``Σ_i λ_i ∇²F^i`` and the
cost derivatives) are exact: CasADi differentiates the RK4 expression graph itself.
Batched evaluation over a horizon of ``N`` stages uses ``casadi.Function.map(N)`` (one call
into CasADi's virtual machine, no Python loop per stage); the mapped functions are built once
per ``N`` and cached.

Array layout: every public method takes and returns **time-major** numpy arrays (stage on
axis 0). CasADi's ``map`` works on column-major ``(n, N)`` matrices; the conversion is a
transpose on the way in and one reshape on the way out. Matrices are flattened row-major per
stage inside CasADi (``reshape(A.T, -1, 1)``), so ``out.T.reshape(N, n, m)`` recovers them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, TypeAlias

import casadi as ca
import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.optimization._compile import compile_functions

__all__ = [
    "ConstraintModel",
    "DiscreteModel",
    "TerminalCost",
    "discretize_constraints",
    "discretize_rk4",
    "make_terminal_cost",
]

Parallelization = Literal["serial", "thread"]
#: CasADi symbolic expression (SX or MX); internal use only.
_Sym: TypeAlias = Any


def _sizes(function: ca.Function, name: str, n_in: int, n_out: int) -> list[int]:
    """Check a CasADi Function's arity and return the row counts of its (column) inputs."""
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


def _symbols(sizes: list[int], names: list[str], use_sx: bool) -> list[_Sym]:
    kind: _Sym = ca.SX if use_sx else ca.MX
    return [kind.sym(name, size) for name, size in zip(names, sizes, strict=True)]


def _row_major(matrix: _Sym) -> _Sym:
    """Flatten a matrix row by row into a column (so numpy's C-order reshape restores it)."""
    return ca.reshape(matrix.T, -1, 1)


def _dense_function(
    name: str, inputs: list[_Sym], outputs: list[_Sym], in_names: list[str], out_names: list[str]
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


def _evaluate(function: ca.Function, args: list[FloatArray]) -> list[FloatArray]:
    """Evaluate a (mapped) Function on numpy buffers, without DM conversion.

    A time-major C-contiguous array ``(N, n)`` is exactly CasADi's column-major ``(n, N)``
    matrix, so inputs are passed as they are and every output comes back as a flat array
    that reshapes to ``(N, ...)`` without copying.
    """
    buffer, evaluate = function.buffer()
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
    evaluate()
    return outputs


def _to_stages(values: FloatArray, n_stages: int, shape: tuple[int, ...]) -> FloatArray:
    """Reshape a flat mapped output (column-major ``(prod(shape), N)``) to ``(N, *shape)``."""
    return values.reshape((n_stages, *shape))


def _check_stages(array: FloatArray, n_cols: int, name: str, n_stages: int | None) -> FloatArray:
    array = np.asarray(array, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != n_cols:
        raise InputError(f"{name} must have shape (N, {n_cols}), got {array.shape}")
    if n_stages is not None and array.shape[0] != n_stages:
        raise InputError(f"{name} must have {n_stages} rows, got {array.shape[0]}")
    return array


def _stage_arrays(
    states: FloatArray, inputs: FloatArray, parameters: FloatArray, n_x: int, n_u: int, n_p: int
) -> tuple[int, FloatArray, FloatArray, FloatArray]:
    """Validate per-stage ``X``, ``U``, ``P`` against one horizon; return ``(N, X, U, P)``."""
    states = _check_stages(states, n_x, "X", None)
    n_stages = states.shape[0]
    inputs = _check_stages(inputs, n_u, "U", n_stages)
    parameters = _check_stages(parameters, n_p, "P", n_stages)
    return n_stages, states, inputs, parameters


@dataclass(frozen=True, eq=False)
class _MappedCache:
    """Mapped CasADi Functions per horizon length (filled lazily)."""

    functions: dict[tuple[str, int], ca.Function] = field(default_factory=dict)


def _mapped(
    cache: _MappedCache,
    function: ca.Function,
    n_stages: int,
    parallelization: Parallelization,
    n_threads: int,
) -> ca.Function:
    key = (function.name(), n_stages)
    mapped = cache.functions.get(key)
    if mapped is None:
        if parallelization == "thread" and n_threads > 1:
            mapped = function.map(n_stages, "thread", n_threads)
        else:
            mapped = function.map(n_stages)
        cache.functions[key] = mapped
    return mapped


@dataclass(frozen=True, eq=False)
class DiscreteModel:
    """One RK4 step ``x_{k+1} = F(x_k, u_k, p_k)`` and its stage cost, batched over stages.

    Build it with :func:`discretize_rk4`. Every method takes time-major arrays
    ``X (N, n_x)``, ``U (N, n_u)``, ``P (N, n_p)`` (one row per stage ``k = 0..N-1``; ``P``
    may have zero columns) and evaluates all ``N`` stages in one CasADi call.

    Attributes
    ----------
    n_x, n_u, n_p : int
        State, input and stage-parameter dimensions.
    dt : float
        Step length [s].
    step_function : casadi.Function
        ``F(x, u, p) -> x_next`` for one stage.
    cost_function : casadi.Function
        ``L(x, u, p) -> scalar``: the RK4 quadrature of the running-cost rate over the step.
    parallelization : {"serial", "thread"}
        How CasADi's ``map`` evaluates the stages.
    n_threads : int
        Number of threads when ``parallelization == "thread"``.
    """

    n_x: int
    n_u: int
    n_p: int
    dt: float
    step_function: ca.Function
    cost_function: ca.Function
    _first_order: ca.Function = field(repr=False)
    _jacobians: ca.Function = field(repr=False)
    _dyn_hessian: ca.Function = field(repr=False)
    _cost_gradient: ca.Function = field(repr=False)
    _cost_hessian: ca.Function = field(repr=False)
    _lagrangian_hessian: ca.Function = field(repr=False)
    _closed_loop_step: ca.Function = field(repr=False)
    parallelization: Parallelization = "serial"
    n_threads: int = 2
    _cache: _MappedCache = field(default_factory=_MappedCache, repr=False)

    def _map(self, function: ca.Function, n_stages: int) -> ca.Function:
        return _mapped(self._cache, function, n_stages, self.parallelization, self.n_threads)

    def _inputs(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[int, FloatArray, FloatArray, FloatArray]:
        return _stage_arrays(states, inputs, parameters, self.n_x, self.n_u, self.n_p)

    def step(self, states: FloatArray, inputs: FloatArray, parameters: FloatArray) -> FloatArray:
        """Next states ``F(x_k, u_k, p_k)``, shape ``(N, n_x)``.

        Examples
        --------
        >>> import casadi as ca, numpy as np
        >>> x, u, p = ca.SX.sym("x"), ca.SX.sym("u"), ca.SX.sym("p", 0)
        >>> f = ca.Function("f", [x, u, p], [-x + u])
        >>> l = ca.Function("l", [x, u, p], [x**2 + u**2])
        >>> model = discretize_rk4(f, l, 0.1)
        >>> model.step(np.ones((2, 1)), np.zeros((2, 1)), np.zeros((2, 0))).round(7)
        array([[0.9048375],
               [0.9048375]])
        """
        n_stages, xs, us, ps = self._inputs(states, inputs, parameters)
        (out,) = _evaluate(self._map(self.step_function, n_stages), [xs, us, ps])
        return _to_stages(out, n_stages, (self.n_x,))

    def jacobians(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """Exact ``F_x`` of shape ``(N, n_x, n_x)`` and ``F_u`` of shape ``(N, n_x, n_u)``."""
        n_stages, xs, us, ps = self._inputs(states, inputs, parameters)
        f_x, f_u = _evaluate(self._map(self._jacobians, n_stages), [xs, us, ps])
        return (
            _to_stages(f_x, n_stages, (self.n_x, self.n_x)),
            _to_stages(f_u, n_stages, (self.n_x, self.n_u)),
        )

    def weighted_hessians(
        self,
        states: FloatArray,
        inputs: FloatArray,
        parameters: FloatArray,
        costate_next: FloatArray,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Costate-weighted Hessians of the step, ``Σ_i λ_{k+1,i} ∇²F^i_k``.

        Parameters
        ----------
        states, inputs, parameters : ndarray of shape (N, n_x), (N, n_u), (N, n_p)
            Stage points.
        costate_next : ndarray of shape (N, n_x)
            Weights ``λ_{k+1}`` (the costate one stage ahead).

        Returns
        -------
        H_xx, H_xu, H_uu : ndarray of shape (N, n_x, n_x), (N, n_x, n_u), (N, n_u, n_u)
            Blocks of the Hessian of ``λ_{k+1}ᵀ F(x, u, p)`` with respect to ``(x, u)``.
        """
        n_stages, xs, us, ps = self._inputs(states, inputs, parameters)
        lam = _check_stages(costate_next, self.n_x, "costate_next", n_stages)
        h_xx, h_xu, h_uu = _evaluate(self._map(self._dyn_hessian, n_stages), [xs, us, ps, lam])
        return self._hessian_blocks(n_stages, h_xx, h_xu, h_uu)

    def _hessian_blocks(
        self, n_stages: int, h_xx: FloatArray, h_xu: FloatArray, h_uu: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        return (
            _to_stages(h_xx, n_stages, (self.n_x, self.n_x)),
            _to_stages(h_xu, n_stages, (self.n_x, self.n_u)),
            _to_stages(h_uu, n_stages, (self.n_u, self.n_u)),
        )

    def cost(self, states: FloatArray, inputs: FloatArray, parameters: FloatArray) -> FloatArray:
        """Stage costs ``L(x_k, u_k, p_k)``, shape ``(N,)``."""
        n_stages, xs, us, ps = self._inputs(states, inputs, parameters)
        (out,) = _evaluate(self._map(self.cost_function, n_stages), [xs, us, ps])
        return _to_stages(out, n_stages, ())

    def cost_gradients(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """Stage-cost gradients ``L_x`` of shape ``(N, n_x)`` and ``L_u`` of shape ``(N, n_u)``."""
        n_stages, xs, us, ps = self._inputs(states, inputs, parameters)
        l_x, l_u = _evaluate(self._map(self._cost_gradient, n_stages), [xs, us, ps])
        return _to_stages(l_x, n_stages, (self.n_x,)), _to_stages(l_u, n_stages, (self.n_u,))

    def cost_hessians(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Stage-cost Hessian blocks ``L_xx (N, n_x, n_x)``, ``L_xu (N, n_x, n_u)``, ``L_uu``."""
        n_stages, xs, us, ps = self._inputs(states, inputs, parameters)
        h_xx, h_xu, h_uu = _evaluate(self._map(self._cost_hessian, n_stages), [xs, us, ps])
        return self._hessian_blocks(n_stages, h_xx, h_xu, h_uu)

    def first_order(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
        """All first-order data in one call: ``(F_x, F_u, L, L_x, L_u)`` (shapes as above)."""
        n_stages, xs, us, ps = self._inputs(states, inputs, parameters)
        f_x, f_u, cost, l_x, l_u = _evaluate(self._map(self._first_order, n_stages), [xs, us, ps])
        return (
            _to_stages(f_x, n_stages, (self.n_x, self.n_x)),
            _to_stages(f_u, n_stages, (self.n_x, self.n_u)),
            _to_stages(cost, n_stages, ()),
            _to_stages(l_x, n_stages, (self.n_x,)),
            _to_stages(l_u, n_stages, (self.n_u,)),
        )

    def lagrangian_hessians(
        self,
        states: FloatArray,
        inputs: FloatArray,
        parameters: FloatArray,
        costate_next: FloatArray,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Hessian blocks of ``L(x,u,p) + λ_{k+1}ᵀ F(x,u,p)`` in one call (Q, S, R of PRONTO)."""
        n_stages, xs, us, ps = self._inputs(states, inputs, parameters)
        lam = _check_stages(costate_next, self.n_x, "costate_next", n_stages)
        h_xx, h_xu, h_uu = _evaluate(
            self._map(self._lagrangian_hessian, n_stages), [xs, us, ps, lam]
        )
        return self._hessian_blocks(n_stages, h_xx, h_xu, h_uu)

    def rollout(
        self,
        initial_state: FloatArray,
        reference_states: FloatArray,
        reference_inputs: FloatArray,
        gains: FloatArray,
        parameters: FloatArray,
    ) -> tuple[FloatArray, FloatArray]:
        """Closed-loop simulation ``u_k = μ_k + K_k (α_k − x_k)``, ``x_{k+1} = F(x_k, u_k, p_k)``.

        One ``casadi.Function.mapaccum`` call runs the whole recursion.

        Parameters
        ----------
        initial_state : ndarray of shape (n_x,)
            ``x_0``.
        reference_states : ndarray of shape (N, n_x) or (N + 1, n_x)
            ``α_k`` (rows beyond ``N`` are ignored).
        reference_inputs : ndarray of shape (N, n_u)
            ``μ_k``.
        gains : ndarray of shape (N, n_u, n_x)
            ``K_k`` (zeros give an open-loop simulation).
        parameters : ndarray of shape (N, n_p)
            Stage parameters.

        Returns
        -------
        states : ndarray of shape (N + 1, n_x)
            Simulated states (may contain inf/NaN if the simulation diverges).
        inputs : ndarray of shape (N, n_u)
            Applied inputs.
        """
        mu = _check_stages(reference_inputs, self.n_u, "reference_inputs", None)
        n_stages = mu.shape[0]
        alpha = np.asarray(reference_states, dtype=np.float64)[:n_stages]
        alpha = _check_stages(alpha, self.n_x, "reference_states", n_stages)
        params = _check_stages(parameters, self.n_p, "parameters", n_stages)
        gains = np.asarray(gains, dtype=np.float64)
        if gains.shape != (n_stages, self.n_u, self.n_x):
            raise InputError(f"gains must have shape {(n_stages, self.n_u, self.n_x)}")
        x0 = np.asarray(initial_state, dtype=np.float64).reshape(self.n_x)
        key = ("rollout", n_stages)
        accumulated = self._cache.functions.get(key)
        if accumulated is None:
            accumulated = self._closed_loop_step.mapaccum("rollout", n_stages)
            self._cache.functions[key] = accumulated
        (out,) = _evaluate(accumulated, [x0, alpha, mu, gains.reshape(n_stages, -1), params])
        states = np.empty((n_stages + 1, self.n_x))
        states[0] = x0
        states[1:] = _to_stages(out, n_stages, (self.n_x,))
        inputs = mu + np.einsum("kij,kj->ki", gains, alpha - states[:-1])
        return states, inputs


def _build_rk4(
    dynamics: ca.Function,
    running_cost: ca.Function,
    sizes: list[int],
    dt: float,
    use_sx: bool,
) -> dict[str, ca.Function]:
    """Build every single-stage CasADi Function of the RK4 map (SX or MX symbols)."""
    x, u, p = _symbols(sizes, ["x", "u", "p"], use_sx)
    n_x, n_u = sizes[0], sizes[1]
    kind: _Sym = ca.SX if use_sx else ca.MX
    lam = kind.sym("lam", n_x)

    def rate(state: _Sym) -> tuple[_Sym, _Sym]:
        return dynamics(state, u, p), running_cost(state, u, p)

    k1, q1 = rate(x)
    k2, q2 = rate(x + dt / 2 * k1)
    k3, q3 = rate(x + dt / 2 * k2)
    k4, q4 = rate(x + dt * k3)
    x_next = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    stage_cost = dt / 6 * (q1 + 2 * q2 + 2 * q3 + q4)
    w = ca.vertcat(x, u)

    def hessian_blocks(expr: _Sym) -> list[_Sym]:
        hess, _ = ca.hessian(expr, w)
        return [
            _row_major(hess[:n_x, :n_x]),
            _row_major(hess[:n_x, n_x:]),
            _row_major(hess[n_x:, n_x:]),
        ]

    f_x = ca.jacobian(x_next, x)
    f_u = ca.jacobian(x_next, u)
    l_x = ca.gradient(stage_cost, x)
    l_u = ca.gradient(stage_cost, u)
    args = [x, u, p]
    names = ["x", "u", "p"]
    hess_names = ["h_xx", "h_xu", "h_uu"]
    gains = kind.sym("k", n_u * n_x)
    alpha = kind.sym("alpha", n_x)
    mu = kind.sym("mu", n_u)
    gain = ca.reshape(gains, n_x, n_u).T
    closed_u = mu + gain @ (alpha - x)
    functions = {
        "step": _dense_function("rk4_step", args, [x_next], names, ["x_next"]),
        "cost": _dense_function("rk4_cost", args, [stage_cost], names, ["l"]),
        "jacobians": _dense_function(
            "rk4_jac", args, [_row_major(f_x), _row_major(f_u)], names, ["f_x", "f_u"]
        ),
        "first_order": _dense_function(
            "rk4_first",
            args,
            [_row_major(f_x), _row_major(f_u), stage_cost, l_x, l_u],
            names,
            ["f_x", "f_u", "l", "l_x", "l_u"],
        ),
        "dyn_hessian": _dense_function(
            "rk4_dyn_hess",
            [*args, lam],
            hessian_blocks(ca.dot(lam, x_next)),
            [*names, "lam"],
            hess_names,
        ),
        "cost_gradient": _dense_function("rk4_cost_grad", args, [l_x, l_u], names, ["l_x", "l_u"]),
        "cost_hessian": _dense_function(
            "rk4_cost_hess", args, hessian_blocks(stage_cost), names, hess_names
        ),
        "lagrangian_hessian": _dense_function(
            "rk4_lag_hess",
            [*args, lam],
            hessian_blocks(stage_cost + ca.dot(lam, x_next)),
            [*names, "lam"],
            hess_names,
        ),
    }
    step = functions["step"]
    functions["closed_loop_step"] = _dense_function(
        "rk4_closed_loop",
        [x, alpha, mu, gains, p],
        [step(x, closed_u, p)],
        ["x", "alpha", "mu", "k", "p"],
        ["x_next"],
    )
    return functions


def discretize_rk4(
    dynamics: ca.Function,
    running_cost: ca.Function,
    dt: float,
    *,
    parallelization: Parallelization = "serial",
    n_threads: int = 2,
    compile_c: bool = False,
    cache_dir: Path | None = None,
) -> DiscreteModel:
    """Discretise ``ẋ = f(x, u, p)`` and the cost rate ``l`` by one RK4 step (zero-order hold).

    Parameters
    ----------
    dynamics : casadi.Function
        ``f(x[n_x], u[n_u], p[n_p]) -> xdot[n_x]`` (continuous time, SI units per second).
    running_cost : casadi.Function
        ``l(x, u, p) -> scalar``: running-cost *rate* (cost per second).
    dt : float
        Step length [s], > 0.
    parallelization : {"serial", "thread"}, optional
        Evaluation mode of the batched (``map``) functions.
    n_threads : int, optional
        Threads for ``parallelization="thread"``.
    compile_c : bool, optional
        Generate C code for the stage functions, compile it once (cached on disk, see
        :mod:`auvplan.optimization._compile`) and evaluate the compiled code: about 10x faster
        Hessians for vehicle models; falls back to the CasADi VM without a C compiler.
    cache_dir : Path, optional
        Cache folder of the compiled libraries (default ``~/.cache/auvplan/casadi``).

    Returns
    -------
    DiscreteModel
        The stage map ``F`` and the stage cost ``L`` (RK4 quadrature of ``l``; module notes).

    Raises
    ------
    InputError
        If the functions have the wrong arity or sizes, or ``dt`` is not positive.

    Notes
    -----
    The stage functions are built with SX symbols when the user functions can be evaluated
    symbolically on SX (fast virtual machine); otherwise with MX.

    Examples
    --------
    >>> import casadi as ca
    >>> x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p", 0)
    >>> f = ca.Function("f", [x, u, p], [ca.vertcat(x[1], u)])
    >>> l = ca.Function("l", [x, u, p], [u**2])
    >>> model = discretize_rk4(f, l, 0.5)
    >>> (model.n_x, model.n_u, model.n_p)
    (2, 1, 0)
    """
    if not np.isfinite(dt) or dt <= 0.0:
        raise InputError(f"dt must be a positive number of seconds, got {dt!r}")
    sizes = _sizes(dynamics, "dynamics", 3, 1)
    cost_sizes = _sizes(running_cost, "running_cost", 3, 1)
    if cost_sizes != sizes:
        raise InputError(f"running_cost input sizes {cost_sizes} differ from dynamics {sizes}")
    if dynamics.size_out(0) != (sizes[0], 1) and not (sizes[0] == 1 and dynamics.numel_out(0) == 1):
        raise InputError(f"dynamics output must be ({sizes[0]}, 1), got {dynamics.size_out(0)}")
    if running_cost.numel_out(0) != 1:
        raise InputError(f"running_cost must return a scalar, got {running_cost.size_out(0)}")
    try:
        functions = _build_rk4(dynamics, running_cost, sizes, float(dt), True)
    except RuntimeError:  # the user functions cannot be evaluated on SX symbols
        functions = _build_rk4(dynamics, running_cost, sizes, float(dt), False)
    if compile_c:
        functions = compile_functions(functions, cache_dir)
    return DiscreteModel(
        n_x=sizes[0],
        n_u=sizes[1],
        n_p=sizes[2],
        dt=float(dt),
        step_function=functions["step"],
        cost_function=functions["cost"],
        _first_order=functions["first_order"],
        _jacobians=functions["jacobians"],
        _dyn_hessian=functions["dyn_hessian"],
        _cost_gradient=functions["cost_gradient"],
        _cost_hessian=functions["cost_hessian"],
        _lagrangian_hessian=functions["lagrangian_hessian"],
        _closed_loop_step=functions["closed_loop_step"],
        parallelization=parallelization,
        n_threads=n_threads,
    )


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
    _hessian: ca.Function = field(repr=False)
    _cache: _MappedCache = field(default_factory=_MappedCache, repr=False)

    def _inputs(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[int, FloatArray, FloatArray, FloatArray]:
        return _stage_arrays(states, inputs, parameters, self.n_x, self.n_u, self.n_p)

    def values(self, states: FloatArray, inputs: FloatArray, parameters: FloatArray) -> FloatArray:
        """Constraint values, shape ``(N, n_c)`` (``>= 0`` feasible)."""
        n_stages, xs, us, ps = self._inputs(states, inputs, parameters)
        (out,) = _evaluate(_mapped(self._cache, self.function, n_stages, "serial", 1), [xs, us, ps])
        return _to_stages(out, n_stages, (self.n_c,))

    def jacobians(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Values ``(N, n_c)`` and Jacobians ``c_x (N, n_c, n_x)``, ``c_u (N, n_c, n_u)``."""
        n_stages, xs, us, ps = self._inputs(states, inputs, parameters)
        c, c_x, c_u = _evaluate(
            _mapped(self._cache, self._jacobians, n_stages, "serial", 1), [xs, us, ps]
        )
        return (
            _to_stages(c, n_stages, (self.n_c,)),
            _to_stages(c_x, n_stages, (self.n_c, self.n_x)),
            _to_stages(c_u, n_stages, (self.n_c, self.n_u)),
        )

    def weighted_hessians(
        self,
        states: FloatArray,
        inputs: FloatArray,
        parameters: FloatArray,
        weights: FloatArray,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Blocks of ``Σ_j w_{k,j} ∇²c_j(x_k, u_k, p_k)``; ``weights`` has shape ``(N, n_c)``."""
        n_stages, xs, us, ps = self._inputs(states, inputs, parameters)
        w = _check_stages(weights, self.n_c, "weights", n_stages)
        h_xx, h_xu, h_uu = _evaluate(
            _mapped(self._cache, self._hessian, n_stages, "serial", 1), [xs, us, ps, w]
        )
        return (
            _to_stages(h_xx, n_stages, (self.n_x, self.n_x)),
            _to_stages(h_xu, n_stages, (self.n_x, self.n_u)),
            _to_stages(h_uu, n_stages, (self.n_u, self.n_u)),
        )


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
        sizes = _sizes(function, f"constraint {i}", 3, 1)
        if sizes != [n_x, n_u, n_p]:
            raise InputError(f"constraint {i} input sizes {sizes} differ from {[n_x, n_u, n_p]}")

    def build(use_sx: bool) -> tuple[ca.Function, ca.Function, ca.Function, int]:
        x, u, p = _symbols([n_x, n_u, n_p], ["x", "u", "p"], use_sx)
        kind: _Sym = ca.SX if use_sx else ca.MX
        parts = [ca.reshape(function(x, u, p), -1, 1) for function in functions]
        c: _Sym = ca.vertcat(*parts) if parts else kind(0, 1)
        n_c = int(c.numel())
        weights = kind.sym("w", n_c)
        w = ca.vertcat(x, u)
        hess, _ = ca.hessian(ca.dot(weights, c), w)
        args = [x, u, p]
        names = ["x", "u", "p"]
        value = _dense_function("constraints", args, [c], names, ["c"])
        jac = _dense_function(
            "constraint_jac",
            args,
            [c, _row_major(ca.jacobian(c, x)), _row_major(ca.jacobian(c, u))],
            names,
            ["c", "c_x", "c_u"],
        )
        hessian = _dense_function(
            "constraint_hess",
            [*args, weights],
            [
                _row_major(hess[:n_x, :n_x]),
                _row_major(hess[:n_x, n_x:]),
                _row_major(hess[n_x:, n_x:]),
            ],
            [*names, "w"],
            ["h_xx", "h_xu", "h_uu"],
        )
        return value, jac, hessian, n_c

    try:
        value, jac, hessian, n_c = build(True)
    except RuntimeError:
        value, jac, hessian, n_c = build(False)
    return ConstraintModel(n_x, n_u, n_p, n_c, value, jac, hessian)


@dataclass(frozen=True, eq=False)
class TerminalCost:
    """Terminal cost ``m(x_N)`` with exact gradient and Hessian (one CasADi call)."""

    n_x: int
    function: ca.Function
    _derivatives: ca.Function = field(repr=False)

    def evaluate(self, state: FloatArray) -> tuple[float, FloatArray, FloatArray]:
        """Return ``m(x)``, ``m_x`` of shape ``(n_x,)`` and ``m_xx`` of shape ``(n_x, n_x)``."""
        value, gradient, hessian = self._derivatives(np.asarray(state, dtype=np.float64))
        return (
            float(value),
            np.asarray(gradient.full(), dtype=np.float64).reshape(self.n_x),
            np.asarray(hessian.full(), dtype=np.float64),
        )

    def value(self, state: FloatArray) -> float:
        """``m(x)``."""
        return float(self.function(np.asarray(state, dtype=np.float64)))


def make_terminal_cost(terminal_cost: ca.Function, n_x: int) -> TerminalCost:
    """Wrap ``m(x[n_x]) -> scalar`` with its exact derivatives.

    Raises
    ------
    InputError
        If the function has the wrong arity or input size.
    """
    sizes = _sizes(terminal_cost, "terminal_cost", 1, 1)
    if sizes != [n_x] or terminal_cost.numel_out(0) != 1:
        raise InputError(f"terminal_cost must map ({n_x},) to a scalar, got inputs {sizes}")
    x: _Sym
    try:
        x = ca.SX.sym("x", n_x)
        value = terminal_cost(x)
    except RuntimeError:
        x = ca.MX.sym("x", n_x)
        value = terminal_cost(x)
    hess, grad = ca.hessian(value, x)
    derivatives = _dense_function("terminal", [x], [value, grad, hess], ["x"], ["m", "m_x", "m_xx"])
    return TerminalCost(n_x, terminal_cost, derivatives)
