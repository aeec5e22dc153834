"""Sequential recursions of discrete-time PRONTO, compiled with numba.

Only the backward Riccati sweeps, the costate recursion and the forward LQ pass are
sequential; everything else is batched. All arrays are C-contiguous float64, time-major.
Equations: ``reference/pronto.md`` §6.1–§6.3.
"""

from __future__ import annotations

import numba
import numpy as np

from auvplan._typing import FloatArray, IntArray


@numba.njit(cache=True)
def _cholesky(matrix: FloatArray) -> tuple[FloatArray, bool]:
    """Lower Cholesky factor of a symmetric matrix; ``ok`` is False unless strictly PD."""
    n = matrix.shape[0]
    lower = np.zeros((n, n))
    for j in range(n):
        diag = matrix[j, j]
        for k in range(j):
            diag -= lower[j, k] * lower[j, k]
        if not diag > 0.0:  # also catches NaN
            return lower, False
        lower[j, j] = np.sqrt(diag)
        for i in range(j + 1, n):
            value = matrix[i, j]
            for k in range(j):
                value -= lower[i, k] * lower[j, k]
            lower[i, j] = value / lower[j, j]
    return lower, True


@numba.njit(cache=True)
def _cholesky_solve(lower: FloatArray, rhs: FloatArray) -> FloatArray:
    """Solve ``(L Lᵀ) X = rhs`` for a 2-D right-hand side."""
    n, m = rhs.shape
    out = rhs.copy()
    for c in range(m):
        for i in range(n):
            value = out[i, c]
            for k in range(i):
                value -= lower[i, k] * out[k, c]
            out[i, c] = value / lower[i, i]
        for i in range(n - 1, -1, -1):
            value = out[i, c]
            for k in range(i + 1, n):
                value -= lower[k, i] * out[k, c]
            out[i, c] = value / lower[i, i]
    return out


@numba.njit(cache=True)
def _above_floor(matrix: FloatArray, floor: float) -> bool:
    """Whether ``matrix − floor·I`` passes the Cholesky test (all eigenvalues above ``floor``)."""
    shifted = matrix.copy()
    for i in range(matrix.shape[0]):
        shifted[i, i] -= floor
    return _cholesky(shifted)[1]


@numba.njit(cache=True)
def _clip_in_place(matrix: FloatArray, floor: float) -> None:
    """``V max(Λ, floor) Vᵀ`` of a symmetric matrix, written over it (kept when already above)."""
    if _above_floor(matrix, floor):
        return
    values, vectors = np.linalg.eigh(matrix)
    matrix[:, :] = (vectors * np.maximum(values, floor)) @ vectors.T


@numba.njit(cache=True)
def _root(parent: IntArray, block: int) -> int:
    """Root of ``block`` in the union-find forest ``parent``."""
    while parent[block] != block:
        block = parent[block]
    return block


@numba.njit(cache=True)
def _merge(parent: IntArray, a: int, b: int) -> None:
    """Join the trees of ``a`` and ``b`` (the smaller root becomes the root)."""
    a, b = _root(parent, a), _root(parent, b)
    if a != b:
        parent[max(a, b)] = min(a, b)


@numba.njit(cache=True)
def _components(matrix: FloatArray, parent: IntArray, order: IntArray, starts: IntArray) -> int:
    """Connected components of the graph of ``matrix``'s nonzero off-diagonal entries.

    Writes the indices of component ``c`` to ``order[starts[c]:starts[c + 1]]`` (ascending)
    and returns the number of components; ``parent`` is scratch space of the matrix's size.
    A symmetric matrix is block-diagonal in its components (up to a permutation).
    """
    n = matrix.shape[0]
    for i in range(n):
        parent[i] = i
    for i in range(n):
        for j in range(i + 1, n):
            if matrix[i, j] != 0.0:
                _merge(parent, i, j)
    n_components = 0
    for i in range(n):  # a root is its component's smallest index: roots come in order
        root = _root(parent, i)
        parent[i] = root
        if root == i:
            starts[n_components] = i  # the root's index, for now
            n_components += 1
    size = np.zeros(n, dtype=np.int64)
    for i in range(n):
        size[parent[i]] += 1
    offset = 0
    for c in range(n_components):
        root = starts[c]
        starts[c] = offset
        offset += size[root]
        size[root] = starts[c]  # now the next free slot of the component
    starts[n_components] = n
    for i in range(n):
        order[size[parent[i]]] = i
        size[parent[i]] += 1
    return n_components


@numba.njit(cache=True)
def _clip_components(
    stage: FloatArray, floor: float, parent: IntArray, order: IntArray, starts: IntArray
) -> None:
    """``V max(Λ, floor) Vᵀ`` of a symmetric matrix, written over it, block by block.

    The matrix is block-diagonal in the components of its nonzero entries (:func:`_components`;
    ``parent``, ``order``, ``starts`` are its scratch arrays): each block is tested and clipped on
    its own (:func:`_clip_in_place`), a ``1 × 1`` block as ``max(w, floor)``.
    """
    for c in range(_components(stage, parent, order, starts)):
        index = order[starts[c] : starts[c + 1]]
        size = index.size
        if size == 1:
            if stage[index[0], index[0]] <= floor:  # noqa: PLR1730 (max() would drop a NaN)
                stage[index[0], index[0]] = floor
            continue
        block = np.empty((size, size))
        for i in range(size):
            for j in range(size):
                block[i, j] = stage[index[i], index[j]]
        _clip_in_place(block, floor)
        for i in range(size):
            for j in range(size):
                stage[index[i], index[j]] = block[i, j]


@numba.njit(cache=True)
def _clipped_stage(
    q: FloatArray, s: FloatArray, r: FloatArray, floor: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``Q, S, R`` of ``½(W + Wᵀ)``, ``W = [[Q, S], [Sᵀ, R]]``, eigenvalues clipped at ``floor``.

    Only the blocks of coupled coordinates that fail the Cholesky test of ``W − floor·I``
    change (:func:`_clip_components`): within a vehicle e.g. its position, which its dynamics
    do not curve, is a block of its own; at ``O(Σ n_c³)`` instead of ``O(n³)``.
    """
    n_x, n_u = s.shape
    n = n_x + n_u
    stage = np.empty((n, n))
    stage[:n_x, :n_x] = 0.5 * (q + q.T)
    stage[:n_x, n_x:] = s
    stage[n_x:, :n_x] = s.T
    stage[n_x:, n_x:] = 0.5 * (r + r.T)
    scratch = np.empty((3, n + 1), dtype=np.int64)
    _clip_components(stage, floor, scratch[0], scratch[1], scratch[2])
    return stage[:n_x, :n_x].copy(), stage[:n_x, n_x:].copy(), stage[n_x:, n_x:].copy()


@numba.njit(cache=True)
def clip_stage_weights(
    q_mat: FloatArray, s_mat: FloatArray, r_mat: FloatArray, floor: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """:func:`_clipped_stage` of every stage.

    Returns the clipped ``Q (N, n_x, n_x)``, ``S (N, n_x, n_u)`` and ``R (N, n_u, n_u)``.
    """
    q_out = np.empty_like(q_mat)
    s_out = np.empty_like(s_mat)
    r_out = np.empty_like(r_mat)
    for k in range(q_mat.shape[0]):
        q_out[k], s_out[k], r_out[k] = _clipped_stage(q_mat[k], s_mat[k], r_mat[k], floor)
    return q_out, s_out, r_out


@numba.njit(cache=True)
def regulator_riccati(
    a_mat: FloatArray, b_mat: FloatArray, q_r: FloatArray, r_r: FloatArray, p_final: FloatArray
) -> tuple[FloatArray, bool]:
    """Time-varying discrete LQR gains ``K_k = M⁻¹ Bᵀ P_{k+1} A`` (pronto.md §6.1).

    Returns the gains ``(N, n_u, n_x)`` and ``ok`` (False if some ``M_k`` was not PD).
    """
    n_stages, n_x, n_u = b_mat.shape
    gains = np.zeros((n_stages, n_u, n_x))
    p_next = p_final.copy()
    ok = True
    for k in range(n_stages - 1, -1, -1):
        a = a_mat[k]
        b = b_mat[k]
        pb = p_next @ b
        m = r_r + b.T @ pb
        lower, is_pd = _cholesky(0.5 * (m + m.T))
        if not is_pd:
            ok = False
            break
        g = pb.T @ a
        gain = _cholesky_solve(lower, g)
        gains[k] = gain
        p = q_r + a.T @ p_next @ a - g.T @ gain
        p_next = 0.5 * (p + p.T)
    return gains, ok


@numba.njit(cache=True)
def closed_loop_costate(
    a_mat: FloatArray,
    b_mat: FloatArray,
    gains: FloatArray,
    l_x: FloatArray,
    l_u: FloatArray,
    lam_final: FloatArray,
) -> FloatArray:
    """Costate ``λ_k = a_k − K_kᵀ b_k + (A_k − B_k K_k)ᵀ λ_{k+1}``, ``λ_N = m_x`` (§6.2)."""
    n_stages, n_x, _ = b_mat.shape
    lam = np.zeros((n_stages + 1, n_x))
    lam[n_stages] = lam_final
    for k in range(n_stages - 1, -1, -1):  # (A − B K)ᵀ λ = Aᵀ λ − Kᵀ (Bᵀ λ): O(n²) per stage
        lam[k] = (
            l_x[k]
            - gains[k].T @ l_u[k]
            + a_mat[k].T @ lam[k + 1]
            - gains[k].T @ (b_mat[k].T @ lam[k + 1])
        )
    return lam


@numba.njit(cache=True)
def _block_diagonal_transpose_times(
    diagonal: FloatArray, matrix: FloatArray, rows: IntArray, columns: IntArray
) -> FloatArray:
    """``diagonalᵀ @ matrix`` for a block-diagonal ``diagonal``, without transposed copies.

    Block ``b`` is ``diagonal[rows[b, 0]:rows[b, 1], columns[b, 0]:columns[b, 1]]``; entries
    outside the blocks are taken as zero. ``matrix @ diagonal`` is the transpose of
    ``diagonalᵀ @ matrixᵀ`` (``matrix.T``, a view).
    """
    out = np.zeros((diagonal.shape[1], matrix.shape[1]))
    for b in range(rows.shape[0]):
        for j in range(columns[b, 0], columns[b, 1]):
            for k in range(rows[b, 0], rows[b, 1]):
                d = diagonal[k, j]
                if d != 0.0:
                    for c in range(matrix.shape[1]):
                        out[j, c] += d * matrix[k, c]
    return out


@numba.njit(cache=True)
def _gather(matrix: FloatArray, rows: IntArray, columns: IntArray) -> FloatArray:
    """``matrix[rows][:, columns]`` in one pass."""
    out = np.empty((rows.size, columns.size))
    for i in range(rows.size):
        for j in range(columns.size):
            out[i, j] = matrix[rows[i], columns[j]]
    return out


@numba.njit(cache=True)
def _join_coupled(
    matrix: FloatArray, row_block: IntArray, column_block: IntArray, parent: IntArray
) -> None:
    """Merge (union-find ``parent``) the blocks that a nonzero entry of ``matrix`` joins."""
    for i in range(matrix.shape[0]):
        for j in range(matrix.shape[1]):
            if matrix[i, j] != 0.0 and row_block[i] != column_block[j]:
                _merge(parent, row_block[i], column_block[j])


@numba.njit(cache=True)
def _owners(blocks: IntArray, size: int) -> IntArray:
    """Block of every row given the ``(start, stop)`` ranges of the blocks."""
    owner = np.zeros(size, dtype=np.int64)
    for b in range(blocks.shape[0]):
        owner[blocks[b, 0] : blocks[b, 1]] = b
    return owner


@numba.njit(cache=True)
def _component(
    parent: IntArray, root: int, x_blocks: IntArray, u_blocks: IntArray
) -> tuple[IntArray, IntArray, IntArray, IntArray]:
    """State and input rows of the component ``root``, and its blocks' local ranges."""
    n_x = n_u = n_blocks = 0
    for b in range(x_blocks.shape[0]):
        if _root(parent, b) == root:
            n_x += x_blocks[b, 1] - x_blocks[b, 0]
            n_u += u_blocks[b, 1] - u_blocks[b, 0]
            n_blocks += 1
    states, inputs = np.empty(n_x, np.int64), np.empty(n_u, np.int64)
    local_x, local_u = np.empty((n_blocks, 2), np.int64), np.empty((n_blocks, 2), np.int64)
    i = j = c = 0
    for b in range(x_blocks.shape[0]):
        if _root(parent, b) != root:
            continue
        local_x[c, 0], local_u[c, 0] = i, j
        for row in range(x_blocks[b, 0], x_blocks[b, 1]):
            states[i] = row
            i += 1
        for row in range(u_blocks[b, 0], u_blocks[b, 1]):
            inputs[j] = row
            j += 1
        local_x[c, 1], local_u[c, 1] = i, j
        c += 1
    return states, inputs, local_x, local_u


@numba.njit(cache=True)
def lq_backward(
    a_mat: FloatArray,
    b_mat: FloatArray,
    q_mat: FloatArray,
    s_mat: FloatArray,
    r_mat: FloatArray,
    l_x: FloatArray,
    l_u: FloatArray,
    p_final: FloatArray,
    r_final: FloatArray,
    x_blocks: IntArray,
    u_blocks: IntArray,
    floor: float,
) -> tuple[FloatArray, FloatArray, FloatArray, int]:
    """Discrete Riccati with cross term for the LQ direction (§6.3), component by component.

    ``A_k`` and ``B_k`` are block-diagonal with the state and input ranges ``x_blocks``,
    ``u_blocks`` (``(n_blocks, 2)`` start/stop, e.g. one block per vehicle; one block for a
    coupled model). Blocks couple through the weights: a nonzero entry of ``Q_k``, ``S_k``
    or ``R_k`` (or of ``P_N``) between two blocks joins them, and ``P_k`` couples every pair
    joined at some stage ``≥ k``. The recursion keeps those components (merged as ``k``
    decreases) and runs on each on its own, where every matrix is block-diagonal in them:
    ``O(Σ_c n_c³)`` per stage instead of ``O(n_x³)`` (vehicles far apart, whose separation
    barriers vanish, stay apart). Products with ``A_k``, ``B_k`` inside a component use its
    blocks (``O(n_c² n_block)``).

    With ``floor > 0`` every stage's weights ``W_k = [[Q_k, S_k], [S_kᵀ, R_k]]`` are replaced
    by their projection onto ``{W ⪰ floor·I}`` (eigenvalues clipped at ``floor``, per
    component and in it per block of coupled coordinates: :func:`_clipped_stage`) as the
    sweep reaches them: the convexified model, without a clipped copy of the weights. The
    caller clips ``P_N``.

    Returns the feedback ``K^o (N, n_u, n_x)``, feed-forward ``v^o (N, n_u)``, ``M_k⁻¹``
    ``(N, n_u, n_u)`` (for other gradients: :func:`lq_feedforward`) and the stage index at
    which ``M_k = R_k + B_kᵀ P B_k`` failed the Cholesky test (``-1`` if none).
    """
    n_stages, n_x, n_u = b_mat.shape
    n_blocks = x_blocks.shape[0]
    x_owner, u_owner = _owners(x_blocks, n_x), _owners(u_blocks, n_u)
    parent = np.arange(n_blocks)
    feedback = np.zeros((n_stages, n_u, n_x))
    feedforward = np.zeros((n_stages, n_u))
    m_inverse = np.zeros((n_stages, n_u, n_u))
    p = p_final.copy()
    r = r_final.copy()
    _join_coupled(p, x_owner, x_owner, parent)
    for k in range(n_stages - 1, -1, -1):
        _join_coupled(q_mat[k], x_owner, x_owner, parent)
        _join_coupled(s_mat[k], x_owner, u_owner, parent)
        _join_coupled(r_mat[k], u_owner, u_owner, parent)
        for root in range(n_blocks):
            if _root(parent, root) != root:
                continue
            xs, us, xb, ub = _component(parent, root, x_blocks, u_blocks)
            a, b = _gather(a_mat[k], xs, xs), _gather(b_mat[k], xs, us)
            p_c = _gather(p, xs, xs)
            q_c, s_c, r_c = (
                _gather(q_mat[k], xs, xs),
                _gather(s_mat[k], xs, us),
                _gather(r_mat[k], us, us),
            )
            if floor > 0.0:
                q_c, s_c, r_c = _clipped_stage(q_c, s_c, r_c, floor)
            pa = _block_diagonal_transpose_times(a, p_c.T, xb, xb).T  # P A
            pb = _block_diagonal_transpose_times(b, p_c.T, xb, ub).T  # P B
            m = r_c + _block_diagonal_transpose_times(b, pb, xb, ub)  # R + Bᵀ P B
            lower, is_pd = _cholesky(0.5 * (m + m.T))
            if not is_pd:
                return feedback, feedforward, m_inverse, k
            g_mat = (s_c + _block_diagonal_transpose_times(a, pb, xb, xb)).T  # Sᵀ + (P B)ᵀ A
            g_vec = l_u[k][us] + b.T @ r[xs]
            rhs = np.zeros((us.size, xs.size + 1 + us.size))
            rhs[:, : xs.size] = g_mat
            rhs[:, xs.size] = g_vec
            for i in range(us.size):
                rhs[i, xs.size + 1 + i] = 1.0
            sol = _cholesky_solve(lower, rhs)
            gain = sol[:, : xs.size].copy()
            p_new = q_c + _block_diagonal_transpose_times(a, pa, xb, xb) - g_mat.T @ gain
            r_new = l_x[k][xs] + a.T @ r[xs] - gain.T @ g_vec
            for i in range(us.size):
                feedforward[k, us[i]] = -sol[i, xs.size]
                for j in range(xs.size):
                    feedback[k, us[i], xs[j]] = gain[i, j]
                for j in range(us.size):
                    m_inverse[k, us[i], us[j]] = sol[i, xs.size + 1 + j]
            for i in range(xs.size):
                r[xs[i]] = r_new[i]
                for j in range(xs.size):
                    p[xs[i], xs[j]] = 0.5 * (p_new[i, j] + p_new[j, i])
    return feedback, feedforward, m_inverse, -1


@numba.njit(cache=True)
def lq_feedforward(
    a_mat: FloatArray,
    b_mat: FloatArray,
    feedback: FloatArray,
    m_inverse: FloatArray,
    l_x: FloatArray,
    l_u: FloatArray,
    r_final: FloatArray,
) -> FloatArray:
    """Feed-forward ``v^o`` of :func:`lq_backward`'s factorised model for other gradients.

    The gains ``K^o`` and ``M_k⁻¹`` do not depend on the gradients: with ``r_N = r_final``,
    ``g_k = l_{u,k} + B_kᵀ r_{k+1}``, ``v^o_k = −M_k⁻¹ g_k`` and
    ``r_k = l_{x,k} + A_kᵀ r_{k+1} − K^{oᵀ}_k g_k``: ``O(n_x² + n_x n_u)`` per stage.
    """
    n_stages, _, n_u = b_mat.shape
    feedforward = np.zeros((n_stages, n_u))
    r = r_final.copy()
    for k in range(n_stages - 1, -1, -1):
        g = l_u[k] + b_mat[k].T @ r
        feedforward[k] = -(m_inverse[k] @ g)
        r = l_x[k] + a_mat[k].T @ r - feedback[k].T @ g
    return feedforward


@numba.njit(cache=True)
def lq_forward(
    a_mat: FloatArray, b_mat: FloatArray, feedback: FloatArray, feedforward: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Forward pass ``v_k = v^o_k − K^o_k z_k``, ``z_{k+1} = A_k z_k + B_k v_k``, ``z_0 = 0``."""
    n_stages, n_x, n_u = b_mat.shape
    z = np.zeros((n_stages + 1, n_x))
    v = np.zeros((n_stages, n_u))
    for k in range(n_stages):
        v[k] = feedforward[k] - feedback[k] @ z[k]
        z[k + 1] = a_mat[k] @ z[k] + b_mat[k] @ v[k]
    return z, v
