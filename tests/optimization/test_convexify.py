"""The convexified model: eigenvalues clipped at the floor, per block where stages decouple."""

from __future__ import annotations

import numpy as np

from auvplan.optimization.lq import convexify
from auvplan.optimization.stages import StageWeights

N_X, N_Z = 16, 20
GROUPS = (np.r_[0:8, 16:18], np.r_[8:16, 18:20])


def _weights(rng: np.random.Generator) -> StageWeights:
    stages = 60
    stacked = np.zeros((stages, N_Z, N_Z))
    for group in GROUPS:
        block = rng.normal(size=(stages, 10, 10))
        stacked[np.ix_(np.arange(stages), group, group)] = block + np.swapaxes(block, 1, 2)
    stacked[::4, 0, 8] = stacked[::4, 8, 0] = 0.3  # some stages couple the two blocks
    stacked[1::5] = stacked[1::5] @ np.swapaxes(stacked[1::5], 1, 2) + np.eye(N_Z)  # some PD
    return StageWeights(
        stacked[:, :N_X, :N_X].copy(),
        stacked[:, :N_X, N_X:].copy(),
        stacked[:, N_X:, N_X:].copy(),
        np.eye(N_X),
    )


def _stacked(weights: StageWeights) -> np.ndarray:
    top = np.concatenate([weights.Q, weights.S], axis=2)
    return np.concatenate([top, np.concatenate([np.swapaxes(weights.S, 1, 2), weights.R], 2)], 1)


def _projection(stacked: np.ndarray, floor: float) -> np.ndarray:
    """``V max(Λ, floor) Vᵀ`` of every stage, by numpy on the whole matrix."""
    values, vectors = np.linalg.eigh(stacked)
    return np.einsum("kij,kj,klj->kil", vectors, np.maximum(values, floor), vectors)


def test_clipped_model_is_the_eigenvalue_projection() -> None:
    """Two vehicles' blocks, joined at some stages: the same as projecting every stage whole."""
    weights = _weights(np.random.default_rng(0))
    clipped = _stacked(convexify(weights, 1e-2))
    np.testing.assert_allclose(clipped, _projection(_stacked(weights), 1e-2), atol=1e-12)
    assert np.min(np.linalg.eigvalsh(clipped)) >= 1e-2 - 1e-12


def test_clipping_by_coupled_components_gives_the_projection() -> None:
    """Four vehicles, chains and pairs of them coupled at some stages, and coordinates of a
    vehicle that nothing couples (1 × 1 blocks, below and above the floor)."""
    rng = np.random.default_rng(2)
    n_x, stages = 16, 80
    groups = tuple(np.r_[4 * g : 4 * g + 4, n_x + g] for g in range(4))  # 4 states, 1 input
    stacked = np.zeros((stages, n_x + 4, n_x + 4))
    for group in groups:
        block = rng.normal(size=(stages, 5, 5))
        stacked[np.ix_(np.arange(stages), group, group)] = block + np.swapaxes(block, 1, 2)
    for a, b, every in ((0, 2, 3), (2, 3, 4), (1, 3, 7)):  # chains and pairs of components
        stacked[::every, 4 * a, 4 * b + 1] = stacked[::every, 4 * b + 1, 4 * a] = 0.4
        stacked[::every, n_x + a, 4 * b] = stacked[::every, 4 * b, n_x + a] = -0.2
    alone = 4 * 1 + 2  # vehicle 1's third state: on its own at every stage
    stacked[:, alone, :] = stacked[:, :, alone] = 0.0
    stacked[:, alone, alone] = rng.normal(size=stages)
    weights = StageWeights(
        stacked[:, :n_x, :n_x].copy(),
        stacked[:, :n_x, n_x:].copy(),
        stacked[:, n_x:, n_x:].copy(),
        np.eye(n_x),
    )
    clipped = _stacked(convexify(weights, 1e-2))
    np.testing.assert_allclose(clipped, _projection(stacked, 1e-2), atol=1e-12)
    assert np.min(np.linalg.eigvalsh(clipped)) >= 1e-2 - 1e-12
    assert np.all(clipped[:, alone, alone] == np.maximum(stacked[:, alone, alone], 1e-2))


def test_stages_above_the_floor_are_kept_bit_for_bit() -> None:
    weights = _weights(np.random.default_rng(3))
    stacked = _stacked(weights)
    kept = np.all(np.linalg.eigvalsh(stacked) > 1e-2, axis=1)
    assert kept.any()
    assert not kept.all()
    clipped = _stacked(convexify(weights, 1e-2))
    assert np.array_equal(clipped[kept], stacked[kept])


def test_blocks_wholly_below_the_floor_become_the_floor() -> None:
    """Blocks whose Gershgorin discs lie below the floor (vehicles' positions far apart, which
    only vanishing barriers curve, some slightly negative) are ``floor·I`` exactly, and equal
    the projection; stages whose discs straddle the floor take the eigendecomposition."""
    rng = np.random.default_rng(4)
    weights = _weights(rng)
    stacked = _stacked(weights)
    tiny = rng.normal(scale=1e-13, size=(stacked.shape[0], 10, 10))
    below = stacked.copy()
    below[np.ix_(np.arange(stacked.shape[0]), GROUPS[1], GROUPS[1])] = tiny + np.swapaxes(
        tiny, 1, 2
    )
    below[np.ix_(np.arange(stacked.shape[0]), GROUPS[0], GROUPS[1])] = 0.0  # on its own
    below[np.ix_(np.arange(stacked.shape[0]), GROUPS[1], GROUPS[0])] = 0.0
    below[::3, GROUPS[1][0], GROUPS[1][0]] = 5e-3  # discs reaching up to the floor
    below[1::3, GROUPS[1][1], GROUPS[1][1]] = 2e-2  # one eigenvalue above it: no shortcut
    weights = StageWeights(
        below[:, :N_X, :N_X].copy(), below[:, :N_X, N_X:].copy(), below[:, N_X:, N_X:].copy(),
        np.eye(N_X),
    )  # fmt: skip
    clipped = _stacked(convexify(weights, 1e-2))
    np.testing.assert_allclose(clipped, _projection(below, 1e-2), atol=1e-12)
    second = clipped[np.ix_(np.arange(below.shape[0]), GROUPS[1], GROUPS[1])]
    shortcut = np.r_[0 : below.shape[0] : 3, 2 : below.shape[0] : 3]
    floor = np.broadcast_to(1e-2 * np.eye(10), (shortcut.size, 10, 10))
    assert np.array_equal(second[shortcut], floor)
    assert not np.any(np.all(second[1::3] == 1e-2 * np.eye(10), axis=(1, 2)))
