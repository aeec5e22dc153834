"""Eigenvalue clipping of many small symmetric matrices, :data:`LANES` at a time (cyclic Jacobi).

The convexified model of the LQ ladder (:func:`auvplan.optimization.lq.convexify`) projects
thousands of small blocks (e.g. ``8 × 8``, a vehicle's curved states and its inputs, at every
stage) onto ``{W ⪰ floor·I}``. LAPACK takes ~5 µs per ``8 × 8`` block, most of it overhead;
here :data:`LANES` blocks of one size (up to :data:`JACOBI_MAX_SIZE`) are diagonalised together
by the cyclic Jacobi method, every rotation one set of LLVM vector instructions on
``<LANES x double>`` (numba intrinsics, like :mod:`~auvplan.optimization._lane_codegen`'s
kernels).

A rotation in the plane ``(p, q)`` with ``t = tan φ`` the smaller root of
``t² + 2θt − 1 = 0``, ``θ = (a_qq − a_pp) / (2 a_pq)``, ``c = 1/√(1 + t²)``, ``s = t c``,
zeroes ``a_pq`` (``A ← Jᵀ A J``, ``V ← V J``); sweeps over every ``p < q`` until the
off-diagonal part of a block is below :data:`TOLERANCE` of its norm, then ``V max(Λ, floor) Vᵀ``.
A block whose lane has converged is rotated by ``c = 1, s = 0`` (exactly nothing), so its
result does not depend on the blocks it shares a vector with. Jacobi is accurate to the
rounding of each eigenvalue relative to the block's norm (Demmel & Veselić 1992).
"""

from __future__ import annotations

from typing import Any, Final

import numba
import numpy as np
from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic

from auvplan._typing import FloatArray
from auvplan.optimization._lane_codegen import (
    LANES,
    VECTOR,
    splat,
    vector_intrinsic,
    vector_pointer,
)

__all__ = ["clip_blocks"]

#: Convergence: ``Σ_{i<j} a_ij² ≤ TOLERANCE² ‖A‖_F²`` for every block of a group.
TOLERANCE: Final = 1e-15
#: Largest block diagonalised by Jacobi: its ``O(n³)`` per sweep catches up with LAPACK's
#: overhead as blocks grow (random ``n × n`` blocks: 2.9 against 8.1 µs at 8, 19 against 28 µs
#: at 16, 25 against 32 µs at 20 — about even on a 5-vehicle family mission's 20 × 20 blocks —
#: 449 against 222 µs at 50); larger blocks go to LAPACK (``numpy.linalg.eigh``).
JACOBI_MAX_SIZE: Final = 16
#: Sweeps before a group stops anyway (a sweep squares the off-diagonal norm near convergence:
#: 5–6 for an ``8 × 8`` block; a non-finite block never converges and stays non-finite).
MAX_SWEEPS: Final = 40


def _cosine_sine(builder: ir.IRBuilder, app: Any, apq: Any, aqq: Any, idle: Any) -> tuple[Any, Any]:
    """Each lane's ``c``, ``s`` zeroing ``a_pq`` (module notes); ``c = 1, s = 0`` where ``idle``."""
    theta = builder.fdiv(builder.fsub(aqq, app), builder.fmul(splat(2.0), apq))
    root = vector_intrinsic(
        builder, "llvm.sqrt", builder.fadd(builder.fmul(theta, theta), splat(1.0))
    )
    t = builder.fdiv(splat(1.0), builder.fadd(vector_intrinsic(builder, "llvm.fabs", theta), root))
    t = builder.select(builder.fcmp_ordered("<", theta, splat(0.0)), builder.fneg(t), t)
    t = builder.select(
        builder.or_(idle, builder.fcmp_ordered("==", apq, splat(0.0))), splat(0.0), t
    )
    c = builder.fdiv(
        splat(1.0),
        vector_intrinsic(builder, "llvm.sqrt", builder.fadd(builder.fmul(t, t), splat(1.0))),
    )
    return c, builder.fmul(t, c)


def _rotate(builder: ir.IRBuilder, base: Any, i: Any, j: Any, c: Any, s: Any) -> None:
    """``(x_i, x_j) ← (c x_i − s x_j, s x_i + c x_j)`` on the vectors ``i``, ``j`` at ``base``."""
    pointer_i, pointer_j = builder.gep(base, [i]), builder.gep(base, [j])
    x_i, x_j = builder.load(pointer_i, align=8), builder.load(pointer_j, align=8)
    builder.store(builder.fsub(builder.fmul(c, x_i), builder.fmul(s, x_j)), pointer_i, align=8)
    builder.store(builder.fadd(builder.fmul(s, x_i), builder.fmul(c, x_j)), pointer_j, align=8)


@intrinsic
def _jacobi_rotation(_typingctx: Any, a: Any, v: Any, p: Any, q: Any, done: Any) -> Any:
    """One Jacobi rotation in the plane ``(p, q)`` of every lane: ``A ← Jᵀ A J``, ``V ← V J``.

    ``a``, ``v``: C-contiguous float64 arrays ``(n, n, LANES)``; ``done``: ``(LANES,)``,
    nonzero for the lanes left as they are.
    """

    def codegen(context: Any, builder: ir.IRBuilder, signature: Any, args: Any) -> Any:
        array = context.make_array(signature.args[0])(context, builder, args[0])
        n = cgutils.unpack_tuple(builder, array.shape, 3)[0]  # type: ignore[no-untyped-call]
        base_a = builder.bitcast(array.data, VECTOR.as_pointer())
        base_v = vector_pointer(context, builder, signature.args[1], args[1])
        row_p, row_q = builder.mul(args[2], n), builder.mul(args[3], n)
        app, apq, aqq = (
            builder.load(builder.gep(base_a, [index]), align=8)
            for index in (builder.add(row_p, args[2]), builder.add(row_p, args[3]),
                          builder.add(row_q, args[3]))
        )  # fmt: skip
        done_ = builder.load(vector_pointer(context, builder, signature.args[4], args[4]), align=8)
        c, s = _cosine_sine(builder, app, apq, aqq, builder.fcmp_ordered("!=", done_, splat(0.0)))
        with cgutils.for_range(builder, n) as loop:  # A J: columns p, q
            row_k = builder.mul(loop.index, n)
            _rotate(builder, base_a, builder.add(row_k, args[2]), builder.add(row_k, args[3]), c, s)
        with cgutils.for_range(builder, n) as loop:  # Jᵀ (A J): rows p, q
            k = loop.index
            _rotate(builder, base_a, builder.add(row_p, k), builder.add(row_q, k), c, s)
        with cgutils.for_range(builder, n) as loop:  # V J
            row_k = builder.mul(loop.index, n)
            _rotate(builder, base_v, builder.add(row_k, args[2]), builder.add(row_k, args[3]), c, s)
        return context.get_dummy_value()

    return types.void(a, v, p, q, done), codegen


@numba.njit(cache=True, nogil=True)
def _converged(a: FloatArray, done: FloatArray) -> bool:
    """Mark the lanes of ``a (n, n, LANES)`` whose off-diagonal part is negligible.

    Returns whether every lane is marked.
    """
    n = a.shape[0]
    finished = True
    for lane in range(LANES):
        off = diagonal = 0.0
        for i in range(n):
            diagonal += a[i, i, lane] * a[i, i, lane]
            for j in range(i + 1, n):
                off += a[i, j, lane] * a[i, j, lane]
        done[lane] = 1.0 if off <= TOLERANCE * TOLERANCE * (diagonal + 2.0 * off) else 0.0
        finished = finished and done[lane] != 0.0
    return finished


@numba.njit(cache=True, nogil=True)
def _jacobi(a: FloatArray, v: FloatArray) -> None:
    """Diagonalise the ``LANES`` symmetric blocks ``a (n, n, LANES)`` in place (vectors: ``v``)."""
    n = a.shape[0]
    for i in range(n):
        for j in range(n):
            v[i, j, :] = 1.0 if i == j else 0.0
    done = np.empty(LANES)
    for _ in range(MAX_SWEEPS):
        if _converged(a, done):
            return
        for p in range(n - 1):
            for q in range(p + 1, n):
                _jacobi_rotation(a, v, p, q, done)  # type: ignore[call-arg]


@numba.njit(cache=True, nogil=True)
def clip_blocks(blocks: FloatArray, floor: float) -> None:
    """``V max(Λ, floor) Vᵀ`` of every symmetric block ``blocks (B, n, n)``, written over it.

    ``LANES`` blocks at a time (:func:`_jacobi`; a last group short of blocks repeats its
    last one), or one by one by LAPACK above :data:`JACOBI_MAX_SIZE`. Each result depends on
    its own block only.
    """
    n_blocks, n = blocks.shape[0], blocks.shape[1]
    if n > JACOBI_MAX_SIZE:
        for b in range(n_blocks):
            values, vectors = np.linalg.eigh(blocks[b])
            blocks[b] = (vectors * np.maximum(values, floor)) @ vectors.T  # BLAS
        return
    a, v = np.empty((n, n, LANES)), np.empty((n, n, LANES))
    for first in range(0, n_blocks, LANES):
        for lane in range(LANES):
            a[:, :, lane] = blocks[min(first + lane, n_blocks - 1)]
        _jacobi(a, v)
        for lane in range(min(LANES, n_blocks - first)):
            values = np.array([a[i, i, lane] for i in range(n)])
            _project(v[:, :, lane], values, floor, blocks[first + lane])


@numba.njit(cache=True, nogil=True)
def _project(vectors: FloatArray, values: FloatArray, floor: float, out: FloatArray) -> None:
    """``out = V max(Λ, floor) Vᵀ``, symmetric to the bit (the upper triangle mirrored).

    For the small blocks of :func:`_jacobi` (``O(n³)`` scalar operations; LAPACK's larger
    blocks take BLAS's product instead).
    """
    n = values.size
    for i in range(n):
        for j in range(i, n):
            value = 0.0
            for k in range(n):
                value += vectors[i, k] * max(values[k], floor) * vectors[j, k]
            out[i, j] = out[j, i] = value
