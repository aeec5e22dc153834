"""Eigenvalue clipping of small symmetric blocks by cyclic Jacobi on vector lanes.

Oracle: numpy's LAPACK eigendecomposition, ``V max(Λ, floor) Vᵀ``.
"""

from __future__ import annotations

import numpy as np
import pytest

from auvplan.optimization._lane_codegen import LANES
from auvplan.optimization._lane_eigen import JACOBI_MAX_SIZE, clip_blocks


def _projection(blocks: np.ndarray, floor: float) -> np.ndarray:
    values, vectors = np.linalg.eigh(blocks)
    return np.einsum("kij,kj,klj->kil", vectors, np.maximum(values, floor), vectors)


def _clipped(blocks: np.ndarray, floor: float) -> np.ndarray:
    out = np.ascontiguousarray(blocks, dtype=float).copy()
    clip_blocks(out, floor)
    return out


@pytest.mark.parametrize("size", [2, 3, 5, 8, 10, JACOBI_MAX_SIZE + 6])  # the last by LAPACK
def test_clipped_blocks_are_the_eigenvalue_projection(rng: np.random.Generator, size: int) -> None:
    """Indefinite blocks of eigenvalues spread over five decades, a count that is not a
    multiple of LANES: the projection to rounding, symmetric, its eigenvalues at the floor."""
    count = 4 * LANES + 3
    vectors = np.linalg.qr(rng.normal(size=(count, size, size)))[0]
    values = rng.choice([-1.0, 1.0], (count, size)) * 10.0 ** rng.uniform(-3, 2, (count, size))
    blocks = np.einsum("kij,kj,klj->kil", vectors, values, vectors)
    blocks = 0.5 * (blocks + np.swapaxes(blocks, 1, 2))
    clipped = _clipped(blocks, 1e-2)
    scale = np.abs(blocks).max(axis=(1, 2))[:, None, None]
    expected = _projection(blocks, 1e-2)
    np.testing.assert_allclose(clipped / scale, expected / scale, rtol=0.0, atol=1e-13)
    if size <= JACOBI_MAX_SIZE:  # mirrored; BLAS's product is symmetric to rounding
        np.testing.assert_array_equal(clipped, np.swapaxes(clipped, 1, 2))
    assert np.min(np.linalg.eigvalsh(clipped)) >= 1e-2 * (1.0 - 1e-10)


def test_repeated_eigenvalues_diagonal_and_zero_blocks(rng: np.random.Generator) -> None:
    """Blocks Jacobi needs no rotation for, or whose eigenvalues repeat (no unique vectors)."""
    size = 6
    vectors = np.linalg.qr(rng.normal(size=(size, size)))[0]
    repeated = vectors @ np.diag([-2.0, -2.0, 3.0, 3.0, 3.0, 0.5]) @ vectors.T
    diagonal = np.diag([4.0, -1.0, 0.0, 2e-3, 7.0, -3.0])
    blocks = np.stack([0.5 * (repeated + repeated.T), diagonal, np.zeros((size, size))])
    clipped = _clipped(blocks, 1e-2)
    np.testing.assert_allclose(clipped, _projection(blocks, 1e-2), rtol=0.0, atol=1e-13)
    np.testing.assert_array_equal(clipped[1], np.diag(np.maximum(np.diag(diagonal), 1e-2)))
    np.testing.assert_array_equal(clipped[2], 1e-2 * np.eye(size))


def test_a_block_s_result_does_not_depend_on_its_neighbours(rng: np.random.Generator) -> None:
    """Blocks converging in different numbers of sweeps share a vector: each result equals the
    block clipped on its own, to the bit (the same on any split of the stages)."""
    size = 8
    blocks = rng.normal(size=(2 * LANES + 1, size, size))
    blocks = blocks + np.swapaxes(blocks, 1, 2)
    blocks[1] = np.diag(rng.normal(size=size))  # converged before its first sweep
    together = _clipped(blocks, 1e-2)
    for k in range(blocks.shape[0]):
        np.testing.assert_array_equal(_clipped(blocks[k : k + 1], 1e-2)[0], together[k])


def test_non_finite_blocks_stay_non_finite_and_leave_the_others_alone(
    rng: np.random.Generator,
) -> None:
    """A block with a NaN never converges: the sweeps stop at their cap, it stays non-finite
    (the Riccati sweep then refuses the model) and its neighbours are clipped as alone."""
    size = 5
    blocks = rng.normal(size=(LANES, size, size))
    blocks = blocks + np.swapaxes(blocks, 1, 2)
    blocks[2, 1, 3] = blocks[2, 3, 1] = np.nan
    clipped = _clipped(blocks, 1e-2)
    assert not np.all(np.isfinite(clipped[2]))
    for k in (0, 1, 3):
        np.testing.assert_array_equal(clipped[k], _clipped(blocks[k : k + 1], 1e-2)[0])
