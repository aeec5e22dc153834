"""Sequential recursions of discrete-time PRONTO, compiled with numba.

Only the backward Riccati sweeps, the costate recursion and the forward LQ pass are
sequential; everything else is batched. All arrays are C-contiguous float64, time-major.
Equations: ``reference/pronto.md`` §6.1–§6.3.
"""

from __future__ import annotations

import numba
import numpy as np

from auvplan._typing import FloatArray, IntArray
from auvplan.optimization._lane_eigen import clip_blocks


@numba.njit(cache=True)
def _solve_in_place(matrix: FloatArray, n: int, rhs: FloatArray, width: int) -> bool:
    """``rhs[:n, :width] ← M⁻¹ rhs`` for ``M = ½(A + Aᵀ)``, ``A = matrix[:n, :n]``.

    By Cholesky, the factor written over ``matrix``'s lower triangle. Returns False (``rhs``
    unsolved) unless ``M`` is strictly positive definite.
    """
    for j in range(n):
        diag = matrix[j, j]
        for k in range(j):
            diag -= matrix[j, k] * matrix[j, k]
        if not diag > 0.0:  # also catches NaN
            return False
        matrix[j, j] = np.sqrt(diag)
        for i in range(j + 1, n):
            value = 0.5 * (matrix[i, j] + matrix[j, i])
            for k in range(j):
                value -= matrix[i, k] * matrix[j, k]
            matrix[i, j] = value / matrix[j, j]
    for i in range(n):  # L y = rhs, row by row over every column
        for k in range(i):
            factor = matrix[i, k]
            for col in range(width):
                rhs[i, col] -= factor * rhs[k, col]
        for col in range(width):
            rhs[i, col] /= matrix[i, i]
    for i in range(n - 1, -1, -1):  # Lᵀ x = y
        for k in range(i + 1, n):
            factor = matrix[k, i]
            for col in range(width):
                rhs[i, col] -= factor * rhs[k, col]
        for col in range(width):
            rhs[i, col] /= matrix[i, i]
    return True


@numba.njit(cache=True)
def _above_floor(matrix: FloatArray, size: int, floor: float, work: FloatArray) -> bool:
    """Whether ``M − floor·I`` passes the Cholesky test (all eigenvalues above ``floor``).

    ``M = matrix[:size, :size]``; ``work`` (at least as large) holds the factor.
    """
    for i in range(size):
        for j in range(size):
            work[i, j] = matrix[i, j]
        work[i, i] -= floor
    return _solve_in_place(work, size, work, 0)


@numba.njit(cache=True)
def _at_most_floor(matrix: FloatArray, size: int, floor: float) -> bool:
    """Whether every Gershgorin disc of ``M = matrix[:size, :size]`` lies at or below ``floor``.

    Then so does every eigenvalue: ``λ ≤ max_i (m_ii + Σ_{j≠i} |m_ij|) ≤ floor``.
    """
    for i in range(size):
        bound = matrix[i, i]
        for j in range(size):
            if j != i:
                bound += abs(matrix[i, j])
        if not bound <= floor:  # also catches NaN
            return False
    return True


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
def _all_joined(parent: IntArray) -> bool:
    """Whether every block of the union-find forest ``parent`` is in one tree."""
    for block in range(parent.size):  # noqa: SIM110 (numba compiles no generator)
        if _root(parent, block) != 0:
            return False
    return True


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


#: Stages whose blocks :func:`clip_stage_weights` gathers and clips together: enough for whole
#: groups of lanes, few enough for the workspace to stay in cache for large coupled fleets.
CLIP_CHUNK = 64


@numba.njit(cache=True, nogil=True)
def clip_stage_weights(
    q_mat: FloatArray,
    s_mat: FloatArray,
    r_mat: FloatArray,
    floor: float,
    out: tuple[FloatArray, FloatArray, FloatArray],
) -> None:
    """``Q, S, R`` of ``½(W_k + W_kᵀ)``, ``W_k = [[Q_k, S_k], [S_kᵀ, R_k]]``, clipped at ``floor``.

    The projection ``V max(Λ, floor) Vᵀ`` of every stage, block by block: a stage's weights are
    block-diagonal in the components of their nonzero entries (:func:`_components`; within a
    vehicle e.g. its position, which its dynamics do not curve, is a block of its own). A
    ``1 × 1`` block becomes ``max(w, floor)``; a block passing the Cholesky test of
    ``B − floor·I`` is kept (:func:`_above_floor`); one whose Gershgorin discs lie at or below
    the floor becomes ``floor·I`` (:func:`_at_most_floor`: ``V floor·I Vᵀ = floor·I``, e.g. the
    positions of vehicles far apart, which only vanishing barriers curve); the others, of every
    stage, are diagonalised together, ``LANES`` of one size at a time
    (:func:`~auvplan.optimization._lane_eigen.clip_blocks`), :data:`CLIP_CHUNK` stages at a
    time. Each stage's result depends on that stage only.

    Writes the clipped ``Q (N, n_x, n_x)``, ``S (N, n_x, n_u)`` and ``R (N, n_u, n_u)`` into
    ``out`` (arrays of those shapes, e.g. a piece of larger ones).
    """
    n_x = q_mat.shape[1]
    q_out, s_out, r_out = out
    for start in range(0, q_mat.shape[0], CLIP_CHUNK):
        rows = slice(start, min(start + CLIP_CHUNK, q_mat.shape[0]))
        stages = _clipped_stages(q_mat[rows], s_mat[rows], r_mat[rows], floor)
        q_out[rows] = stages[:, :n_x, :n_x]
        s_out[rows] = stages[:, :n_x, n_x:]
        r_out[rows] = stages[:, n_x:, n_x:]


@numba.njit(cache=True, nogil=True)
def _clipped_stages(
    q_mat: FloatArray, s_mat: FloatArray, r_mat: FloatArray, floor: float
) -> FloatArray:
    """The stages of :func:`clip_stage_weights` as symmetric ``(N, n, n)`` matrices, clipped."""
    n_stages, n_x, n_u = s_mat.shape
    n = n_x + n_u
    stages = np.empty((n_stages, n, n))
    jobs = np.empty((n_stages * n, n + 2), dtype=np.int64)  # stage, size, indices
    n_jobs = 0
    scratch = np.empty((3, n + 1), dtype=np.int64)
    block, work = np.empty((n, n)), np.empty((n, n))  # a component's, in the leading rows
    for k in range(n_stages):
        stage = stages[k]
        for i in range(n_x):
            for j in range(n_x):
                stage[i, j] = 0.5 * (q_mat[k, i, j] + q_mat[k, j, i])
            for j in range(n_u):
                stage[i, n_x + j] = stage[n_x + j, i] = s_mat[k, i, j]
        for i in range(n_u):
            for j in range(n_u):
                stage[n_x + i, n_x + j] = 0.5 * (r_mat[k, i, j] + r_mat[k, j, i])
        for c in range(_components(stage, scratch[0], scratch[1], scratch[2])):
            index = scratch[1][scratch[2][c] : scratch[2][c + 1]]
            size = index.size
            if size == 1:
                if stage[index[0], index[0]] <= floor:  # noqa: PLR1730 (max() would drop a NaN)
                    stage[index[0], index[0]] = floor
                continue
            _gather_component(stage, index, index, block)
            if _above_floor(block, size, floor, work):
                continue
            if _at_most_floor(block, size, floor):
                for i in range(size):
                    for j in range(size):
                        stage[index[i], index[j]] = floor if i == j else 0.0
                continue
            jobs[n_jobs, 0], jobs[n_jobs, 1] = k, size
            jobs[n_jobs, 2 : 2 + size] = index
            n_jobs += 1
    for size in range(2, n + 1):
        chosen = np.flatnonzero(jobs[:n_jobs, 1] == size)
        blocks = np.empty((chosen.size, size, size))
        for b in range(chosen.size):
            stage, index = stages[jobs[chosen[b], 0]], jobs[chosen[b], 2 : 2 + size]
            _gather_component(stage, index, index, blocks[b])
        clip_blocks(blocks, floor)
        for b in range(chosen.size):
            stage, index = stages[jobs[chosen[b], 0]], jobs[chosen[b], 2 : 2 + size]
            _scatter_component(blocks[b], index, index, stage)
    return stages


@numba.njit(cache=True)
def _add_transpose_times(matrix: FloatArray, vector: FloatArray, out: FloatArray) -> None:
    """``out += matrixᵀ vector`` (row by row; exact zeros of ``vector`` skipped)."""
    for i in range(matrix.shape[0]):
        value = vector[i]
        if value != 0.0:
            for j in range(matrix.shape[1]):
                out[j] += matrix[i, j] * value


@numba.njit(cache=True)
def _add_times(matrix: FloatArray, vector: FloatArray, out: FloatArray, sign: float) -> None:
    """``out += sign · matrix vector``."""
    for i in range(matrix.shape[0]):
        value = 0.0
        for j in range(matrix.shape[1]):
            value += matrix[i, j] * vector[j]
        out[i] += sign * value


@numba.njit(cache=True)
def closed_loop_costate(
    a_mat: FloatArray,
    b_mat: FloatArray,
    gains: FloatArray,
    l_x: FloatArray,
    l_u: FloatArray,
    lam_final: FloatArray,
) -> FloatArray:
    """Costate ``λ_k = a_k − K_kᵀ b_k + (A_k − B_k K_k)ᵀ λ_{k+1}``, ``λ_N = m_x`` (§6.2).

    As ``λ_k = a_k + A_kᵀ λ_{k+1} − K_kᵀ (b_k + B_kᵀ λ_{k+1})``: ``O(n²)`` per stage.
    """
    n_stages, n_x, n_u = b_mat.shape
    lam = np.zeros((n_stages + 1, n_x))
    lam[n_stages] = lam_final
    pulled = np.empty(n_u)
    for k in range(n_stages - 1, -1, -1):
        for i in range(n_u):
            pulled[i] = l_u[k, i]
        _add_transpose_times(b_mat[k], lam[k + 1], pulled)
        for j in range(n_x):
            lam[k, j] = l_x[k, j]
        _add_transpose_times(a_mat[k], lam[k + 1], lam[k])
        for i in range(n_u):
            pulled[i] = -pulled[i]
        _add_transpose_times(gains[k], pulled, lam[k])
    return lam


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
def _gather_component(
    matrix: FloatArray, rows: IntArray, columns: IntArray, out: FloatArray
) -> None:
    """``out[:len(rows), :len(columns)] = matrix[rows][:, columns]`` (a workspace, no copy made).

    The indices are read as unsigned (no negative-index wraparound: :func:`_unsigned_block`).
    """
    for i in range(rows.size):
        row = matrix[np.uint64(rows[i])]
        for j in range(columns.size):
            out[i, j] = row[np.uint64(columns[j])]


@numba.njit(cache=True)
def _scatter_component(
    values: FloatArray, rows: IntArray, columns: IntArray, matrix: FloatArray
) -> None:
    """``matrix[rows][:, columns] = values[:len(rows), :len(columns)]`` (the inverse gather)."""
    for i in range(rows.size):
        row = matrix[np.uint64(rows[i])]
        for j in range(columns.size):
            row[np.uint64(columns[j])] = values[i, j]


@numba.njit(cache=True)
def _unsigned_block(xb: IntArray, ub: IntArray, c: int) -> tuple[np.uint64, ...]:
    """Block ``c``'s state and input ranges ``(x0, x1, u0, u1)`` as unsigned integers.

    Loops over them index without numba's negative-index wraparound, which stops the
    compiler from vectorising them (a signed range from an unknown start could be negative):
    a 16 × 16 block product ran 2.6 times faster.
    """
    return (np.uint64(xb[c, 0]), np.uint64(xb[c, 1]), np.uint64(ub[c, 0]), np.uint64(ub[c, 1]))


@numba.njit(cache=True)
def _riccati_stage(
    a: FloatArray,
    b: FloatArray,
    weights: tuple[FloatArray, FloatArray, FloatArray],
    l_x: FloatArray,
    l_u: FloatArray,
    p: FloatArray,
    r: FloatArray,
    xb: IntArray,
    ub: IntArray,
    work: tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray],
) -> bool:
    """One stage of the Riccati recursion with cross term, on a component's own matrices.

    ``A (n × n)`` and ``B (n × m)`` are block-diagonal in the local ranges ``xb``, ``ub``
    (``(start, stop)`` per block, ``n = xb[-1, 1]``, ``m = ub[-1, 1]``; only entries inside
    the blocks are read, exact zeros of ``A`` and ``B`` skipped in ``AᵀP`` and ``BᵀP``);
    ``weights = (Q, S, R)``, ``l_x``, ``l_u`` the gradients, ``P``, ``r`` the
    next stage's. With ``G = Sᵀ + BᵀPA``, ``M = R + BᵀPB`` and
    ``g = l_u + Bᵀr``: ``K = M⁻¹G``, ``v = −M⁻¹g``, ``P ← Q + AᵀPA − GᵀK`` and
    ``r ← l_x + Aᵀr − Kᵀg``, written over ``p`` and ``r``.

    ``work = (ap, bp, apa, bpa, bpb, solution)``: workspaces of at least ``n × (n + 1)``,
    ``m × (n + 1)``, ``n × n``, ``m × n``, ``m × m`` and ``m × (n + 1 + m)``; on return
    ``solution[:m, :n + 1 + m]`` is ``[K | −v | M⁻¹]``. False (``p``, ``r``, ``solution``
    then undefined) unless ``M`` is positive definite.
    """
    q, s, weight_r = weights
    ap, bp, apa, bpa, bpb, solution = work
    n, m = xb[-1, 1], ub[-1, 1]
    for j in range(n):  # [AᵀP | Aᵀr], [BᵀP | Bᵀr], skipping exact zeros of A and B
        for col in range(n + 1):
            ap[j, col] = 0.0
    for i in range(m):
        for col in range(n + 1):
            bp[i, col] = 0.0
    for c in range(xb.shape[0]):
        x0, x1, u0, u1 = _unsigned_block(xb, ub, c)
        for k in range(x0, x1):
            next_r = r[k]
            for j in range(x0, x1):
                entry = a[k, j]
                if entry != 0.0:
                    for col in range(n):
                        ap[j, col] += entry * p[k, col]
                    ap[j, n] += entry * next_r
            for i in range(u0, u1):
                entry = b[k, i]
                if entry != 0.0:
                    for col in range(n):
                        bp[i, col] += entry * p[k, col]
                    bp[i, n] += entry * next_r
    for i in range(n):
        for j in range(n):
            apa[i, j] = q[i, j]
    for i in range(m):
        for j in range(n):
            bpa[i, j] = s[j, i]
        for j in range(m):
            bpb[i, j] = weight_r[i, j]
    for c in range(xb.shape[0]):  # Q + AᵀPA, Sᵀ + BᵀPA, R + BᵀPB, row by row
        x0, x1, u0, u1 = _unsigned_block(xb, ub, c)
        for i in range(n):
            for k in range(x0, x1):
                factor = ap[i, k]
                for j in range(x0, x1):
                    apa[i, j] += factor * a[k, j]
        for i in range(m):
            for k in range(x0, x1):
                factor = bp[i, k]
                for j in range(x0, x1):
                    bpa[i, j] += factor * a[k, j]
                for j in range(u0, u1):
                    bpb[i, j] += factor * b[k, j]
    for i in range(m):  # [G | g | I] → [K | −v | M⁻¹], g = l_u + Bᵀr
        for j in range(n):
            solution[i, j] = bpa[i, j]
        bp[i, n] += l_u[i]
        solution[i, n] = bp[i, n]
        for j in range(m):
            solution[i, n + 1 + j] = 1.0 if i == j else 0.0
    if not _solve_in_place(bpb, m, solution, n + 1 + m):
        return False
    for i in range(n):  # r ← l_x + Aᵀr − Kᵀg
        value = l_x[i] + ap[i, n]
        for j in range(m):
            value -= solution[j, i] * bp[j, n]
        r[i] = value
    _subtract_gain_term(apa, bpa, solution, n, m)  # P ← Q + AᵀPA − GᵀK
    for i in range(n):
        for j in range(n):
            p[i, j] = 0.5 * (apa[i, j] + apa[j, i])
    return True


@numba.njit(cache=True)
def _riccati_workspaces(
    n_x: int, n_u: int
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """Workspaces of :func:`_riccati_stage` for up to ``n_x`` states and ``n_u`` inputs."""
    return (
        np.empty((n_x, n_x + 1)),
        np.empty((n_u, n_x + 1)),
        np.empty((n_x, n_x)),
        np.empty((n_u, n_x)),
        np.empty((n_u, n_u)),
        np.empty((n_u, n_x + 1 + n_u)),
    )


@numba.njit(cache=True)
def _subtract_gain_term(apa: FloatArray, g: FloatArray, gain: FloatArray, n: int, m: int) -> None:
    """``apa[:n, :n] −= Gᵀ K`` for ``G = g[:m, :n]``, ``K = gain[:m, :n]`` (row by row of K)."""
    for i in range(m):
        for row in range(n):
            factor = g[i, row]
            for j in range(n):
                apa[row, j] -= factor * gain[i, j]


#: Relative change of ``P`` below which :func:`discrete_are`'s doubling has converged (it
#: converges quadratically: the next iterate would change ``P`` by about its square).
ARE_TOLERANCE = 1e-12
#: Doubling steps before :func:`discrete_are` gives up (each squares the closed loop's
#: contraction, so 64 cover any stabilisable system short of a unit-circle mode).
ARE_MAX_STEPS = 64


@numba.njit(cache=True, nogil=True)
def discrete_are(
    a_mat: FloatArray, b_mat: FloatArray, q_r: FloatArray, r_r: FloatArray
) -> tuple[FloatArray, bool]:
    """Stabilising solution of ``P = AᵀPA − AᵀPB (R + BᵀPB)⁻¹ BᵀPA + Q`` by doubling.

    The structure-preserving doubling algorithm (Chu, Fan & Lin 2005): from ``A_0 = A``,
    ``G_0 = B R⁻¹ Bᵀ``, ``H_0 = Q``, with ``W_k = I + G_k H_k``,

    ``A_{k+1} = A_k W_k⁻¹ A_k``, ``G_{k+1} = G_k + A_k W_k⁻¹ G_k A_kᵀ``,
    ``H_{k+1} = H_k + A_kᵀ H_k W_k⁻¹ A_k``,

    and ``H_k → P`` quadratically (``H_k`` is the Riccati recursion from ``Q`` after
    ``2^k`` steps) when ``(A, B)`` is stabilisable and ``(A, Q^½)`` detectable. About 10
    steps for a vehicle's ``8 × 8`` system, some 30 times faster than
    :func:`scipy.linalg.solve_discrete_are` (QZ), with the same solution to rounding.

    Returns ``P`` (symmetric) and whether the doubling converged to a finite one within
    :data:`ARE_MAX_STEPS` (it diverges when ``(A, B)`` is not stabilisable).
    """
    n = a_mat.shape[0]
    g = b_mat @ np.linalg.solve(r_r, np.ascontiguousarray(b_mat.T))
    g = 0.5 * (g + g.T)
    h = 0.5 * (q_r + q_r.T)
    a = a_mat.copy()
    right = np.empty((n, 2 * n))
    for _ in range(ARE_MAX_STEPS):
        w = g @ h
        for i in range(n):
            w[i, i] += 1.0
        right[:, :n] = a
        right[:, n:] = g
        solved = np.linalg.solve(w, right)  # [W⁻¹ A_k | W⁻¹ G_k]
        w_a, w_g = np.ascontiguousarray(solved[:, :n]), np.ascontiguousarray(solved[:, n:])
        a_t = np.ascontiguousarray(a.T)
        h_next = h + a_t @ (h @ w_a)
        g_next = g + a @ (w_g @ a_t)
        a = a @ w_a
        h_next = 0.5 * (h_next + h_next.T)
        g = 0.5 * (g_next + g_next.T)
        change, size = np.max(np.abs(h_next - h)), np.max(np.abs(h_next))
        h = h_next
        if not np.isfinite(change + size):
            return h, False
        if change <= ARE_TOLERANCE * size:
            return h, True
    return h, False


@numba.njit(cache=True, nogil=True)
def regulator_riccati(
    a_mat: FloatArray, b_mat: FloatArray, q_r: FloatArray, r_r: FloatArray, p_final: FloatArray
) -> tuple[FloatArray, bool]:
    """Time-varying discrete LQR gains ``K_k = M⁻¹ Bᵀ P_{k+1} A`` (pronto.md §6.1).

    ``M = R_r + BᵀPB`` and ``P_k = Q_r + AᵀPA − (BᵀPA)ᵀ K_k``: :func:`_riccati_stage` on one
    block without cross term nor gradients. ``a_mat (N, n_x, n_x)`` and ``b_mat`` may be
    views into a larger system's matrices (a subsystem's blocks): each stage's is copied
    into a workspace. Returns the gains ``(N, n_u, n_x)`` and ``ok`` (False if some ``M_k``
    was not PD).
    """
    n_stages, n_x, n_u = b_mat.shape
    gains = np.zeros((n_stages, n_u, n_x))
    xb, ub = np.array([[0, n_x]]), np.array([[0, n_u]])  # one block
    no_cross, no_x, no_u = np.zeros((n_x, n_u)), np.zeros(n_x), np.zeros(n_u)
    p, r = p_final.copy(), np.zeros(n_x)
    a, b = np.empty((n_x, n_x)), np.empty((n_x, n_u))
    work = _riccati_workspaces(n_x, n_u)
    solution = work[-1]
    for k in range(n_stages - 1, -1, -1):
        a[:, :] = a_mat[k]
        b[:, :] = b_mat[k]
        if not _riccati_stage(a, b, (q_r, no_cross, r_r), no_x, no_u, p, r, xb, ub, work):
            return gains, False
        gains[k] = solution[:, :n_x]
    return gains, True


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
    blocks and skip their exact zeros (``O(n_c² n_block)``). With ``G = Sᵀ + BᵀPA``,
    ``M = R + BᵀPB`` and ``g = l_u + Bᵀr`` (``P``, ``r`` of stage ``k + 1``), stage ``k`` has
    ``K = M⁻¹G``, ``v = −M⁻¹g``, ``P ← Q + AᵀPA − GᵀK`` and ``r ← l_x + Aᵀr − Kᵀg``, all
    formed in workspaces allocated once per sweep.

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
    work = _riccati_workspaces(n_x, n_u)
    solution = work[-1]  # [K | −v | M⁻¹]
    # a component's matrices and vectors, in their leading rows and columns
    a_c, b_c = np.empty((n_x, n_x)), np.empty((n_x, n_u))
    q_c, s_c, r_c = np.empty((n_x, n_x)), np.empty((n_x, n_u)), np.empty((n_u, n_u))
    p_c, lx_c, lu_c, rv_c = np.empty((n_x, n_x)), np.empty(n_x), np.empty(n_u), np.empty(n_x)
    _join_coupled(p, x_owner, x_owner, parent)
    first = _component(parent, 0, x_blocks, u_blocks)  # block 0's component
    for k in range(n_stages - 1, -1, -1):
        if not _all_joined(parent):  # else nothing is left to join, nor to split
            _join_coupled(q_mat[k], x_owner, x_owner, parent)
            _join_coupled(s_mat[k], x_owner, u_owner, parent)
            _join_coupled(r_mat[k], u_owner, u_owner, parent)
            first = _component(parent, 0, x_blocks, u_blocks)
        for root in range(n_blocks):
            if _root(parent, root) != root:
                continue
            xs, us, xb, ub = first if root == 0 else _component(parent, root, x_blocks, u_blocks)
            n, m = xs.size, us.size
            if n == n_x and m == n_u:  # the whole system: its own matrices, in place
                if not _riccati_stage(
                    a_mat[k], b_mat[k], (q_mat[k], s_mat[k], r_mat[k]), l_x[k], l_u[k], p, r,
                    xb, ub, work,
                ):  # fmt: skip
                    return feedback, feedforward, m_inverse, k
                feedback[k] = solution[:, :n_x]
                feedforward[k] = -solution[:, n_x]
                m_inverse[k] = solution[:, n_x + 1 :]
                continue
            _gather_component(a_mat[k], xs, xs, a_c)  # zero between blocks, as in A
            _gather_component(b_mat[k], xs, us, b_c)
            _gather_component(q_mat[k], xs, xs, q_c)
            _gather_component(s_mat[k], xs, us, s_c)
            _gather_component(r_mat[k], us, us, r_c)
            _gather_component(p, xs, xs, p_c)
            for i in range(n):
                lx_c[i], rv_c[i] = l_x[k, xs[i]], r[xs[i]]
            for i in range(m):
                lu_c[i] = l_u[k, us[i]]
            if not _riccati_stage(a_c, b_c, (q_c, s_c, r_c), lx_c, lu_c, p_c, rv_c, xb, ub, work):
                return feedback, feedforward, m_inverse, k
            _scatter_component(p_c, xs, xs, p)
            _scatter_component(solution, us, xs, feedback[k])
            _scatter_component(solution[:, n + 1 :], us, us, m_inverse[k])
            for i in range(n):
                r[xs[i]] = rv_c[i]
            for i in range(m):
                feedforward[k, us[i]] = -solution[i, n]
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
    n_stages, n_x, n_u = b_mat.shape
    feedforward = np.zeros((n_stages, n_u))
    r, r_next = r_final.copy(), np.empty(n_x)
    g = np.empty(n_u)
    for k in range(n_stages - 1, -1, -1):
        for i in range(n_u):
            g[i] = l_u[k, i]
        _add_transpose_times(b_mat[k], r, g)
        _add_times(m_inverse[k], g, feedforward[k], -1.0)
        for j in range(n_x):
            r_next[j] = l_x[k, j]
        _add_transpose_times(a_mat[k], r, r_next)
        for i in range(n_u):
            g[i] = -g[i]
        _add_transpose_times(feedback[k], g, r_next)
        r, r_next = r_next, r
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
        for i in range(n_u):
            v[k, i] = feedforward[k, i]
        _add_times(feedback[k], z[k], v[k], -1.0)
        _add_times(a_mat[k], z[k], z[k + 1], 1.0)
        _add_times(b_mat[k], v[k], z[k + 1], 1.0)
    return z, v
