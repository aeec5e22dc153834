"""Compiled block kernels: the numba translation and the RK4 chain rule vs CasADi.

Oracles: CasADi's own evaluation of the translated Functions, the CasADi discretisation
(:func:`~auvplan.optimization.discretize_rk4`, which differentiates the RK4 expression graph)
of the same ``f`` and ``l`` with the weights fixed, central differences of the kernel
gradient, and a Python loop of single substeps for the closed loop.
"""

from __future__ import annotations

import importlib
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np
import pytest

from auvplan.optimization import BlockKernels, block_kernels, discretize_rk4
from auvplan.optimization._kernel_cache import load_kernel_module
from auvplan.optimization._lane_codegen import LANES
from auvplan.optimization._numba_codegen import (
    _BINARY,
    _TEMPLATES,
    _UNARY,
    UnsupportedOperation,
    instructions,
    numba_source,
    split_stage,
)

from ._kernel_models import assert_close, cart, fixed_weights, pendulum, unicycle

# the package exports the function ``block_kernels`` under the module's name
kernel_module = importlib.import_module("auvplan.optimization.block_kernels")

DT = 0.4
N_POINTS = 6
MODELS: dict[str, tuple[Callable[[], tuple[ca.Function, ca.Function]], np.ndarray]] = {
    "pendulum": (pendulum, np.array([1.5, 0.4])),
    "cart": (cart, np.array([0.7])),
    "unicycle": (unicycle, np.array([0.4, 0.2])),
}


def _compiled(function: ca.Function, cache: Path) -> Callable[[np.ndarray], np.ndarray]:
    """The numba kernel of a one-input, one-output Function, on rows of a 2-D array."""
    source = numba_source({"kernel": function}, "test kernel")
    module, _ = load_kernel_module(source, lambda: source, cache)

    def evaluate(rows: np.ndarray) -> np.ndarray:
        out = np.empty((rows.shape[0], function.numel_out(0)))
        module.kernel_batch(np.ascontiguousarray(rows), out)
        return out

    return evaluate


def _casadi_rows(function: ca.Function, rows: np.ndarray) -> np.ndarray:
    return np.asarray(function.map(rows.shape[0])(rows.T)).T


def _every_operation(rng: np.random.Generator) -> tuple[ca.Function, np.ndarray]:
    """A Function using every translated operation, and 200 rows of arguments for it."""
    a = ca.SX.sym("a", 8)
    # x, y in (-0.9, 0.9); s, t in (0.5, 2); big in (1.5, 3); q, r in (-3, 3); z in {-1, 0, 1}
    x, y, s, t, big, q, r, z = (a[i] for i in range(8))
    expressions = [
        x + y, x - y, x * y, x / s,
        ca.sqrt(s), ca.sin(q), ca.cos(q), ca.tan(x), ca.exp(q), ca.log(s), ca.asin(x),
        ca.acos(y), ca.atan(q), ca.sinh(q), ca.cosh(q), ca.tanh(q), ca.asinh(q), ca.acosh(big),
        ca.atanh(x), ca.erf(q), ca.fabs(q), ca.floor(q), ca.ceil(q),
        -q, q**2, 2 * q, 1 / s, s**t, s**3.5, q**3, ca.atan2(q, r), ca.fmin(q, r), ca.fmax(q, r),
        ca.copysign(s, q), ca.fmod(q, s), ca.sign(z), q < r, q <= r, q == z, q != z,
        ca.logic_not(z), ca.logic_and(z, q < 0), ca.logic_or(z, q < 0),
        ca.if_else(q < r, q * s, r * t),
    ]  # fmt: skip
    function = ca.Function("every_op", [a], [ca.vertcat(*expressions)])
    used = {function.instruction_id(k) for k in range(function.n_instructions())}
    # OP_ASSIGN never occurs in an SX Function's instruction list (it is an MX/codegen op)
    assert used >= set(_BINARY) | set(_UNARY) | set(_TEMPLATES) - {ca.OP_ASSIGN}
    n_rows = 200
    rows = np.column_stack(
        [
            rng.uniform(-0.9, 0.9, (n_rows, 2)),
            rng.uniform(0.5, 2.0, (n_rows, 2)),
            rng.uniform(1.5, 3.0, n_rows),
            rng.uniform(-3.0, 3.0, (n_rows, 2)),
            rng.integers(-1, 2, n_rows).astype(float),
        ]
    )
    rows[:20, 5] = rows[:20, 7]  # q == z: equality true, floor/ceil and sign at integers
    rows[20:25, 6] = rows[20:25, 5]  # q == r: the ties of <, <=, fmin, fmax
    rows[25:27, 5] = (1e30, -1e30)  # floor and ceil beyond the int64 range
    return function, rows


def test_every_translated_operation_evaluates_like_casadi(
    kernel_cache: Path, rng: np.random.Generator
) -> None:
    function, rows = _every_operation(rng)
    expected = _casadi_rows(function, rows)
    actual = _compiled(function, kernel_cache)(rows)
    np.testing.assert_allclose(actual, expected, rtol=1e-12, atol=0.0)


#: A loop over groups of ``LANES`` rows calling a one-input, one-output lane kernel.
_LANE_LOOP = """
@numba.njit(cache=True)
def kernel_groups(rows, out):
    arguments, results = np.empty((rows.shape[1], LANES)), np.empty((out.shape[1], LANES))
    for first in range(0, rows.shape[0], LANES):
        for lane in range(LANES):
            arguments[:, lane] = rows[first + lane]
        kernel_lanes(arguments, results)
        for lane in range(LANES):
            out[first + lane] = results[:, lane]
"""


def test_lane_kernels_equal_the_scalar_kernels_to_the_bit(
    kernel_cache: Path, rng: np.random.Generator
) -> None:
    """Every operation on ``LANES`` points at once gives the scalar kernel's bits, lane by lane."""
    function, rows = _every_operation(rng)
    assert rows.shape[0] % LANES == 0
    source = numba_source({"kernel": function}, "lane kernel", _LANE_LOOP, lanes=("kernel",))
    module, _ = load_kernel_module(source, lambda: source, kernel_cache)
    assert not hasattr(module, "kernel")  # written on lanes only
    actual = np.empty((rows.shape[0], function.numel_out(0)))
    module.kernel_groups(rows, actual)
    np.testing.assert_array_equal(actual, _compiled(function, kernel_cache)(rows))


#: Groups of ``LANES`` rows through a two-input lane kernel split at its second input.
_STAGE_LOOP = """
@numba.njit(cache=True)
def kernel_groups(rows, stage_rows, out):
    y, u = np.empty((rows.shape[1], LANES)), np.empty((stage_rows.shape[1], LANES))
    stage, results = np.empty((KERNEL_STAGE_SIZE, LANES)), np.empty((out.shape[1], LANES))
    for first in range(0, rows.shape[0], LANES):
        for lane in range(LANES):
            y[:, lane] = rows[first + lane]
            u[:, lane] = stage_rows[first + lane]
        kernel_stage_lanes(y, u, stage)
        kernel_lanes(y, u, stage, results)
        for lane in range(LANES):
            out[first + lane] = results[:, lane]
"""


def test_stage_constant_operations_are_hoisted_with_the_same_bits(
    kernel_cache: Path, rng: np.random.Generator
) -> None:
    """What depends on the stage input alone is computed once, before the rest, bit for bit."""
    every, rows = _every_operation(rng)
    _, stage_rows = _every_operation(rng)
    y, u = ca.SX.sym("y", 8), ca.SX.sym("u", 8)
    function = ca.Function("split", [y, u], [ca.vertcat(every(y) * every(u), every(u))])
    stage, body, size = split_stage(instructions(function), (1,), 2)
    transcendental = {ca.OP_SIN, ca.OP_TANH, ca.OP_ERF, ca.OP_EXP}
    assert {i.op for i in stage} >= transcendental
    assert all(i.operands[0] == 1 for i in stage if i.op == ca.OP_INPUT)  # u alone
    assert sum(i.op == ca.OP_TANH for i in body) == 1  # tanh(y) stays; tanh(u) is hoisted
    assert size >= every.numel_out(0)  # every(u) is read by the products and the outputs
    whole = np.hstack([rows, stage_rows])
    joined = ca.Function("joined", [ca.vertcat(y, u)], [function(y, u)])
    expected = _compiled(joined, kernel_cache)(whole)
    source = numba_source({"kernel": function}, "split kernel", stage_inputs=(1,))
    module, _ = load_kernel_module(source, lambda: source, kernel_cache)
    actual = np.empty_like(expected)
    module.kernel_batch(rows, stage_rows, actual)  # the stage, then the body, row by row
    np.testing.assert_array_equal(actual, expected)
    source = numba_source(
        {"kernel": function}, "split lanes", _STAGE_LOOP, lanes=("kernel",), stage_inputs=(1,)
    )
    module, _ = load_kernel_module(source, lambda: source, kernel_cache)
    module.kernel_groups(rows, stage_rows, actual)
    np.testing.assert_array_equal(actual, expected)


def test_infinite_and_nan_constants_evaluate_like_casadi(kernel_cache: Path) -> None:
    """A constant ``inf`` or ``nan`` is translated, or refused (the caller keeps CasADi)."""
    x = ca.SX.sym("x", 1)
    saturated = ca.if_else(x > 0, x + ca.inf, -ca.inf)
    function = ca.Function("limits", [x], [ca.vertcat(saturated, x + float("nan"), x * 2.0)])
    rows = np.array([[-1.5], [0.5], [2.0]])
    try:
        evaluate = _compiled(function, kernel_cache)
    except UnsupportedOperation:
        return
    np.testing.assert_array_equal(evaluate(rows), _casadi_rows(function, rows))


def test_only_the_batched_kernels_get_a_batch_loop(kernel_cache: Path) -> None:
    x = ca.SX.sym("x", 2)
    functions = {
        "twice": ca.Function("twice", [x], [2.0 * x]),
        "square": ca.Function("square", [x], [x * x]),
    }
    source = numba_source(functions, "batched kernels", batched=("twice",))
    module, _ = load_kernel_module(source, lambda: source, kernel_cache)
    rows, out = np.array([[1.0, -2.0], [0.5, 3.0]]), np.empty((2, 2))
    module.twice_batch(rows, out)
    np.testing.assert_array_equal(out, 2.0 * rows)
    single = np.empty(2)
    module.square(rows[1], single)  # the unbatched kernel is there, without a loop
    np.testing.assert_array_equal(single, rows[1] ** 2)
    assert not hasattr(module, "square_batch")


def test_untranslatable_functions_raise_unsupported_operation() -> None:
    x = ca.SX.sym("x", 2)
    with pytest.raises(UnsupportedOperation, match="operation"):
        numba_source({"k": ca.Function("inverse_erf", [x], [ca.erfinv(0.5 * ca.tanh(x))])}, "")
    y = ca.MX.sym("y", 2)
    with pytest.raises(UnsupportedOperation, match="not an SX Function"):
        numba_source({"k": ca.Function("mx", [y], [ca.sin(y)])}, "")
    with pytest.raises(UnsupportedOperation, match="not dense"):
        numba_source({"k": ca.Function("sparse", [x], [ca.vertcat(x[0], ca.SX(1, 1))])}, "")


@pytest.fixture(scope="module")
def compiled(kernel_cache: Path) -> dict[str, BlockKernels]:
    """The kernels of the small models (compiled once per worker)."""
    return {name: block_kernels(*make(), kernel_cache) for name, (make, _) in MODELS.items()}


def _points(
    kernels: BlockKernels, weights: np.ndarray, rng: np.random.Generator, n_points: int = N_POINTS
) -> tuple[np.ndarray, ...]:
    return (
        0.6 * rng.standard_normal((n_points, kernels.n_x)),
        0.8 * rng.standard_normal((n_points, kernels.n_u)),
        rng.standard_normal((n_points, kernels.n_p)),
        np.tile(weights, (n_points, 1)),
    )


def _full(h_xx: np.ndarray, h_xu: np.ndarray, h_uu: np.ndarray) -> np.ndarray:
    """The ``(N, n_z, n_z)`` Hessian from its blocks."""
    return np.block([[h_xx, h_xu], [np.swapaxes(h_xu, 1, 2), h_uu]])


@pytest.mark.parametrize("n_substeps", [1, 2, 5])
@pytest.mark.parametrize("name", list(MODELS))
def test_kernels_equal_the_casadi_discretization(
    name: str, n_substeps: int, compiled: dict[str, BlockKernels], rng: np.random.Generator
) -> None:
    make, weights = MODELS[name]
    dynamics, running_cost = make()
    kernels = compiled[name]
    reference = discretize_rk4(
        dynamics, fixed_weights(running_cost, weights), DT, n_substeps=n_substeps
    )
    x, u, p, w = _points(kernels, weights, rng)
    h = DT / n_substeps
    costate = rng.standard_normal((N_POINTS, kernels.n_x))

    stepped, cost = kernels.step(x, u, p, w, h, n_substeps)
    assert_close(stepped, reference.step(x, u, p), 1e-12)
    assert_close(cost, reference.cost(x, u, p), 1e-12)

    f_x, f_u, total, l_x, l_u = reference.first_order(x, u, p)
    jac, cost_first, grad = kernels.first_order(x, u, p, w, h, n_substeps)
    assert_close(jac, np.concatenate([f_x, f_u], axis=2), 1e-10)
    assert_close(cost_first, total, 1e-12)
    assert_close(grad, np.concatenate([l_x, l_u], axis=1), 1e-10)

    lagrangian = kernels.hessian(x, u, p, w, h, n_substeps, costate, 1.0)
    assert_close(lagrangian, _full(*reference.lagrangian_hessians(x, u, p, costate)), 1e-10)
    dynamics_only = kernels.hessian(x, u, p, w, h, n_substeps, costate, 0.0)
    assert_close(dynamics_only, _full(*reference.weighted_hessians(x, u, p, costate)), 1e-10)
    assert_close(
        kernels.hessian(x, u, p, w, h, n_substeps, costate, 0.3),
        dynamics_only + 0.3 * _full(*reference.cost_hessians(x, u, p)),
        1e-10,
    )


def test_hessian_matches_differences_of_the_kernel_gradient(
    compiled: dict[str, BlockKernels], rng: np.random.Generator
) -> None:
    kernels, weights = compiled["pendulum"], MODELS["pendulum"][1]
    x, u, p, w = _points(kernels, weights, rng)
    costate = rng.standard_normal((N_POINTS, kernels.n_x))
    h, n_substeps, eps = DT / 3, 3, 1e-5

    def lagrangian_gradient(z: np.ndarray) -> np.ndarray:
        jac, _, grad = kernels.first_order(z[:, : kernels.n_x], z[:, kernels.n_x :], p, w, h, 3)
        return grad + np.einsum("bi,bij->bj", costate, jac)

    z = np.concatenate([x, u], axis=1)
    columns = []
    for j in range(z.shape[1]):
        step = np.zeros(z.shape[1])
        step[j] = eps
        columns.append((lagrangian_gradient(z + step) - lagrangian_gradient(z - step)) / (2 * eps))
    differences = np.stack(columns, axis=2)
    assert_close(kernels.hessian(x, u, p, w, h, n_substeps, costate), differences, 1e-7)


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_pieces_and_threads_give_the_one_piece_results_to_the_bit(
    compiled: dict[str, BlockKernels],
    rng: np.random.Generator,
    monkeypatch: pytest.MonkeyPatch,
    threads: int,
) -> None:
    kernels, weights = compiled["cart"], MODELS["cart"][1]
    x, u, p, w = _points(kernels, weights, rng, n_points=8)
    costate = rng.standard_normal((8, kernels.n_x))
    arguments = (x, u, p, w, DT / 2, 2)
    n_stages, h = 5, DT / 2
    loop = (
        rng.standard_normal((8, kernels.n_x)),
        rng.standard_normal((8, n_stages, kernels.n_x)),
        rng.standard_normal((8, n_stages, kernels.n_u)),
        0.3 * rng.standard_normal((8, n_stages, kernels.n_u, kernels.n_x)),
        rng.standard_normal((8, n_stages, kernels.n_p)),
        w,
    )

    def evaluate(threads: int) -> tuple[np.ndarray, ...]:
        return (
            *kernels.first_order(*arguments, threads=threads),
            kernels.hessian(*arguments, costate, 0.7, threads=threads),
            *kernels.closed_loop(*loop, h, 2, threads=threads),
        )

    whole = evaluate(1)
    monkeypatch.setattr(kernel_module, "CHUNK", 3)  # pieces of 3, 3 and 2 points (or more)
    for one, many in zip(whole, evaluate(threads), strict=True):
        np.testing.assert_array_equal(many, one)


def test_jacobians_elsewhere_keep_the_linearisation_s_sweeps(
    compiled: dict[str, BlockKernels], rng: np.random.Generator, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The regulator's Jacobians at other points neither evict nor change the Hessians' data."""
    kernels, weights = compiled["cart"], MODELS["cart"][1]
    x, u, p, w = _points(kernels, weights, rng)
    costate = rng.standard_normal((N_POINTS, kernels.n_x))
    arguments = (x, u, p, w, DT / 2, 2)
    kernels.first_order(*arguments)
    expected = kernels.hessian(*arguments, costate, 1.0)
    kernels.first_order(*arguments)
    kernels.first_order(x + 0.1, u, p, w, DT / 2, 2, remember=False)
    sweeps: list[int] = []
    forward = BlockKernels._forward
    monkeypatch.setattr(
        BlockKernels, "_forward", lambda self, *a: sweeps.append(1) or forward(self, *a)
    )
    assert_close(kernels.hessian(*arguments, costate, 1.0), expected, 0.0)
    assert sweeps == []  # the Hessians reused the linearisation's forward sweep


def _share_memory(sweeps: list[Any], others: list[Any]) -> bool:
    """Whether a node array of ``sweeps`` shares memory with one of ``others``."""
    return any(
        np.shares_memory(a, b)
        for sweep in sweeps
        for other in others
        for a in (sweep.points, sweep.carried)
        for b in (other.points, other.carried)
    )


@pytest.mark.parametrize("threads", [1, 2])
def test_sweeps_written_over_the_last_ones_memory_give_fresh_results(
    compiled: dict[str, BlockKernels], rng: np.random.Generator, threads: int
) -> None:
    """A linearisation elsewhere writes over the sweeps before the remembered ones: the
    remembered ones (and their Hessians) and the new ones are those of fresh kernels."""
    kernels, weights = compiled["cart"], MODELS["cart"][1]
    x, u, p, w = _points(kernels, weights, rng, n_points=9)
    costate = rng.standard_normal((9, kernels.n_x))
    points = [(x + shift, u, p, w, DT / 2, 2) for shift in (0.0, 0.1, 0.2, 0.3)]

    def evaluate(arguments: tuple) -> tuple[np.ndarray, ...]:
        first = kernels.first_order(*arguments, threads=threads)
        return (*first, kernels.hessian(*arguments, costate, 0.7, threads=threads))

    fresh = [evaluate(arguments) for arguments in points]  # each evicts the one before
    again = [evaluate(arguments) for arguments in points]  # on the evicted sweeps' memory
    for ours, theirs in zip(again, fresh, strict=True):
        for one, other in zip(ours, theirs, strict=True):
            np.testing.assert_array_equal(one, other)
    memory = kernels._thread_memory()
    assert memory.spares  # the memory was there to reuse
    kept = memory.last.get(*points[-1][:4], np.array([DT / 2, 2, kernel_module.CHUNK, threads]))
    assert kept is not None
    assert not _share_memory(memory.spares, kept.pieces)


def test_each_thread_remembers_and_writes_over_its_own_sweeps(
    compiled: dict[str, BlockKernels], rng: np.random.Generator
) -> None:
    """Kernels are shared by every model of a vehicle type: a solve in another thread must
    neither find nor write over this thread's sweeps."""
    kernels, weights = compiled["cart"], MODELS["cart"][1]
    x, u, p, w = _points(kernels, weights, rng)
    arguments = (x, u, p, w, DT / 2, 2)
    kernels.first_order(*arguments)
    mine = kernels._thread_memory()
    theirs: list[Any] = []

    def other_solve() -> None:  # linearises elsewhere twice: evicts into its spares
        kernels.first_order(x + 0.1, u, p, w, DT / 2, 2)
        kernels.first_order(x + 0.2, u, p, w, DT / 2, 2)
        theirs.append(kernels._thread_memory())

    worker = threading.Thread(target=other_solve)
    worker.start()
    worker.join()
    assert theirs[0] is not mine
    assert theirs[0].spares
    key = np.array([DT / 2, 2, kernel_module.CHUNK, 1])
    kept = mine.last.get(x, u, p, w, key)  # still this thread's linearisation
    assert kept is not None
    elsewhere = theirs[0].last.get(x + 0.2, u, p, w, key)
    assert not _share_memory(theirs[0].spares + elsewhere.pieces, kept.pieces)


def test_closed_loop_equals_a_loop_of_substeps(
    compiled: dict[str, BlockKernels], rng: np.random.Generator
) -> None:
    kernels = compiled["pendulum"]
    n_points, n_stages, n_substeps = 3, 4, 3
    h = DT / n_substeps
    x0 = 0.5 * rng.standard_normal((n_points, kernels.n_x))
    alpha = 0.5 * rng.standard_normal((n_points, n_stages, kernels.n_x))
    mu = 0.5 * rng.standard_normal((n_points, n_stages, kernels.n_u))
    gains = 0.8 * rng.standard_normal((n_points, n_stages, kernels.n_u, kernels.n_x))
    p = rng.standard_normal((n_points, n_stages, kernels.n_p))
    w = rng.uniform(0.1, 2.0, (n_points, kernels.n_w))  # different weights per point

    path, inputs, costs = kernels.closed_loop(x0, alpha, mu, gains, p, w, h, n_substeps)

    assert path.shape == (n_points, n_stages * n_substeps + 1, kernels.n_x)
    assert costs.shape == (n_points, n_stages)
    for b in range(n_points):
        state = x0[b]
        expected_path, expected_inputs = [state], []
        for k in range(n_stages):
            control = mu[b, k] + gains[b, k] @ (alpha[b, k] - state)
            expected_inputs.append(control)
            args = (control[None], p[b, k][None], w[b][None], h)
            stage_end = kernels.step(state[None], *args, n_substeps)[0][0]
            for _ in range(n_substeps):
                state = kernels.step(state[None], *args, 1)[0][0]
                expected_path.append(state)
            assert_close(state, stage_end, 1e-13)
        assert_close(path[b], np.array(expected_path), 1e-12)
        assert_close(inputs[b], np.array(expected_inputs), 1e-12)
        # a stage of the path is the step of the stage before, and its cost the step's, to
        # the bit (the line search reads the costs of the rollout instead of a step)
        stages = path[b, ::n_substeps]
        stepped, stepped_cost = kernels.step(
            stages[:-1], inputs[b], p[b], np.repeat(w[b][None], n_stages, axis=0), h, n_substeps
        )
        np.testing.assert_array_equal(stepped, stages[1:])
        np.testing.assert_array_equal(stepped_cost, costs[b])


def test_carried_pattern_is_the_closure_of_the_jacobian_pattern() -> None:
    # unicycle (x, y, θ, v) with inputs (ω, a): ẋ = v cos θ, ẏ = v sin θ, θ̇ = ω, v̇ = a;
    # nothing depends on x or y, so D's x and y columns stay the identity's at every node
    z = ca.SX.sym("z", 6)
    rate = ca.vertcat(z[3] * ca.cos(z[2]), z[3] * ca.sin(z[2]), z[4], z[5])
    pattern = kernel_module._carried_pattern(ca.jacobian(rate, z).sparsity(), 4, 2)
    expected = np.array(
        [
            [1, 0, 1, 1, 1, 1],  # x: through θ and v, so through ω and a one node later
            [0, 1, 1, 1, 1, 1],
            [0, 0, 1, 0, 1, 0],  # θ: only itself and ω
            [0, 0, 0, 1, 0, 1],
        ],
        dtype=bool,
    )
    np.testing.assert_array_equal(pattern, expected)


def test_sweeps_carry_the_pattern_s_entries_of_the_node_derivatives(
    compiled: dict[str, BlockKernels], rng: np.random.Generator
) -> None:
    """The sweeps carry ``D`` at the pattern's entries only, and the unicycle's pattern leaves
    some out, so the tests against the CasADi discretisation above (which would see a missing
    nonzero as a wrong Jacobian or Hessian) check the kernels built on it."""
    kernels, weights = compiled["unicycle"], MODELS["unicycle"][1]
    dynamics, _ = unicycle()
    z = ca.SX.sym("z", kernels.n_x + kernels.n_u)
    rate = dynamics(z[: kernels.n_x], z[kernels.n_x :], ca.SX.sym("p", kernels.n_p))
    pattern = kernel_module._carried_pattern(
        ca.jacobian(rate, z).sparsity(), kernels.n_x, kernels.n_u
    )
    # north and east columns: their identity entries only; speed: neither heading nor turn
    assert np.count_nonzero(~pattern) == 8
    np.testing.assert_array_equal(kernels.carried_entries, np.flatnonzero(pattern))
    x, u, p, w = _points(kernels, weights, rng)
    (sweep,) = kernels._sweeps(x, u, p, w, DT / 3, 3, threads=1, remember=False).pieces
    assert sweep.carried.shape == (12, 2, pattern.sum(), LANES)  # 3 substeps, 6 points
