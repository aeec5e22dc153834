r"""Separable stage models: independent subsystems (vehicles) evaluated by compiled kernels.

A fleet's dynamics are block-diagonal and its running cost is a sum over vehicles, so the
stacked problem is described exactly by its **blocks**: block ``b`` owns the rows
``states``, ``inputs`` and ``parameters`` of the stacked ``x``, ``u`` and ``p`` and has its
own ``ẋ_b = f_b(x_b, u_b, p_b)`` and cost rate ``l_b(x_b, u_b, p_b, w_b)`` with runtime
weights ``w_b``:

.. math::

    f(x, u, p) = (f_1(x_1, u_1, p_1), …, f_B(x_B, u_B, p_B)),\qquad
    l(x, u, p) = \sum_b l_b(x_b, u_b, p_b, w_b).

:func:`stack_blocks` builds the stacked CasADi functions from the blocks (one owner of the
equations; the IPOPT reference and the CasADi path use them), and
:class:`BlockDiscreteModel` evaluates the discrete step and its derivatives block by block
with the compiled substep kernels (:mod:`~auvplan.optimization.block_kernels`): blocks with
the same model share one kernel set and are evaluated together, the stacked derivatives are
block-diagonal. It is a :class:`~auvplan.optimization.discretization.StepModel`.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import casadi as ca
import numba
import numpy as np

from auvplan._typing import FloatArray, IntArray
from auvplan.errors import InputError
from auvplan.optimization._casadi import check_rollout, check_stages
from auvplan.optimization.block_kernels import BlockKernels, LastCall, block_kernels

__all__ = [
    "BlockDiscreteModel",
    "StageBlock",
    "check_tiling",
    "coordinate_groups",
    "stack_blocks",
]


@dataclass(frozen=True, eq=False)
class StageBlock:
    """One independent subsystem of a separable stage model.

    Attributes
    ----------
    dynamics : casadi.Function
        ``f_b(x_b, u_b, p_b) -> ẋ_b`` (continuous time, SX).
    running_cost : casadi.Function
        ``l_b(x_b, u_b, p_b, w_b) -> scalar`` cost rate (SX).
    weights : ndarray of shape (n_w,)
        Runtime values of ``w_b``.
    states, inputs, parameters : slice
        Rows of the block in the stacked state, input and stage parameter.
    """

    dynamics: ca.Function
    running_cost: ca.Function
    weights: FloatArray
    states: slice
    inputs: slice
    parameters: slice

    def __post_init__(self) -> None:
        sizes = [int(self.dynamics.numel_in(i)) for i in range(3)]
        spans = [s.stop - s.start for s in (self.states, self.inputs, self.parameters)]
        weights = np.asarray(self.weights, dtype=np.float64).reshape(-1)
        if sizes != spans or weights.size != self.running_cost.numel_in(3):
            raise InputError(f"StageBlock sizes {sizes} do not match its slices {spans}")
        object.__setattr__(self, "weights", weights)


def check_tiling(blocks: Sequence[StageBlock], sizes: tuple[int, int, int]) -> None:
    """Check that the blocks' rows tile the stacked ``(n_x, n_u, n_p)`` exactly.

    The stage parameters may end with rows no block reads (parameters of the path
    constraints only, e.g. other vehicles' positions).

    Raises
    ------
    InputError
        On a gap or an overlap.
    """
    for attribute, size in zip(("states", "inputs", "parameters"), sizes, strict=True):
        rows = sorted((getattr(b, attribute).start, getattr(b, attribute).stop) for b in blocks)
        if attribute == "parameters" and rows:
            size = min(size, rows[-1][1])
        edges = [start for start, _ in rows] + [size]
        if edges[0] != 0 or any(stop != edges[i + 1] for i, (_, stop) in enumerate(rows)):
            raise InputError(f"the blocks' {attribute} do not tile the {size} stacked rows")


def coordinate_groups(blocks: Sequence[StageBlock], n_x: int) -> tuple[IntArray, ...]:
    """Each block's rows of ``z = (x, u)`` (its states, then ``n_x`` + its inputs)."""
    return tuple(
        np.concatenate(
            [
                np.arange(b.states.start, b.states.stop),
                n_x + np.arange(b.inputs.start, b.inputs.stop),
            ]
        )
        for b in blocks
    )


def stack_blocks(
    blocks: Sequence[StageBlock], n_x: int, n_u: int, n_p: int
) -> tuple[ca.Function, ca.Function]:
    """Stacked ``f(x, u, p)`` and ``l(x, u, p)`` of the blocks (module equations).

    Raises
    ------
    InputError
        If the blocks do not tile ``x``, ``u`` and ``p`` exactly.
    """
    check_tiling(blocks, (n_x, n_u, n_p))
    x, u, p = ca.SX.sym("x", n_x), ca.SX.sym("u", n_u), ca.SX.sym("p", n_p)
    xdot = ca.SX.zeros(n_x)
    rate = ca.SX(0.0)
    for block in blocks:
        args = (x[block.states], u[block.inputs], p[block.parameters])
        xdot[block.states] = block.dynamics(*args)
        rate += block.running_cost(*args, ca.DM(block.weights))
    return ca.Function("stacked_f", [x, u, p], [xdot]), ca.Function("stacked_l", [x, u, p], [rate])


@dataclass(frozen=True)
class _Group:
    """Blocks sharing one kernel set, with their stacked weights ``(n_blocks, n_w)``."""

    kernels: BlockKernels
    blocks: tuple[StageBlock, ...]
    weights: FloatArray

    @functools.cached_property
    def starts(self) -> tuple[IntArray, IntArray]:
        """Each block's first row in the stacked state and input."""
        return (
            np.array([b.states.start for b in self.blocks], dtype=np.uint64),
            np.array([b.inputs.start for b in self.blocks], dtype=np.uint64),
        )


@numba.njit(cache=True)
def _place_blocks(
    source: FloatArray,
    rows: IntArray,
    columns: IntArray,
    source_corner: tuple[int, int],
    size: tuple[int, int],
    out: FloatArray,
) -> None:
    """Write each block's part of ``source`` into its place in the stacked ``out``.

    Block ``i``'s stage ``k`` is ``source[i N + k]`` (``N = out.shape[0]``); its
    ``size = (r, c)`` entries from ``source_corner`` go to ``out[k]`` from
    ``(rows[i], columns[i])`` (unsigned: no negative-index wraparound in the loops). Every
    other entry of ``out`` is left as it is.
    """
    n_stages = out.shape[0]
    first_row, first_column = np.uint64(source_corner[0]), np.uint64(source_corner[1])
    n_rows, n_columns = np.uint64(size[0]), np.uint64(size[1])
    for i in range(rows.size):
        for k in range(n_stages):
            block, stage = source[i * n_stages + k], out[k]
            for r in range(n_rows):
                line, target = block[first_row + r], stage[rows[i] + r]
                for c in range(n_columns):
                    target[columns[i] + c] = line[first_column + c]


@dataclass(frozen=True, eq=False)
class BlockDiscreteModel:
    """The discrete step of a separable model, evaluated with compiled substep kernels.

    Same methods and array conventions as
    :class:`~auvplan.optimization.discretization.DiscreteModel` (time-major stacked arrays).
    Build it with :meth:`build`.
    """

    n_x: int
    n_u: int
    n_p: int
    dt: float
    n_substeps: int
    groups: tuple[_Group, ...] = field(repr=False)
    threads: int = 1
    """Threads the kernels split their points over (the same results for any number)."""
    _rolled: LastCall[FloatArray] = field(default_factory=LastCall, repr=False)
    """The stage costs of the last closed-loop :meth:`rollout`, by its stages, inputs and
    parameters: :meth:`cost` of that trajectory (a line-search trial) reads them."""

    @classmethod
    def build(
        cls,
        blocks: Sequence[StageBlock],
        sizes: tuple[int, int, int],
        dt: float,
        n_substeps: int,
        cache_dir: Path | None = None,
        threads: int = 1,
    ) -> BlockDiscreteModel:
        """Load (or compile once) the kernels of every distinct block model.

        Raises
        ------
        UnsupportedOperation
            If a block model cannot be translated (the caller uses CasADi instead).
        """
        check_tiling(blocks, sizes)
        members: dict[int, tuple[BlockKernels, list[StageBlock]]] = {}
        for block in blocks:
            kernels = block_kernels(block.dynamics, block.running_cost, cache_dir)
            members.setdefault(id(kernels), (kernels, []))[1].append(block)
        groups = tuple(
            _Group(kernels, tuple(group), np.array([b.weights for b in group]))
            for kernels, group in members.values()
        )
        return cls(*sizes, dt=dt, n_substeps=n_substeps, groups=groups, threads=threads)

    @property
    def h(self) -> float:
        """RK4 substep length ``dt / n_substeps`` [s]."""
        return self.dt / self.n_substeps

    def _points(
        self, group: _Group, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """The group's blocks stacked on the point axis: ``(n_blocks · N, ·)`` arrays."""
        n_stages = states.shape[0]

        def gather(array: FloatArray, attribute: str) -> FloatArray:
            return np.ascontiguousarray(
                np.concatenate([array[:, getattr(b, attribute)] for b in group.blocks])
            )

        weights = np.repeat(group.weights, n_stages, axis=0)
        return (
            gather(states, "states"),
            gather(inputs, "inputs"),
            gather(parameters, "parameters"),
            weights,
        )

    def _checked(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        states = check_stages(states, self.n_x, "X", None)
        n_stages = states.shape[0]
        return (
            states,
            check_stages(inputs, self.n_u, "U", n_stages),
            check_stages(parameters, self.n_p, "P", n_stages),
        )

    def step(self, states: FloatArray, inputs: FloatArray, parameters: FloatArray) -> FloatArray:
        """Next states ``F(x_k, u_k, p_k)``, shape ``(N, n_x)``."""
        return self._step_and_cost(states, inputs, parameters)[0]

    def cost(self, states: FloatArray, inputs: FloatArray, parameters: FloatArray) -> FloatArray:
        """Stage costs ``L(x_k, u_k, p_k)``, shape ``(N,)``.

        Those of the last :meth:`rollout` when these are its stages, inputs and parameters
        (the closed-loop kernel sums them as :meth:`step` does, to the bit).
        """
        costs = self._rolled.get(states, inputs, parameters)
        if costs is not None:
            return costs.copy()
        return self._step_and_cost(states, inputs, parameters)[1]

    def _step_and_cost(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        states, inputs, parameters = self._checked(states, inputs, parameters)
        n_stages = states.shape[0]
        next_states = np.empty_like(states)
        cost = np.zeros(n_stages)
        for group in self.groups:
            points = self._points(group, states, inputs, parameters)
            stepped, increments = group.kernels.step(*points, self.h, self.n_substeps)
            for i, block in enumerate(group.blocks):
                rows = slice(i * n_stages, (i + 1) * n_stages)
                next_states[:, block.states] = stepped[rows]
                cost += increments[rows]
        return next_states, cost

    def first_order(
        self,
        states: FloatArray,
        inputs: FloatArray,
        parameters: FloatArray,
        remember: bool = True,
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
        """``(F_x, F_u, L, L_x, L_u)``; ``F_x``, ``F_u`` block-diagonal.

        ``remember``: keep the kernels' forward sweeps for the Hessians at these points.
        """
        states, inputs, parameters = self._checked(states, inputs, parameters)
        n_stages = states.shape[0]
        f_x = np.zeros((n_stages, self.n_x, self.n_x))
        f_u = np.zeros((n_stages, self.n_x, self.n_u))
        cost = np.zeros(n_stages)
        l_x, l_u = np.zeros((n_stages, self.n_x)), np.zeros((n_stages, self.n_u))
        for group in self.groups:
            points = self._points(group, states, inputs, parameters)
            jac, total, grad = group.kernels.first_order(
                *points, self.h, self.n_substeps, remember, self.threads
            )
            n_bx, n_bu = group.kernels.n_x, group.kernels.n_u
            xs, us = group.starts
            _place_blocks(jac, xs, xs, (0, 0), (n_bx, n_bx), f_x)
            _place_blocks(jac, xs, us, (0, n_bx), (n_bx, n_bu), f_u)
            for i, block in enumerate(group.blocks):
                rows = slice(i * n_stages, (i + 1) * n_stages)
                cost += total[rows]
                l_x[:, block.states] = grad[rows, :n_bx]
                l_u[:, block.inputs] = grad[rows, n_bx:]
        return f_x, f_u, cost, l_x, l_u

    def jacobians(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """``F_x (N, n_x, n_x)`` and ``F_u (N, n_x, n_u)`` (the remembered sweeps are kept)."""
        f_x, f_u, _, _, _ = self.first_order(states, inputs, parameters, remember=False)
        return f_x, f_u

    def _weighted_hessians(
        self,
        states: FloatArray,
        inputs: FloatArray,
        parameters: FloatArray,
        costate_next: FloatArray,
        cost_weight: float,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        states, inputs, parameters = self._checked(states, inputs, parameters)
        n_stages = states.shape[0]
        costate_next = check_stages(costate_next, self.n_x, "costate_next", n_stages)
        h_xx = np.zeros((n_stages, self.n_x, self.n_x))
        h_xu = np.zeros((n_stages, self.n_x, self.n_u))
        h_uu = np.zeros((n_stages, self.n_u, self.n_u))
        for group in self.groups:
            points = self._points(group, states, inputs, parameters)
            weights = np.concatenate([costate_next[:, b.states] for b in group.blocks])
            hessian = group.kernels.hessian(
                *points, self.h, self.n_substeps, np.ascontiguousarray(weights), cost_weight,
                self.threads,
            )  # fmt: skip
            n_bx, n_bu = group.kernels.n_x, group.kernels.n_u
            xs, us = group.starts
            _place_blocks(hessian, xs, xs, (0, 0), (n_bx, n_bx), h_xx)
            _place_blocks(hessian, xs, us, (0, n_bx), (n_bx, n_bu), h_xu)
            _place_blocks(hessian, us, us, (n_bx, n_bx), (n_bu, n_bu), h_uu)
        return h_xx, h_xu, h_uu

    def lagrangian_hessians(
        self,
        states: FloatArray,
        inputs: FloatArray,
        parameters: FloatArray,
        costate_next: FloatArray,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Hessian blocks of ``L + λ_{k+1}ᵀ F`` (block-diagonal)."""
        return self._weighted_hessians(states, inputs, parameters, costate_next, 1.0)

    def weighted_hessians(
        self,
        states: FloatArray,
        inputs: FloatArray,
        parameters: FloatArray,
        costate_next: FloatArray,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Hessian blocks of ``λ_{k+1}ᵀ F`` (no cost)."""
        return self._weighted_hessians(states, inputs, parameters, costate_next, 0.0)

    def cost_hessians(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Hessian blocks of ``L`` (the step's own second derivatives enter through ``L``)."""
        zeros = np.zeros((np.shape(states)[0], self.n_x))
        return self._weighted_hessians(states, inputs, parameters, zeros, 1.0)

    def rollout(
        self,
        initial_state: FloatArray,
        reference_states: FloatArray,
        reference_inputs: FloatArray,
        gains: FloatArray,
        parameters: FloatArray,
    ) -> tuple[FloatArray, FloatArray]:
        """Closed-loop simulation ``u_k = μ_k + K_k (α_k − x_k)``, ``x_{k+1} = F(x_k, u_k, p_k)``.

        Same arguments and results as
        :meth:`~auvplan.optimization.discretization.DiscreteModel.rollout`.
        """
        x0, alpha, mu, gains, params = check_rollout(
            (self.n_x, self.n_u, self.n_p),
            initial_state, reference_states, reference_inputs, gains, parameters,
        )  # fmt: skip
        n_stages = mu.shape[0]
        if not self._block_diagonal(gains):
            return self._coupled_rollout(x0, alpha, mu, gains, params)
        states = np.empty((n_stages + 1, self.n_x))
        inputs = np.empty((n_stages, self.n_u))
        costs = np.zeros(n_stages)
        for group in self.groups:
            blocks = group.blocks
            path, applied, increments = group.kernels.closed_loop(
                np.stack([x0[b.states] for b in blocks]),
                np.stack([alpha[:, b.states] for b in blocks]),
                np.stack([mu[:, b.inputs] for b in blocks]),
                np.stack([gains[:, b.inputs, b.states] for b in blocks]),
                np.stack([params[:, b.parameters] for b in blocks]),
                group.weights,
                self.h,
                self.n_substeps,
                self.threads,
            )
            for i, block in enumerate(blocks):
                states[:, block.states] = path[i, :: self.n_substeps]
                inputs[:, block.inputs] = applied[i]
                costs += increments[i]
        self._rolled.put(costs, states[:-1], inputs, params)
        return states, inputs

    def _block_diagonal(self, gains: FloatArray) -> bool:
        """Whether ``gains`` act on each block's own states only, as the regulator's do.

        Round-off coupling (below ``1e-10`` of the largest gain, e.g. from the terminal
        Riccati solution of a block-diagonal system) counts as none.
        """
        coupling = np.abs(gains)
        scale = float(np.max(coupling, initial=0.0))
        for group in self.groups:
            for block in group.blocks:
                coupling[:, block.inputs, block.states] = 0.0
        return bool(np.max(coupling, initial=0.0) <= 1e-10 * scale)

    def _coupled_rollout(
        self,
        x0: FloatArray,
        alpha: FloatArray,
        mu: FloatArray,
        gains: FloatArray,
        params: FloatArray,
    ) -> tuple[FloatArray, FloatArray]:
        """The rollout stage by stage, for gains that couple the blocks."""
        n_stages = mu.shape[0]
        states = np.empty((n_stages + 1, self.n_x))
        states[0] = x0
        inputs = np.empty((n_stages, self.n_u))
        with np.errstate(all="ignore"):
            for k in range(n_stages):
                inputs[k] = mu[k] + gains[k] @ (alpha[k] - states[k])
                stage = slice(k, k + 1)
                states[k + 1] = self.step(states[stage], inputs[stage], params[stage])[0]
        return states, inputs
