"""The projection operator ``P``: time-varying LQR along a curve and the closed-loop rollout.

``reference/pronto.md`` §6.1: ``u_k = μ_k + K_k (α_k − x_k)``, ``x_{k+1} = F(x_k, u_k, p_k)``
from ``x_0``, with ``K_k`` the discrete LQR designed along the current trajectory.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from auvplan._typing import FloatArray, IntArray
from auvplan.errors import SolverError
from auvplan.optimization import _kernels
from auvplan.optimization._threads import map_threads
from auvplan.optimization.lq import block_ranges
from auvplan.optimization.model import ProntoModel
from auvplan.optimization.options import ProntoOptions, TerminalRegulator, named_choice
from auvplan.optimization.problem import Trajectory
from auvplan.optimization.separable import coordinate_groups

__all__ = ["design_regulator", "project", "project_guess", "regulator_gains"]


def design_regulator(
    A: FloatArray,
    B: FloatArray,
    Q_r: FloatArray,
    R_r: FloatArray,
    *,
    terminal: TerminalRegulator | Literal["dare", "weight"] = TerminalRegulator.DARE,
    blocks: tuple[IntArray, IntArray] | None = None,
    replaced: tuple[IntArray, FloatArray, FloatArray] | None = None,
    threads: int = 1,
) -> FloatArray:
    """Time-varying discrete LQR along a trajectory (the projection regulator, §6.1).

    With ``blocks`` (state and input ``(start, stop)`` ranges of independent subsystems,
    :func:`~auvplan.optimization.lq.block_ranges`) and weights without entries between them,
    the Riccati matrices stay block-diagonal: each subsystem's regulator (its terminal ARE
    included) is designed on its own, on ``threads`` threads: the same gains at a fraction of
    the cost (zero between subsystems).

    Parameters
    ----------
    A, B : ndarray of shape (N, n_x, n_x), (N, n_x, n_u)
        Linearisation along the trajectory.
    Q_r, R_r : ndarray of shape (n_x, n_x), (n_u, n_u)
        Regulator weights (``R_r ≻ 0``).
    terminal : TerminalRegulator or {"dare", "weight"}
        ``P_N`` the stabilising solution of the discrete ARE at the last stage (``Q_r`` when
        it has none) or ``Q_r``.
    replaced : tuple, optional
        ``(stages, A_s, B_s)``: the regulator is designed on ``A_s``, ``B_s`` at these
        stages instead (``A`` and ``B`` are not modified, nor copied whole).
    threads : int
        Threads the independent subsystems' designs run on (the same gains for any number).

    Returns
    -------
    ndarray of shape (N, n_u, n_x)
        Gains ``K_k`` for ``u_k = μ_k + K_k (α_k − x_k)``.

    Raises
    ------
    InputError
        If ``terminal`` is not a known choice.
    SolverError
        If the Riccati recursion breaks down (non-finite linearisation).
    """
    stages, a_replaced, b_replaced = (
        replaced if replaced is not None else (np.empty(0, np.int64), A[:0], B[:0])
    )
    last = stages.size > 0 and stages[-1] == A.shape[0] - 1
    a_last, b_last = (a_replaced[-1], b_replaced[-1]) if last else (A[-1], B[-1])
    dare = named_choice(TerminalRegulator, terminal, "terminal") is TerminalRegulator.DARE

    def design(part: tuple[slice, slice]) -> tuple[FloatArray, bool]:
        states, inputs = part
        q_r, r_r = Q_r[states, states], R_r[inputs, inputs]
        a_block, b_block = A[:, states, states], B[:, states, inputs]
        if stages.size:  # copies of this subsystem's blocks only
            a_block, b_block = a_block.copy(), b_block.copy()
            a_block[stages] = a_replaced[:, states, states]
            b_block[stages] = b_replaced[:, states, inputs]
        p_final = q_r
        if dare:
            p_final = _terminal_are(a_last[states, states], b_last[states, inputs], q_r, r_r)
        return _kernels.regulator_riccati(
            a_block,
            b_block,
            np.ascontiguousarray(q_r),
            np.ascontiguousarray(r_r),
            np.ascontiguousarray(p_final),
        )

    parts = _independent(blocks, Q_r, R_r, A.shape[1], B.shape[2])
    gains = np.zeros((A.shape[0], B.shape[2], A.shape[1]))
    ok = True
    for (states, inputs), (block, block_ok) in zip(
        parts, map_threads(design, parts, threads), strict=True
    ):
        gains[:, inputs, states] = block
        ok = ok and block_ok
    if not ok or not np.all(np.isfinite(gains)):
        raise SolverError(
            "the projection-regulator Riccati recursion broke down (non-finite A, B?)"
        )
    return gains


def _terminal_are(a: FloatArray, b: FloatArray, q_r: FloatArray, r_r: FloatArray) -> FloatArray:
    """``P_N`` of the discrete ARE at the last stage (``Q_r`` when it has no stabilising one).

    By doubling (:func:`~auvplan.optimization._kernels.discrete_are`), positive semidefinite
    by construction.
    """
    try:
        candidate, converged = _kernels.discrete_are(
            *(np.ascontiguousarray(m) for m in (a, b, q_r, r_r))
        )
    except np.linalg.LinAlgError:  # W_k singular to machine precision: diverging too
        return q_r
    return candidate if converged else q_r


def _independent(
    blocks: tuple[IntArray, IntArray] | None,
    Q_r: FloatArray,
    R_r: FloatArray,
    n_x: int,
    n_u: int,
) -> list[tuple[slice, slice]]:
    """State and input slices of the subsystems the regulator may be designed on separately.

    One (everything) unless ``blocks`` has several and ``Q_r``, ``R_r`` vanish between them.
    """
    whole = [(slice(0, n_x), slice(0, n_u))]
    if blocks is None or len(blocks[0]) < 2:
        return whole
    parts = [
        (slice(int(x0), int(x1)), slice(int(u0), int(u1)))
        for (x0, x1), (u0, u1) in zip(blocks[0], blocks[1], strict=True)
    ]
    coupled_q, coupled_r = Q_r != 0.0, R_r != 0.0
    for states, inputs in parts:
        coupled_q[states, states] = False
        coupled_r[inputs, inputs] = False
    return whole if coupled_q.any() or coupled_r.any() else parts


def regulator_gains(
    model: ProntoModel,
    trajectory: Trajectory,
    A: FloatArray,
    B: FloatArray,
    options: ProntoOptions,
) -> FloatArray:
    """The projection regulator along ``trajectory`` (given its exact ``A``, ``B``).

    With :attr:`TrajectoryProblem.regulator_floor` the regulator is designed on the
    linearisation at the floored states instead (the Jacobians are evaluated again at the
    stages where a state lies below its floor).
    """
    problem = model.problem
    replaced = None
    if problem.regulator_floor is not None:
        states = trajectory.states[:-1]
        below = np.abs(states) < problem.regulator_floor
        stages = np.flatnonzero(np.any(below, axis=1))
        if stages.size:
            sign = np.where(states[stages] < 0.0, -1.0, 1.0)
            design = np.where(below[stages], sign * problem.regulator_floor, states[stages])
            replaced = (
                stages,
                *model.discrete.jacobians(
                    design, trajectory.inputs[stages], problem.parameters[stages]
                ),
            )
    return design_regulator(
        A,
        B,
        problem.state_weight,
        problem.input_weight,
        terminal=options.terminal_regulator,
        blocks=block_ranges(
            coordinate_groups(problem.blocks, problem.n_states), problem.n_states, problem.n_inputs
        ),
        replaced=replaced,
        threads=options.n_threads,
    )


def project(model: ProntoModel, reference: Trajectory, gains: FloatArray) -> Trajectory:
    """Projection operator ``P``: closed loop ``u_k = μ_k + K_k (α_k − x_k)`` from ``x0``.

    Parameters
    ----------
    model : ProntoModel
        Evaluators.
    reference : Trajectory
        The curve ``η = (α, μ)`` (need not satisfy the dynamics).
    gains : ndarray of shape (N, n_u, n_x)
        Regulator gains.

    Returns
    -------
    Trajectory
        ``P(η)``; may contain non-finite values if the simulation diverged.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        states, inputs = model.discrete.rollout(
            model.problem.initial_state,
            reference.states,
            reference.inputs,
            gains,
            model.problem.parameters,
        )
    return Trajectory(states, inputs)


def project_guess(
    model: ProntoModel, guess: Trajectory, options: ProntoOptions
) -> tuple[Trajectory, FloatArray]:
    """Project a curve onto the trajectory manifold with a regulator designed along it.

    Returns
    -------
    trajectory : Trajectory
        ``P(guess)``, a trajectory of the discrete dynamics from ``x0``.
    gains : ndarray of shape (N, n_u, n_x)
        The regulator used.

    Raises
    ------
    SolverError
        If the closed-loop simulation diverges.
    """
    f_x, f_u = model.discrete.jacobians(guess.states[:-1], guess.inputs, model.problem.parameters)
    gains = regulator_gains(model, guess, f_x, f_u, options)
    trajectory = project(model, guess, gains)
    if not (np.all(np.isfinite(trajectory.states)) and np.all(np.isfinite(trajectory.inputs))):
        raise SolverError(
            "the projection of the initial guess diverged; use a better guess or regulator"
        )
    return trajectory, gains
