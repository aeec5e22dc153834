"""The convexified model: eigenvalues clipped at the floor, per block when stages decouple."""

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


def test_clipped_model_is_the_eigenvalue_projection() -> None:
    weights = _weights(np.random.default_rng(0))
    clipped = _stacked(convexify(weights, 1e-2))
    values, vectors = np.linalg.eigh(_stacked(weights))
    expected = np.einsum("kij,kj,klj->kil", vectors, np.maximum(values, 1e-2), vectors)
    np.testing.assert_allclose(clipped, expected, atol=1e-12)
    assert np.min(np.linalg.eigvalsh(clipped)) >= 1e-2 - 1e-12


def test_block_wise_clipping_gives_the_same_model() -> None:
    weights = _weights(np.random.default_rng(1))
    whole, by_block = convexify(weights, 1e-2), convexify(weights, 1e-2, GROUPS)
    np.testing.assert_allclose(_stacked(by_block), _stacked(whole), atol=1e-12)


def test_clipping_by_coupled_components_gives_the_same_model() -> None:
    """Four vehicles, pairs of them coupled at some stages: clipped per component, exactly."""
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
    weights = StageWeights(
        stacked[:, :n_x, :n_x].copy(),
        stacked[:, :n_x, n_x:].copy(),
        stacked[:, n_x:, n_x:].copy(),
        np.eye(n_x),
    )
    whole, by_component = convexify(weights, 1e-2), convexify(weights, 1e-2, groups)
    np.testing.assert_allclose(_stacked(by_component), _stacked(whole), atol=1e-12)
    assert np.min(np.linalg.eigvalsh(_stacked(by_component))) >= 1e-2 - 1e-12
