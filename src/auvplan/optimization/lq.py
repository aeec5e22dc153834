"""LQ search direction of PRONTO: discrete Riccati with cross term and the fallback ladder.

Newton (exact weights) → convexified (per-stage eigenvalue clipping) → steepest (constant
positive-definite model); ``reference/pronto.md`` §4.2 and §6.3.
"""

from __future__ import annotations

import enum
import logging
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from auvplan._typing import FloatArray, IntArray
from auvplan.errors import SolverError
from auvplan.optimization import _kernels
from auvplan.optimization._threads import map_threads, pieces
from auvplan.optimization.stages import Linearization, StageWeights

__all__ = [
    "DirectionType",
    "LqDirection",
    "LqFactor",
    "convexify",
    "directional_derivative",
    "quadratic_form",
    "solve_lq_direction",
]

logger = logging.getLogger(__name__)


class DirectionType(enum.Enum):
    """Which quadratic model produced the search direction (the fallback ladder)."""

    NEWTON = "newton"
    CONVEXIFIED = "convexified"
    STEEPEST = "steepest"


def convexify(weights: StageWeights, floor: float, threads: int = 1) -> StageWeights:
    """Clip the eigenvalues of every ``[[Q, S], [Sᵀ, R]]`` and of ``P_N`` at ``floor``.

    The convexified model of the ladder. Only the blocks of coupled coordinates that fail a
    Cholesky test above the floor change
    (:func:`auvplan.optimization._kernels.clip_stage_weights`); the stages are split over
    ``threads`` threads (the same results for any number).

    Returns
    -------
    StageWeights
        Positive-definite weights (projection onto ``{W ⪰ floor·I}`` per stage).
    """
    q, s, r = (np.ascontiguousarray(w) for w in (weights.Q, weights.S, weights.R))
    clipped = (np.empty_like(q), np.empty_like(s), np.empty_like(r))
    map_threads(
        lambda rows: _kernels.clip_stage_weights(
            q[rows], s[rows], r[rows], floor, (clipped[0][rows], clipped[1][rows], clipped[2][rows])
        ),
        pieces(q.shape[0], threads, q.shape[0]),
        threads,
    )
    return StageWeights(*clipped, _clipped_matrix(weights.P_N, floor))


def _clipped_matrix(matrix: FloatArray, floor: float) -> FloatArray:
    """``V max(Λ, floor) Vᵀ`` of ``½(M + Mᵀ)``."""
    values, vectors = np.linalg.eigh(0.5 * (matrix + matrix.T))
    clipped: FloatArray = (vectors * np.maximum(values, floor)) @ vectors.T
    return clipped


@dataclass(frozen=True)
class LqDirection:
    """Search direction ``ζ = (z, v)`` from the LQ subproblem.

    Attributes
    ----------
    z : ndarray of shape (N + 1, n_x)
        State direction (``z_0 = 0``).
    v : ndarray of shape (N, n_u)
        Input direction.
    slope : float
        ``Dh·ζ`` (negative for a descent direction; ``−ζᵀ W ζ`` for the model ``W`` that
        produced it).
    direction : DirectionType
        Ladder level used.
    factor : LqFactor, optional
        Its model's Riccati factorisation (:meth:`LqFactor.slope` for other gradients).
    """

    z: FloatArray
    v: FloatArray
    slope: float
    direction: DirectionType
    factor: LqFactor | None = None


@dataclass(frozen=True)
class LqFactor:
    """The Riccati factorisation of an LQ model: its solution for any gradients.

    Attributes
    ----------
    A, B : ndarray
        The linearisation's ``F_x (N, n_x, n_x)``, ``F_u (N, n_x, n_u)``.
    feedback : ndarray of shape (N, n_u, n_x)
        ``K^o``.
    m_inverse : ndarray of shape (N, n_u, n_u)
        ``M_k⁻¹ = (R_k + B_kᵀ P_{k+1} B_k)⁻¹``.
    """

    A: FloatArray
    B: FloatArray
    feedback: FloatArray
    m_inverse: FloatArray

    def slope(self, linearization: Linearization) -> float:
        """``Dh·ζ`` of the model's minimiser ``ζ`` for the gradients of ``linearization``.

        ``−Dh·ζ = gᵀ H⁻¹ g`` in the model's metric: a backward sweep for the feed-forward
        (:func:`~auvplan.optimization._kernels.lq_feedforward`) and a forward pass, with no
        factorisation.
        """
        lin = linearization
        feedforward = _kernels.lq_feedforward(
            self.A, self.B, self.feedback, self.m_inverse,
            *(np.ascontiguousarray(g) for g in (lin.a, lin.b, lin.m_x)),
        )  # fmt: skip
        z, v = _kernels.lq_forward(self.A, self.B, self.feedback, feedforward)
        return directional_derivative(lin, z, v)


def quadratic_form(weights: StageWeights, z: FloatArray, v: FloatArray) -> float:
    """``Σ_k (z_kᵀ Q_k z_k + 2 z_kᵀ S_k v_k + v_kᵀ R_k v_k) + z_Nᵀ P_N z_N`` (``D²`` of a model)."""
    zs, zn = z[:-1], z[-1]
    return float(
        np.einsum("ki,kij,kj->", zs, weights.Q, zs)
        + 2.0 * np.einsum("ki,kij,kj->", zs, weights.S, v)
        + np.einsum("ki,kij,kj->", v, weights.R, v)
        + zn @ weights.P_N @ zn
    )


def directional_derivative(linearization: Linearization, z: FloatArray, v: FloatArray) -> float:
    """``Dh·ζ = Σ_k (a_kᵀ z_k + b_kᵀ v_k) + m_xᵀ z_N`` for ``ζ = (z, v)`` (§3.1)."""
    lin = linearization
    return float(np.sum(lin.a * z[:-1]) + np.sum(lin.b * v) + lin.m_x @ z[-1])


def block_ranges(groups: tuple[IntArray, ...], n_x: int, n_u: int) -> tuple[IntArray, IntArray]:
    """``(start, stop)`` rows of each group's states and inputs, shape ``(n_blocks, 2)`` each.

    ``groups`` are index sets of ``z = (x, u)`` that tile it (e.g. one per vehicle,
    :func:`~auvplan.optimization.separable.coordinate_groups`); without groups, or when
    a group's states or inputs are not one contiguous range, the whole ``x`` and ``u`` form
    one block.
    """
    whole = np.array([[0, n_x]], dtype=np.int64), np.array([[0, n_u]], dtype=np.int64)
    x_blocks: list[tuple[int, int]] = []
    u_blocks: list[tuple[int, int]] = []
    for group in groups:
        states, inputs = group[group < n_x], group[group >= n_x] - n_x
        for indices, ranges in ((states, x_blocks), (inputs, u_blocks)):
            if indices.size == 0:
                ranges.append((0, 0))
                continue
            start, stop = int(indices.min()), int(indices.max()) + 1
            if stop - start != indices.size:  # not one contiguous range
                return whole
            ranges.append((start, stop))
    if not groups:
        return whole
    return np.array(x_blocks, dtype=np.int64), np.array(u_blocks, dtype=np.int64)


def _try_direction(
    linearization: Linearization,
    weights: StageWeights,
    direction: DirectionType,
    blocks: tuple[IntArray, IntArray],
) -> LqDirection | None:
    """The direction of one ladder level (``None`` if its model fails)."""
    lin = linearization
    feedback, feedforward, m_inverse, failed = _kernels.lq_backward(
        lin.A,
        lin.B,
        np.ascontiguousarray(weights.Q),
        np.ascontiguousarray(weights.S),
        np.ascontiguousarray(weights.R),
        lin.a,
        lin.b,
        np.ascontiguousarray(weights.P_N),
        np.ascontiguousarray(lin.m_x),
        *blocks,
    )
    if failed >= 0:
        logger.debug("%s LQ model not positive definite at stage %d", direction.value, failed)
        return None
    z, v = _kernels.lq_forward(lin.A, lin.B, feedback, feedforward)
    slope = directional_derivative(lin, z, v)
    if not (np.isfinite(slope) and np.all(np.isfinite(z))):
        return None
    if slope > 0.0:
        logger.debug("%s direction is not a descent direction (Dh·ζ = %g)", direction.value, slope)
        return None
    return LqDirection(z, v, slope, direction, LqFactor(lin.A, lin.B, feedback, m_inverse))


def solve_lq_direction(
    linearization: Linearization,
    weights: StageWeights,
    *,
    quasi_weights: Callable[[], StageWeights] | None = None,
    steepest_weights: StageWeights | None = None,
    eigenvalue_floor: float = 1e-8,
    groups: tuple[IntArray, ...] = (),
    threads: int = 1,
) -> LqDirection:
    """Search direction by the discrete Riccati recursion with cross term (§6.3).

    Fallback ladder: Newton (``weights``) → convexified quasi-Newton (eigenvalue-clipped
    ``quasi_weights()``, or clipped ``weights`` when none given: :func:`convexify`) →
    steepest (``steepest_weights``, e.g. the regulator weights). A level is
    rejected when some ``M_k = R_k + B_kᵀ P_{k+1} B_k`` fails the Cholesky test or
    ``Dh·ζ > 0``.

    Parameters
    ----------
    linearization : Linearization
        ``A, B, a, b, m_x`` along the current trajectory.
    weights : StageWeights
        Exact second-order weights (:func:`second_order_weights`).
    quasi_weights : callable, optional
        Lazily computed quasi-Newton weights (cost Hessians only).
    steepest_weights : StageWeights, optional
        Last-resort positive-definite model.
    eigenvalue_floor : float
        Eigenvalue clip of the convexified model.
    groups : tuple of ndarray
        Independent subsystems' indices of ``(x, u)``; ``A_k`` and ``B_k`` are block-diagonal
        in them (:func:`block_ranges`), which the Riccati sweep uses.
    threads : int
        The convexified model's stages are clipped on as many threads (the same direction
        for any number).

    Returns
    -------
    LqDirection
        Direction, slope ``Dh·ζ`` and the ladder level used.

    Raises
    ------
    SolverError
        If no level produced a descent direction.
    """
    blocks = block_ranges(groups, linearization.A.shape[1], linearization.B.shape[2])
    direction = _try_direction(linearization, weights, DirectionType.NEWTON, blocks)
    if direction is not None:
        return direction
    base = quasi_weights() if quasi_weights is not None else weights
    convexified = convexify(base, eigenvalue_floor, threads)
    direction = _try_direction(linearization, convexified, DirectionType.CONVEXIFIED, blocks)
    if direction is not None:
        return direction
    if steepest_weights is not None:
        direction = _try_direction(linearization, steepest_weights, DirectionType.STEEPEST, blocks)
        if direction is not None:
            return direction
    raise SolverError("no descent direction: Newton, convexified and steepest models all failed")
