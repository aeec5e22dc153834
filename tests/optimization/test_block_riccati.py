"""Riccati sweeps that use the block-diagonal ``A_k``, ``B_k`` of a fleet give the dense results."""

from __future__ import annotations

import numpy as np
import pytest

from auvplan.optimization import StageWeights, _kernels, convexify, design_regulator
from auvplan.optimization.lq import block_ranges

SIZES = ((3, 1), (5, 2), (4, 2))  # (states, inputs) of three subsystems
N_X, N_U, N = sum(s for s, _ in SIZES), sum(m for _, m in SIZES), 40


def _groups() -> tuple[np.ndarray, ...]:
    groups, x0, u0 = [], 0, 0
    for n_s, n_i in SIZES:
        groups.append(np.r_[x0 : x0 + n_s, N_X + u0 : N_X + u0 + n_i])
        x0, u0 = x0 + n_s, u0 + n_i
    return tuple(groups)


def _block_diagonal_dynamics(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    a, b = np.zeros((N, N_X, N_X)), np.zeros((N, N_X, N_U))
    x0 = u0 = 0
    for n_s, n_i in SIZES:
        a[:, x0 : x0 + n_s, x0 : x0 + n_s] = np.eye(n_s) + 0.1 * rng.normal(size=(N, n_s, n_s))
        b[:, x0 : x0 + n_s, u0 : u0 + n_i] = 0.3 * rng.normal(size=(N, n_s, n_i))
        x0, u0 = x0 + n_s, u0 + n_i
    return a, b


def test_block_ranges_of_contiguous_and_scattered_groups() -> None:
    x_blocks, u_blocks = block_ranges(_groups(), N_X, N_U)
    assert x_blocks.tolist() == [[0, 3], [3, 8], [8, 12]]
    assert u_blocks.tolist() == [[0, 1], [1, 3], [3, 5]]
    scattered = (np.r_[0, 2, N_X], np.r_[1, 3:N_X, N_X + 1 : N_X + N_U])
    assert [r.tolist() for r in block_ranges(scattered, N_X, N_U)] == [[[0, N_X]], [[0, N_U]]]
    assert [r.tolist() for r in block_ranges((), N_X, N_U)] == [[[0, N_X]], [[0, N_U]]]


def test_lq_sweep_with_blocks_equals_the_dense_sweep(rng: np.random.Generator) -> None:
    a, b = _block_diagonal_dynamics(rng)
    z = rng.normal(size=(N, N_X + N_U, N_X + N_U))
    w = z @ np.swapaxes(z, 1, 2) + np.eye(N_X + N_U)  # coupled (dense) PD stage weights
    q, s, r = w[:, :N_X, :N_X].copy(), w[:, :N_X, N_X:].copy(), w[:, N_X:, N_X:].copy()
    l_x, l_u = rng.normal(size=(N, N_X)), rng.normal(size=(N, N_U))
    p_final, m_x = np.eye(N_X) + 0.1 * np.ones((N_X, N_X)), rng.normal(size=N_X)
    args = (a, b, q, s, r, l_x, l_u, p_final, m_x)
    dense = _kernels.lq_backward(*args, np.array([[0, N_X]]), np.array([[0, N_U]]))
    blocked = _kernels.lq_backward(*args, *block_ranges(_groups(), N_X, N_U))
    assert dense[3] == blocked[3] == -1
    np.testing.assert_allclose(blocked[0], dense[0], rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(blocked[1], dense[1], rtol=1e-11, atol=1e-12)


@pytest.mark.parametrize("coupled", [False, True])
def test_regulator_per_subsystem_equals_the_whole(rng: np.random.Generator, coupled: bool) -> None:
    a, b = _block_diagonal_dynamics(rng)
    q_r, r_r = np.diag(rng.uniform(0.5, 2.0, N_X)), np.diag(rng.uniform(0.5, 2.0, N_U))
    if coupled:  # a weight between subsystems: designed as one system
        q_r[0, 5] = q_r[5, 0] = 0.2
    whole = design_regulator(a, b, q_r, r_r)
    parts = design_regulator(a, b, q_r, r_r, blocks=block_ranges(_groups(), N_X, N_U))
    np.testing.assert_allclose(parts, whole, rtol=1e-10, atol=1e-12)
    if not coupled:
        assert np.all(parts[:, 0, 3:] == 0.0)  # subsystem 0's input ignores the others


@pytest.mark.parametrize("pair", [(0, 1), (0, 2)])  # adjacent, and with a subsystem between
def test_lq_sweep_by_components_equals_the_dense_sweep(
    rng: np.random.Generator, pair: tuple[int, int]
) -> None:
    """Weights block-diagonal but for two subsystems coupled at stage 25 (a near pass)."""
    a, b = _block_diagonal_dynamics(rng)
    w = np.zeros((N, N_X + N_U, N_X + N_U))
    for group in _groups():
        z = rng.normal(size=(N, group.size, group.size))
        w[:, group[:, None], group] = z @ np.swapaxes(z, 1, 2) + np.eye(group.size)
    coupled = np.r_[_groups()[pair[0]], _groups()[pair[1]]]
    z = rng.normal(size=(coupled.size, coupled.size))
    w[25, coupled[:, None], coupled] += z @ z.T
    q, s, r = w[:, :N_X, :N_X].copy(), w[:, :N_X, N_X:].copy(), w[:, N_X:, N_X:].copy()
    l_x, l_u = rng.normal(size=(N, N_X)), rng.normal(size=(N, N_U))
    p_final, m_x = np.diag(rng.uniform(1.0, 2.0, N_X)), rng.normal(size=N_X)
    args = (a, b, q, s, r, l_x, l_u, p_final, m_x)
    dense = _kernels.lq_backward(*args, np.array([[0, N_X]]), np.array([[0, N_U]]))
    parts = _kernels.lq_backward(*args, *block_ranges(_groups(), N_X, N_U))
    assert dense[3] == parts[3] == -1
    np.testing.assert_allclose(parts[0], dense[0], rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(parts[1], dense[1], rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(parts[2], dense[2], rtol=1e-10, atol=1e-12)  # M⁻¹
    # another gradient through the stored factorisation: the sweep's own feed-forward for it
    other_x, other_u, other_m = (
        rng.normal(size=(N, N_X)),
        rng.normal(size=(N, N_U)),
        rng.normal(size=N_X),
    )
    again = _kernels.lq_backward(
        a, b, q, s, r, other_x, other_u, p_final, other_m, *block_ranges(_groups(), N_X, N_U)
    )
    reused = _kernels.lq_feedforward(a, b, parts[0], parts[2], other_x, other_u, other_m)
    np.testing.assert_allclose(reused, again[1], rtol=1e-9, atol=1e-11)
    assert not np.allclose(reused, parts[1])
    # the pair is coupled up to the near pass, independent after it; the third never
    states = (slice(0, 3), slice(3, 8), slice(8, 12))
    inputs_0, other = slice(0, 1), ({1, 2} - {pair[1]}).pop()
    assert np.all(np.abs(dense[0][:26, inputs_0, states[pair[1]]]) > 0.0)
    assert np.all(dense[0][26:, inputs_0, states[pair[1]]] == 0.0)
    assert np.all(dense[0][:, inputs_0, states[other]] == 0.0)


def test_regulator_on_replaced_stages_equals_the_regulator_on_the_edited_linearisation(
    rng: np.random.Generator,
) -> None:
    a, b = _block_diagonal_dynamics(rng)
    other_a, other_b = _block_diagonal_dynamics(rng)
    stages = np.array([3, 17, N - 1])
    edited_a, edited_b = a.copy(), b.copy()
    edited_a[stages], edited_b[stages] = other_a[stages], other_b[stages]
    q_r, r_r = np.diag(rng.uniform(0.5, 2.0, N_X)), np.diag(rng.uniform(0.5, 2.0, N_U))
    blocks = block_ranges(_groups(), N_X, N_U)
    expected = design_regulator(edited_a, edited_b, q_r, r_r, blocks=blocks)
    replaced = (stages, other_a[stages], other_b[stages])
    given = design_regulator(a, b, q_r, r_r, blocks=blocks, replaced=replaced)
    np.testing.assert_allclose(given, expected, rtol=1e-12, atol=1e-14)
    assert not np.allclose(given, design_regulator(a, b, q_r, r_r, blocks=blocks))


def _projected(w: np.ndarray, floor: float) -> np.ndarray:
    """``V max(Λ, floor) Vᵀ`` of every stage, by numpy on the whole matrix."""
    values, vectors = np.linalg.eigh(w)
    return np.einsum("kij,kj,klj->kil", vectors, np.maximum(values, floor), vectors)


@pytest.mark.parametrize("pair", [(0, 1), (0, 2)])
def test_clipped_lq_sweep_is_the_sweep_of_the_projected_weights(
    rng: np.random.Generator, pair: tuple[int, int]
) -> None:
    """Indefinite stage weights (two subsystems coupled at some stages, a state on its own):
    the sweep of the convexified weights equals the sweep of the weights projected by numpy,
    and the convexified weights are the same to the bit on any number of threads."""
    a, b = _block_diagonal_dynamics(rng)
    w = np.zeros((N, N_X + N_U, N_X + N_U))
    for group in _groups():
        z = rng.normal(size=(N, group.size, group.size))
        w[:, group[:, None], group] = z @ np.swapaxes(z, 1, 2) - 2.0 * np.eye(group.size)
    coupled = np.r_[_groups()[pair[0]], _groups()[pair[1]]]
    w[::4, coupled[0], coupled[-1]] = w[::4, coupled[-1], coupled[0]] = 0.7
    w[:, 9, :] = w[:, :, 9] = 0.0  # a state that nothing couples: a 1 x 1 block
    w[:, 9, 9] = rng.normal(size=N)
    l_x, l_u = rng.normal(size=(N, N_X)), rng.normal(size=(N, N_U))
    p_final, m_x = np.diag(rng.uniform(1.0, 2.0, N_X)), rng.normal(size=N_X)
    blocks = block_ranges(_groups(), N_X, N_U)

    def sweep(q: np.ndarray, s: np.ndarray, r: np.ndarray) -> tuple:
        return _kernels.lq_backward(a, b, q, s, r, l_x, l_u, p_final, m_x, *blocks)

    def parts(stacked: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return tuple(  # type: ignore[return-value]
            np.ascontiguousarray(x)
            for x in (stacked[:, :N_X, :N_X], stacked[:, :N_X, N_X:], stacked[:, N_X:, N_X:])
        )

    assert sweep(*parts(w))[3] >= 0  # unclipped, the sweep fails
    plain = sweep(*parts(_projected(w, 0.5)))
    convexified = [convexify(StageWeights(*parts(w), p_final), 0.5, t) for t in (1, 3)]
    for x, y in zip(
        (convexified[0].Q, convexified[0].S, convexified[0].R),
        (convexified[1].Q, convexified[1].S, convexified[1].R),
        strict=True,
    ):
        np.testing.assert_array_equal(x, y)
    clipped = sweep(convexified[0].Q, convexified[0].S, convexified[0].R)
    assert clipped[3] == plain[3] == -1
    np.testing.assert_allclose(clipped[0], plain[0], rtol=1e-9, atol=1e-11)
    np.testing.assert_allclose(clipped[1], plain[1], rtol=1e-9, atol=1e-11)
