r"""Compiled kernels of one block's continuous model, stepped by RK4; built once per model.

For a block ``ẋ = f(x, u, p)`` with running-cost rate ``l(x, u, p, w)`` (``w``: runtime
weights) three node kernels are generated, with no mission quantity baked in:

- ``value(y, u, p, w) -> (f, l)``;
- ``first(y, u, p, w, D) -> (f, l, J D̃, D̃ᵀ g)`` with ``J = ∂f/∂(y, u)``,
  ``g = ∇_{(y,u)} l`` and ``D̃ = [D; 0 I]`` for a node's ``D = ∂y/∂(x, u)`` (``n_x × n_z``;
  ``D`` and ``J D̃`` as their entries in :func:`_carried_pattern`, row by row: the others are
  structurally zero);
- ``hessian(y, u, p, w, λ, ν, D) -> (upper triangle of D̃ᵀ H D̃, ∇_y (ν l + λᵀ f))`` with
  ``H = ∇²_{(y,u)} (ν l + λᵀ f)``.

Each is split in two (:func:`~auvplan.optimization._numba_codegen.split_stage`): what depends
on ``u``, ``p`` and ``w`` alone (e.g. ``tanh`` of each input, a smooth actuator limit) is the
same at every node of a step, and is computed once per step by ``name_stage``.
They are translated to numba (:mod:`~auvplan.optimization._numba_codegen`) and cached on
disk (:mod:`~auvplan.optimization._kernel_cache`) under a key made of the serialised ``f``
and ``l``: the first mission with a model pays the compilation (seconds, logged), every
later one, in any process, loads it. :class:`BlockKernels` integrates whole control
intervals of ``m`` RK4 substeps of length ``h`` (zero-order hold, the cost as a quadrature
state; :mod:`~auvplan.optimization.integration`) and differentiates them exactly to second
order through the ``4m`` model evaluations, the **nodes**
``(K_n, ℓ_n) = (f, l)(Y_n, u)``. Every node's argument is linear in the substep's start
``y_j`` and the previous node's ``K`` (``Y_{j,0} = y_j``,
``Y_{j,i} = y_j + h a_i K_{j,i-1}``, ``a = (0, ½, ½, 1)``), and so are the step's results
``y_{j+1} = y_j + h Σ_i b_i K_{j,i}`` and ``L = h Σ_{j,i} b_i ℓ_{j,i}``, ``b = (1, 2, 2, 1)/6``.
With ``D_n = ∂Y_n/∂(x, u)`` the first-order data follow forward,

.. math::

    ∂K_n/∂(x, u) = J_n \tilde D_n,\qquad \tilde D_n = \begin{bmatrix} D_n \\ 0\;\; I\end{bmatrix},
    \qquad ∇_{(x,u)} L = h \sum_n b_n \tilde D_n^T g_n,

and since only the nodes are nonlinear, the Hessian of ``ν L + λᵀ F`` is exactly

.. math::

    \sum_n \tilde D_n^T\, ∇^2_{(y,u)} \big(\bar K_n^T f + ν h b_n l\big)\big|_{Y_n}\, \tilde D_n

with the node adjoints ``K̄`` of a reverse sweep. The node kernels form the products with
``D̃`` symbolically, with ``D`` zero where it structurally is (:func:`_carried_pattern`),
so the code multiplies no structural zero; the sweeps (``forward_batch``,
``reverse_batch``, generated with the node kernels) run point by point through the nodes.
"""

from __future__ import annotations

import hashlib
import logging
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Final, Generic, TypeVar

import casadi as ca
import numpy as np

from auvplan._typing import BoolArray, FloatArray, IntArray
from auvplan.optimization._kernel_cache import load_kernel_module, mark_compiled
from auvplan.optimization._lane_codegen import LANES
from auvplan.optimization._numba_codegen import (
    GENERATOR_VERSION,
    UnsupportedOperation,
    numba_source,
)
from auvplan.optimization._threads import map_threads, pieces

__all__ = ["BlockKernels", "block_kernels"]

logger = logging.getLogger(__name__)

#: RK4 node offsets ``a_i`` (``Y_i = y + h a_i K_{i-1}``) and quadrature weights ``b_i``.
RK4_OFFSETS: Final = (0.0, 0.5, 0.5, 1.0)
RK4_WEIGHTS: Final = (1.0 / 6.0, 2.0 / 6.0, 2.0 / 6.0, 1.0 / 6.0)
#: Largest Hessian kernel translated (SX instructions); larger models stay in CasADi, whose
#: virtual machine starts at once, because numba's compile time grows with the code size.
MAX_KERNEL_INSTRUCTIONS: Final = 12_000
#: Most points evaluated in one piece (bounds the memory of the stored node derivatives).
CHUNK: Final = 8192

#: The RK4 coefficients of a substep of length ``h``, for the functions appended below:
#: ``h b_i`` and the next node's offset ``h a_{i+1}`` (0 after the last node), the values of
#: :data:`RK4_WEIGHTS` and :data:`RK4_OFFSETS` times ``h`` as :meth:`BlockKernels.step` forms them.
_RK4_SOURCE: Final = """
@numba.njit(cache=True, error_model='numpy', nogil=True)
def rk4_coefficients(h):
    factors = (h * (1.0 / 6.0), h * (2.0 / 6.0), h * (2.0 / 6.0), h * (1.0 / 6.0))
    offsets = (h * 0.5, h * 0.5, h * 1.0, 0.0)
    return factors, offsets
"""
#: Closed-loop RK4 simulation appended to every kernel module: it calls the ``value`` kernel
#: in a sequential loop, and numba caches a function only together with the kernels it calls
#: as globals of its own module. Its arithmetic is :meth:`BlockKernels.step`'s, operation by
#: operation (``y = x + (h a_i) K``, ``x' = x + Σ_i (h b_i) K_i`` and ``L = Σ (h b_i) ℓ`` summed
#: in node order): a stage of the path is the step of the stage before, to the bit, and its
#: ``costs`` are the step's.
_CLOSED_LOOP_SOURCE: Final = """
@numba.njit(cache=True, error_model='numpy', nogil=True)
def closed_loop_batch(x0, alpha, mu, gains, p, w, h, n_sub, path, inputs, costs):
    n_points, n_stages, n_x = alpha.shape
    n_u = mu.shape[2]
    start = np.empty(n_x)
    advanced = np.empty(n_x)
    y = np.empty(n_x)
    rate = np.empty(n_x)
    q = np.empty(1)
    stage = np.empty(VALUE_STAGE_SIZE)
    factors, offsets = rk4_coefficients(h)
    for b in range(n_points):
        for t in range(n_x):
            start[t] = x0[b, t]
            path[b, 0, t] = start[t]
        for k in range(n_stages):
            for i in range(n_u):
                s = mu[b, k, i]
                for j in range(n_x):
                    s += gains[b, k, i, j] * (alpha[b, k, j] - start[j])
                inputs[b, k, i] = s
            value_stage(start, inputs[b, k], p[b, k], w[b], stage)
            cost = 0.0
            for j in range(n_sub):
                for t in range(n_x):
                    y[t] = start[t]
                    advanced[t] = start[t]
                for i in range(4):
                    value(y, inputs[b, k], p[b, k], w[b], stage, rate, q)
                    cost += factors[i] * q[0]
                    for t in range(n_x):
                        advanced[t] += factors[i] * rate[t]
                        y[t] = start[t] + offsets[i] * rate[t]
                for t in range(n_x):
                    start[t] = advanced[t]
                    path[b, k * n_sub + j + 1, t] = start[t]
            costs[b, k] = cost
"""
#: The derivative sweeps appended to every kernel module (as the closed loop, for numba's
#: cache), through the ``4m`` nodes of :data:`LANES` points at once (the lane kernels
#: ``first_lanes`` and ``hessian_lanes``, after their ``_stage_lanes`` once per group of points;
#: a last group short of points repeats its last point),
#: with the arithmetic of the chain rule (module notes) in the same order for every lane.
#: ``forward_batch`` stores every node's point ``Y_n`` and ``D_n`` lane-major,
#: ``points (n_nodes, G, n_x, LANES)`` and ``carried (n_nodes, G, n_d, LANES)`` (the ``n_d``
#: entries ``entries`` of ``D``, :func:`_symbolic_kernels`) for ``G = ⌈B / LANES⌉`` groups,
#: for ``reverse_batch``, and returns the step's ``∂F/∂(x, u)``,
#: ``L`` and ``∇L``; ``reverse_batch`` adds ``Σ_n D̃_nᵀ ∇²(K̄_nᵀ f + ν h b_n l) D̃_n`` into
#: ``total (B, n_z, n_z)``.
_SWEEP_SOURCE: Final = """
@numba.njit(cache=True, error_model='numpy', nogil=True)
def lanes_of(rows, first, out):
    n_points = rows.shape[0]
    for lane in range(LANES):
        b = min(first + lane, n_points - 1)
        for t in range(rows.shape[1]):
            out[t, lane] = rows[b, t]


@numba.njit(cache=True, error_model='numpy', nogil=True)
def forward_batch(x, u, p, w, h, n_sub, entries, points, carried, step_jac, cost, cost_grad):
    n_points, n_x = x.shape
    n_d = entries.size
    n_z = step_jac.shape[2]
    rate = np.empty((n_x, LANES))
    q = np.empty((1, LANES))
    rate_d = np.empty((n_d, LANES))
    grad_d = np.empty((n_z, LANES))
    y = np.empty((n_x, LANES))
    dy = np.empty((n_d, LANES))
    advanced = np.empty((n_x, LANES))
    advanced_d = np.empty((n_d, LANES))
    u_lanes = np.empty((u.shape[1], LANES))
    p_lanes = np.empty((p.shape[1], LANES))
    w_lanes = np.empty((w.shape[1], LANES))
    total = np.empty(LANES)
    total_grad = np.empty((n_z, LANES))
    stage = np.empty((FIRST_STAGE_SIZE, LANES))
    factors, offsets = rk4_coefficients(h)
    for g in range(points.shape[1]):
        first_point = g * LANES
        lanes_of(x, first_point, y)
        lanes_of(u, first_point, u_lanes)
        lanes_of(p, first_point, p_lanes)
        lanes_of(w, first_point, w_lanes)
        first_stage_lanes(y, u_lanes, p_lanes, w_lanes, dy, stage)
        for t in range(n_d):
            dy[t, :] = 1.0 if entries[t] // n_z == entries[t] % n_z else 0.0
        total[:] = 0.0
        total_grad[:, :] = 0.0
        for j in range(n_sub):
            n = 4 * j
            advanced[:, :] = y
            points[n, g] = y
            advanced_d[:, :] = dy
            carried[n, g] = dy
            for i in range(4):
                first_lanes(points[n + i, g], u_lanes, p_lanes, w_lanes, carried[n + i, g], stage,
                            rate, q, rate_d, grad_d)
                for lane in range(LANES):
                    total[lane] += factors[i] * q[0, lane]
                for c in range(n_z):
                    for lane in range(LANES):
                        total_grad[c, lane] += factors[i] * grad_d[c, lane]
                for t in range(n_x):
                    for lane in range(LANES):
                        advanced[t, lane] += factors[i] * rate[t, lane]
                for t in range(n_d):
                    for lane in range(LANES):
                        advanced_d[t, lane] += factors[i] * rate_d[t, lane]
                if i < 3:
                    for t in range(n_x):
                        for lane in range(LANES):
                            points[n + i + 1, g, t, lane] = y[t, lane] + offsets[i] * rate[t, lane]
                    for t in range(n_d):
                        for lane in range(LANES):
                            carried[n + i + 1, g, t, lane] = (
                                dy[t, lane] + offsets[i] * rate_d[t, lane]
                            )
            y[:, :] = advanced
            dy[:, :] = advanced_d
        for lane in range(min(LANES, n_points - first_point)):
            b = first_point + lane
            cost[b] = total[lane]
            for c in range(n_z):
                cost_grad[b, c] = total_grad[c, lane]
            step_jac[b] = 0.0
            for t in range(n_d):
                step_jac[b, entries[t] // n_z, entries[t] % n_z] = dy[t, lane]


@numba.njit(cache=True, error_model='numpy', nogil=True)
def reverse_batch(points, carried, u, p, w, h, costate, cost_weight, total):
    n_nodes, n_groups, n_x = points.shape[:3]
    n_points, n_z = total.shape[:2]
    n_upper = n_z * (n_z + 1) // 2
    factors, offsets = rk4_coefficients(h)
    y_bar = np.empty((n_x, LANES))
    start_bar = np.empty((n_x, LANES))
    point_bar = np.empty((n_x, LANES))
    k_bar = np.empty((n_x, LANES))
    weight = np.empty((1, LANES))
    node_upper = np.empty((n_upper, LANES))
    upper = np.empty((n_upper, LANES))
    u_lanes = np.empty((u.shape[1], LANES))
    p_lanes = np.empty((p.shape[1], LANES))
    w_lanes = np.empty((w.shape[1], LANES))
    stage = np.empty((HESSIAN_STAGE_SIZE, LANES))
    for g in range(n_groups):
        first_point = g * LANES
        lanes_of(costate, first_point, y_bar)
        lanes_of(u, first_point, u_lanes)
        lanes_of(p, first_point, p_lanes)
        lanes_of(w, first_point, w_lanes)
        hessian_stage_lanes(points[0, g], u_lanes, p_lanes, w_lanes, k_bar, weight, carried[0, g],
                            stage)
        upper[:, :] = 0.0
        for j in range(n_nodes // 4 - 1, -1, -1):
            start_bar[:, :] = y_bar
            for i in range(3, -1, -1):
                for t in range(n_x):
                    for lane in range(LANES):
                        k_bar[t, lane] = factors[i] * y_bar[t, lane]
                        if i < 3:
                            k_bar[t, lane] += offsets[i] * point_bar[t, lane]
                weight[:, :] = cost_weight * factors[i]
                hessian_lanes(points[4 * j + i, g], u_lanes, p_lanes, w_lanes, k_bar, weight,
                              carried[4 * j + i, g], stage, node_upper, point_bar)
                for t in range(n_upper):
                    for lane in range(LANES):
                        upper[t, lane] += node_upper[t, lane]
                for t in range(n_x):
                    for lane in range(LANES):
                        start_bar[t, lane] += point_bar[t, lane]
            y_bar[:, :] = start_bar
        for lane in range(min(LANES, n_points - first_point)):
            b = first_point + lane
            k = 0
            for r in range(n_z):
                total[b, r, r] += upper[k, lane]
                k += 1
                for c in range(r + 1, n_z):
                    total[b, r, c] += upper[k, lane]
                    total[b, c, r] += upper[k, lane]
                    k += 1
"""
#: Everything appended to the generated node kernels (part of the cache key).
_APPENDIX: Final = _RK4_SOURCE + _CLOSED_LOOP_SOURCE + _SWEEP_SOURCE
_BUILT: dict[tuple[str, Path | None], BlockKernels] = {}


def _carried_pattern(jacobian: ca.Sparsity, n_x: int, n_u: int) -> BoolArray:
    """Where a node's ``D = ∂Y/∂(x, u)`` can be nonzero, at any node of any step (``n_x × n_z``).

    ``D_0 = [I 0]`` and every later ``D`` is a start's plus multiples of ``J D̃`` (module notes),
    so the pattern is the least fixed point of ``S ← S ∪ S_J S̃`` from ``[I 0]``, with ``S_J``
    the structural nonzeros of ``J = ∂f/∂(y, u)``: e.g. no rate depends on a position, so no
    other coordinate's ``D`` depends on it.
    """
    n_z = n_x + n_u
    rows, columns = jacobian.get_triplet()
    depends = np.zeros((n_x, n_z), dtype=np.int64)
    depends[rows, columns] = 1
    pattern = np.eye(n_x, n_z, dtype=np.int64)
    inputs = np.eye(n_u, n_z, n_x, dtype=np.int64)  # D̃'s rows [0 I]
    while True:
        grown = (pattern + depends @ np.vstack([pattern, inputs])) > 0
        if np.array_equal(grown, pattern > 0):
            return grown
        pattern = grown.astype(np.int64)


def _symbolic_kernels(
    dynamics: ca.Function, running_cost: ca.Function
) -> tuple[dict[str, ca.Function], IntArray]:
    """The three kernel Functions (module docstring) on SX symbols, and ``D``'s entries.

    ``D`` enters as one symbol per entry of :func:`_carried_pattern` (row-major order; the
    others are the zeros they are), and ``first`` returns those entries of ``J D̃`` (the
    others are zero too: the pattern is closed under ``S ← S_J S̃``). The entries are
    returned as their row-major indices into ``n_x × n_z``.
    """
    n_x, n_u, n_p = (int(dynamics.numel_in(i)) for i in range(3))
    n_z = n_x + n_u
    y, u, p = ca.SX.sym("y", n_x), ca.SX.sym("u", n_u), ca.SX.sym("p", n_p)
    w, lam, nu = (
        ca.SX.sym("w", int(running_cost.numel_in(3))),
        ca.SX.sym("lam", n_x),
        ca.SX.sym("nu"),
    )
    rate, cost = dynamics(y, u, p), running_cost(y, u, p, w)
    yu = ca.vertcat(y, u)
    jacobian = ca.jacobian(rate, yu)
    rows, columns = np.nonzero(_carried_pattern(jacobian.sparsity(), n_x, n_u))
    d_entries = ca.SX.sym("D", rows.size)
    carried = ca.SX.zeros(n_x, n_z)
    for k, (r, c) in enumerate(zip(rows, columns, strict=True)):
        carried[int(r), int(c)] = d_entries[k]
    tilde = ca.vertcat(carried, ca.horzcat(ca.SX.zeros(n_u, n_x), ca.SX.eye(n_u)))
    hessian, gradient = ca.hessian(nu * cost + ca.dot(lam, rate), yu)
    curvature = ca.mtimes([tilde.T, hessian, tilde])
    upper = ca.vertcat(*(curvature[i, j] for i in range(n_z) for j in range(i, n_z)))

    def dense(name: str, args: list[ca.SX], outputs: list[ca.SX]) -> ca.Function:
        return ca.Function(name, args, ca.cse([ca.densify(out) for out in outputs]))

    rate_d = ca.mtimes(jacobian, tilde)
    functions = {
        "value": dense("model_value", [y, u, p, w], [rate, cost]),
        "first": dense(
            "model_first",
            [y, u, p, w, d_entries],
            [
                rate,
                cost,
                ca.vertcat(*(rate_d[int(r), int(c)] for r, c in zip(rows, columns, strict=True))),
                ca.mtimes(tilde.T, ca.gradient(cost, yu)),
            ],
        ),
        "hessian": dense(
            "model_hessian", [y, u, p, w, lam, nu, d_entries], [upper, gradient[:n_x]]
        ),
    }
    return functions, rows * n_z + columns


def _pieces(n_points: int, threads: int) -> list[slice]:
    """The points in one piece per thread, none over :data:`CHUNK`."""
    return pieces(n_points, threads, CHUNK)


_T = TypeVar("_T")


@dataclass(eq=False)
class LastCall(Generic[_T]):
    """What was computed from the last arrays given, kept with copies of them (one entry).

    ``get`` returns it only for arrays equal to those, entry by entry (``None`` else): a
    memcmp of the arguments instead of the work they stand for.
    """

    _entry: tuple[tuple[FloatArray, ...], _T] | None = None

    def get(self, *arrays: FloatArray) -> _T | None:
        """The value kept for these arrays, or ``None``."""
        if self._entry is None:
            return None
        known, value = self._entry
        if len(known) == len(arrays) and all(
            np.array_equal(a, b) for a, b in zip(known, arrays, strict=True)
        ):
            return value
        return None

    def put(self, value: _T, *arrays: FloatArray) -> _T | None:
        """Keep ``value`` for copies of ``arrays`` in place of the last; returns the last."""
        last = None if self._entry is None else self._entry[1]
        self._entry = (tuple(np.array(a) for a in arrays), value)
        return last


@dataclass(frozen=True)
class _Forward:
    """A forward sweep's nodes: their points and derivatives, for the reverse sweep.

    ``points`` ``Y_n (n_nodes, G, n_x, LANES)``, ``carried`` ``D_n (n_nodes, G, n_d, LANES)``
    (:attr:`BlockKernels.carried_entries`; point ``b`` in group ``b // LANES``, lane
    ``b % LANES``).
    """

    points: FloatArray
    carried: FloatArray


@dataclass(frozen=True)
class _Sweeps:
    """The forward sweeps of a batch, one per piece, and the step's first-order data of all.

    ``first_order`` is ``(∂F/∂(x, u), L, ∇L)`` of every point; each piece's arrays are views
    of their rows (written there by its sweep: no gathering of the pieces).
    """

    pieces: list[_Forward]
    first_order: tuple[FloatArray, FloatArray, FloatArray]


@dataclass
class _SweepMemory:
    """One thread's forward sweeps: the last remembered ones and the ones they evicted."""

    last: LastCall[_Sweeps] = field(default_factory=LastCall)
    """The sweeps of the last :meth:`BlockKernels.first_order` call, by its arguments: a
    Newton step asks for the Hessians at the trajectory it just linearised."""
    spares: list[_Forward] = field(default_factory=list)
    """The sweeps ``last`` held before (one per piece), whose memory the next remembered
    sweeps write over."""


@dataclass(frozen=True, eq=False)
class BlockKernels:
    """The compiled kernels of one block model and its RK4 steps.

    Every method takes points on axis 0: ``x (B, n_x)``, ``u (B, n_u)``, ``p (B, n_p)``,
    weights ``w (B, n_w)``; ``h`` is the substep length [s] and ``n_substeps`` the substeps
    per step. ``threads``: the points are split into that many pieces, evaluated on as many
    threads (:func:`~auvplan.optimization._threads.map_threads`; the same results for any
    number).
    """

    module: ModuleType
    n_x: int
    n_u: int
    n_p: int
    n_w: int
    carried_entries: IntArray
    """The entries of a node's ``D`` the sweeps carry (row-major indices into ``n_x × n_z``;
    :func:`_symbolic_kernels`), the module's ``CARRIED_ENTRIES``."""
    _memory: threading.local = field(default_factory=threading.local, repr=False)
    """Each calling thread's :class:`_SweepMemory` (kernels are shared by every model of a
    vehicle type: solves in two threads must not write over each other's sweeps)."""

    def _thread_memory(self) -> _SweepMemory:
        """The calling thread's remembered sweeps (made on its first call)."""
        if not hasattr(self._memory, "sweeps"):
            self._memory.sweeps = _SweepMemory()
        memory: _SweepMemory = self._memory.sweeps
        return memory

    def _sweeps(
        self,
        x: FloatArray,
        u: FloatArray,
        p: FloatArray,
        w: FloatArray,
        h: float,
        n_substeps: int,
        threads: int,
        remember: bool = True,
    ) -> _Sweeps:
        """The forward sweeps of every piece of :func:`_pieces` (reused when the arguments repeat).

        ``remember=False`` leaves the remembered sweeps alone (e.g. Jacobians at other points
        between a linearisation and its Hessians).
        """
        arguments = (x, u, p, w, np.array([h, n_substeps, CHUNK, threads], dtype=np.float64))
        memory = self._thread_memory()
        sweeps = memory.last.get(*arguments)
        if sweeps is None:
            pieces = _pieces(x.shape[0], threads)
            spares: list[_Forward | None] = [None] * len(pieces)
            if remember:  # else the sweeps outlive this call: the caller reads them
                spares[: len(memory.spares)] = memory.spares[: len(pieces)]
            n_points, n_z = x.shape[0], self.n_x + self.n_u
            whole = (
                np.empty((n_points, self.n_x, n_z)),
                np.empty(n_points),
                np.empty((n_points, n_z)),
            )

            def forward(work: tuple[slice, _Forward | None]) -> _Forward:
                rows, spare = work
                out = (whole[0][rows], whole[1][rows], whole[2][rows])
                return self._forward(x[rows], u[rows], p[rows], w[rows], h, n_substeps, out, spare)

            sweeps = _Sweeps(
                map_threads(forward, list(zip(pieces, spares, strict=True)), threads), whole
            )
            if remember:
                last = memory.last.put(sweeps, *arguments)
                memory.spares[:] = [] if last is None else last.pieces
        return sweeps

    def step(
        self, x: FloatArray, u: FloatArray, p: FloatArray, w: FloatArray, h: float, n_substeps: int
    ) -> tuple[FloatArray, FloatArray]:
        """``F (B, n_x)`` and ``L (B,)`` of one control interval."""
        n_points = x.shape[0]
        cost = np.zeros(n_points)
        rate, increment = np.empty((n_points, self.n_x)), np.empty((n_points, 1))
        for _ in range(n_substeps):
            y, advanced = x, x.copy()
            for i in range(4):
                self.module.value_batch(np.ascontiguousarray(y), u, p, w, rate, increment)
                advanced += h * RK4_WEIGHTS[i] * rate
                cost += h * RK4_WEIGHTS[i] * increment[:, 0]
                if i < 3:
                    y = x + h * RK4_OFFSETS[i + 1] * rate
            x = advanced
        return x, cost

    def _forward(
        self,
        x: FloatArray,
        u: FloatArray,
        p: FloatArray,
        w: FloatArray,
        h: float,
        n_substeps: int,
        out: tuple[FloatArray, FloatArray, FloatArray],
        spare: _Forward | None = None,
    ) -> _Forward:
        """Forward sweep through the ``4m`` nodes with first-order derivatives.

        ``out``: where the step's ``(∂F/∂(x, u), L, ∇L)`` of these points are written.
        ``spare``: a sweep no longer needed, whose node arrays are written over when their
        shapes match (fresh memory is first touched page by page).
        """
        n_points, n_x = x.shape[0], self.n_x
        nodes = (4 * n_substeps, -(-n_points // LANES))
        if spare is not None and spare.points.shape == (*nodes, n_x, LANES):
            points, carried = spare.points, spare.carried
        else:
            points = np.empty((*nodes, n_x, LANES))
            carried = np.empty((*nodes, self.carried_entries.size, LANES))
        step_jac, cost, cost_grad = out
        self.module.forward_batch(
            np.ascontiguousarray(x), u, p, w, h, n_substeps, self.carried_entries, points,
            carried, step_jac, cost, cost_grad,
        )  # fmt: skip
        return _Forward(points, carried)

    def first_order(
        self,
        x: FloatArray,
        u: FloatArray,
        p: FloatArray,
        w: FloatArray,
        h: float,
        n_substeps: int,
        remember: bool = True,
        threads: int = 1,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``∂F/∂(x, u) (B, n_x, n_z)``, ``L (B,)`` and ``∇_{(x,u)} L (B, n_z)``.

        ``remember``: keep the forward sweeps for :meth:`hessian` at the same arguments.
        """
        # fresh arrays for every sweep, never written after it
        return self._sweeps(x, u, p, w, h, n_substeps, threads, remember).first_order

    def hessian(
        self,
        x: FloatArray,
        u: FloatArray,
        p: FloatArray,
        w: FloatArray,
        h: float,
        n_substeps: int,
        costate: FloatArray,
        cost_weight: float = 1.0,
        threads: int = 1,
    ) -> FloatArray:
        """``∇²_{(x,u)} (ν L + λᵀ F)`` of shape ``(B, n_z, n_z)`` (``λ = costate``, ``ν``)."""
        n_z = self.n_x + self.n_u
        total = np.zeros((x.shape[0], n_z, n_z))
        sweeps = self._sweeps(x, u, p, w, h, n_substeps, threads)

        def reverse(piece: tuple[slice, _Forward]) -> None:
            rows, forward = piece
            self._reverse(forward, u[rows], p[rows], w[rows], h, costate[rows], cost_weight,
                          total[rows])  # fmt: skip

        pieces = list(zip(_pieces(x.shape[0], threads), sweeps.pieces, strict=True))
        map_threads(reverse, pieces, threads)
        return total

    def _reverse(
        self,
        forward: _Forward,
        u: FloatArray,
        p: FloatArray,
        w: FloatArray,
        h: float,
        costate: FloatArray,
        cost_weight: float,
        total: FloatArray,
    ) -> None:
        """Reverse sweep: node adjoints ``K̄`` and the node Hessians added into ``total``."""
        self.module.reverse_batch(
            forward.points, forward.carried, u, p, w, h, np.ascontiguousarray(costate),
            cost_weight, total,
        )  # fmt: skip

    def closed_loop(
        self,
        x0: FloatArray,
        reference_states: FloatArray,
        reference_inputs: FloatArray,
        gains: FloatArray,
        p: FloatArray,
        w: FloatArray,
        h: float,
        n_substeps: int,
        threads: int = 1,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Independent closed-loop simulations ``u_k = μ_k + K_k (α_k − x_k)`` (held over a step).

        Parameters
        ----------
        x0 : ndarray of shape (B, n_x)
            Initial states.
        reference_states, reference_inputs : ndarray of shape (B, N, n_x), (B, N, n_u)
            ``α_k`` and ``μ_k``.
        gains : ndarray of shape (B, N, n_u, n_x)
            ``K_k``.
        p : ndarray of shape (B, N, n_p)
            Stage parameters.
        w : ndarray of shape (B, n_w)
            Weights.
        h : float
            Substep length [s].
        n_substeps : int
            Substeps per stage.

        Returns
        -------
        path : ndarray of shape (B, N · n_substeps + 1, n_x)
            The state after every substep (every ``n_substeps``-th is a stage state; each the
            :meth:`step` of the one before, to the bit).
        inputs : ndarray of shape (B, N, n_u)
            The inputs applied.
        costs : ndarray of shape (B, N)
            The stage costs ``L`` along the path (:meth:`step`'s, to the bit).
        """
        n_points, n_stages = reference_inputs.shape[:2]
        path = np.empty((n_points, n_stages * n_substeps + 1, self.n_x))
        inputs = np.empty((n_points, n_stages, self.n_u))
        costs = np.empty((n_points, n_stages))
        arrays = [
            np.ascontiguousarray(a) for a in (x0, reference_states, reference_inputs, gains, p, w)
        ]
        map_threads(
            lambda rows: self.module.closed_loop_batch(
                *(a[rows] for a in arrays), h, n_substeps, path[rows], inputs[rows], costs[rows]
            ),
            _pieces(n_points, threads),
            threads,
        )
        return path, inputs, costs


def _warm_up(kernels: BlockKernels) -> None:
    """Call every kernel once: compiles it (new model) or loads its machine code."""
    z, u = np.zeros((1, kernels.n_x)), np.zeros((1, kernels.n_u))
    p, w = np.zeros((1, kernels.n_p)), np.zeros((1, kernels.n_w))
    kernels.step(z, u, p, w, 0.1, 1)
    kernels.hessian(z, u, p, w, 0.1, 1, np.zeros((1, kernels.n_x)))
    gains = np.zeros((1, 1, kernels.n_u, kernels.n_x))
    kernels.closed_loop(z, z[:, None], u[:, None], gains, p[:, None], w, 0.1, 1)


def block_kernels(
    dynamics: ca.Function, running_cost: ca.Function, cache_dir: Path | None = None
) -> BlockKernels:
    """The compiled kernels of ``f(x, u, p)`` and ``l(x, u, p, w)`` (module notes).

    Raises
    ------
    UnsupportedOperation
        If the model uses an operation the translator does not know, or its Hessian kernel
        exceeds :data:`MAX_KERNEL_INSTRUCTIONS` (evaluate it with CasADi then).
    """
    key = "\n".join(
        [
            str(GENERATOR_VERSION),
            _APPENDIX,
            dynamics.serialize(),
            running_cost.serialize(),
        ]
    )
    memo = (hashlib.sha256(key.encode("utf-8")).hexdigest(), cache_dir)
    built = _BUILT.get(memo)
    if built is not None:
        return built

    def source() -> str:
        functions, entries = _symbolic_kernels(dynamics, running_cost)
        size = functions["hessian"].n_instructions()
        if size > MAX_KERNEL_INSTRUCTIONS:
            raise UnsupportedOperation(
                f"the model's Hessian has {size} instructions (> {MAX_KERNEL_INSTRUCTIONS})"
            )
        carried = f"\nCARRIED_ENTRIES = np.array({entries.tolist()}, dtype=np.int64)\n"
        return numba_source(
            functions,
            f"model kernels {memo[0][:24]}",
            _APPENDIX + carried,
            batched=("value",),
            lanes=("first", "hessian"),  # they run inside the sweeps only
            stage_inputs=(1, 2, 3),  # u, p, w: the same at every node of a step
        )

    module, is_new = load_kernel_module(key, source, cache_dir)
    n_x, n_u, n_p = (int(dynamics.numel_in(i)) for i in range(3))
    kernels = BlockKernels(
        module, n_x, n_u, n_p, int(running_cost.numel_in(3)), module.CARRIED_ENTRIES
    )
    started = time.perf_counter()
    if is_new:
        logger.info("compiling the stage kernels of a new vehicle model (once)")
    _warm_up(kernels)
    mark_compiled(module)
    if is_new:
        logger.info("stage kernels compiled in %.0f s", time.perf_counter() - started)
    _BUILT[memo] = kernels
    return kernels
