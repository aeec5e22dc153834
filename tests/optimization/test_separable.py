"""Separable models: BlockDiscreteModel vs the CasADi discretisation of the stacked blocks.

Oracles: :func:`~auvplan.optimization.discretize_rk4` on ``stack_blocks(...)`` (one CasADi
graph of the whole stacked system) for every method and the closed-loop rollout, and
``solve_pronto`` with the stacked CasADi model for the solver.
"""

from __future__ import annotations

import dataclasses
import logging
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from auvplan.errors import InputError
from auvplan.io.vehicles import load_vehicle
from auvplan.mission.fleet import FleetLayout, FleetLimits, FleetWeights, build_fleet_functions
from auvplan.optimization import (
    BlockDiscreteModel,
    DiscreteModel,
    PathConstraint,
    ProntoOptions,
    StageBackend,
    StageBlock,
    Trajectory,
    TrajectoryProblem,
    build_model,
    discretize_rk4,
    solve_pronto,
    stack_blocks,
)
from auvplan.optimization.separable import check_tiling
from auvplan.vehicle import build_vehicle_model

from ._kernel_models import assert_close, three_blocks

DT = 0.3
N_SUBSTEPS = 2
N_STAGES = 5


@pytest.fixture(scope="module")
def models(kernel_cache: Path) -> tuple[BlockDiscreteModel, DiscreteModel]:
    """The block model of :func:`three_blocks` and the CasADi model of the stacked blocks."""
    blocks, sizes = three_blocks()
    block_model = BlockDiscreteModel.build(blocks, sizes, DT, N_SUBSTEPS, kernel_cache)
    reference = discretize_rk4(*stack_blocks(blocks, *sizes), DT, n_substeps=N_SUBSTEPS)
    return block_model, reference


def _stages(
    model: DiscreteModel | BlockDiscreteModel, rng: np.random.Generator, n_stages: int = N_STAGES
) -> tuple[np.ndarray, ...]:
    return (
        0.6 * rng.standard_normal((n_stages, model.n_x)),
        0.8 * rng.standard_normal((n_stages, model.n_u)),
        rng.standard_normal((n_stages, model.n_p)),
        rng.standard_normal((n_stages, model.n_x)),
    )


def test_blocks_sharing_a_model_share_its_kernels(
    models: tuple[BlockDiscreteModel, DiscreteModel],
) -> None:
    block_model, _ = models
    assert (block_model.n_x, block_model.n_u, block_model.n_p) == (7, 4, 2)
    assert sorted(len(group.blocks) for group in block_model.groups) == [1, 2]
    pendulums = next(group for group in block_model.groups if len(group.blocks) == 2)
    np.testing.assert_array_equal(pendulums.weights, [[1.0, 0.5], [2.0, 0.1]])


def test_every_method_equals_the_stacked_casadi_model(
    models: tuple[BlockDiscreteModel, DiscreteModel], rng: np.random.Generator
) -> None:
    block_model, reference = models
    x, u, p, costate = _stages(block_model, rng)
    assert_close(block_model.step(x, u, p), reference.step(x, u, p), 1e-12)
    assert_close(block_model.cost(x, u, p), reference.cost(x, u, p), 1e-12)
    arguments = {
        "first_order": (x, u, p),
        "jacobians": (x, u, p),
        "cost_hessians": (x, u, p),
        "lagrangian_hessians": (x, u, p, costate),
        "weighted_hessians": (x, u, p, costate),
    }
    for method, args in arguments.items():
        results = getattr(block_model, method)(*args)
        for actual, expected in zip(results, getattr(reference, method)(*args), strict=True):
            assert_close(actual, expected, 1e-10)


def _block_gains(model: BlockDiscreteModel, rng: np.random.Generator) -> np.ndarray:
    """Random gains acting on each block's own states only (as the regulator's do)."""
    gains = np.zeros((N_STAGES, model.n_u, model.n_x))
    for group in model.groups:
        for block in group.blocks:
            shape = (
                N_STAGES,
                block.inputs.stop - block.inputs.start,
                block.states.stop - block.states.start,
            )
            gains[:, block.inputs, block.states] = 0.5 * rng.standard_normal(shape)
    return gains


def _count_calls(monkeypatch: pytest.MonkeyPatch, name: str) -> list[int]:
    """A list that grows by one at every call of ``BlockDiscreteModel.<name>`` (still made)."""
    calls: list[int] = []
    method = getattr(BlockDiscreteModel, name)

    def spy(self: BlockDiscreteModel, *args: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        calls.append(1)
        return method(self, *args)

    monkeypatch.setattr(BlockDiscreteModel, name, spy)
    return calls


def test_rollout_equals_the_casadi_rollout(
    models: tuple[BlockDiscreteModel, DiscreteModel],
    rng: np.random.Generator,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    block_model, reference = models
    x0 = 0.5 * rng.standard_normal(block_model.n_x)
    alpha = 0.5 * rng.standard_normal((N_STAGES + 1, block_model.n_x))  # row N is ignored
    mu = 0.5 * rng.standard_normal((N_STAGES, block_model.n_u))
    params = rng.standard_normal((N_STAGES, block_model.n_p))
    diagonal = _block_gains(block_model, rng)
    coupling = 0.3 * rng.standard_normal(diagonal.shape)
    coupling[diagonal != 0.0] = 0.0

    coupled_calls = _count_calls(monkeypatch, "_coupled_rollout")
    results = {}
    for name, gains in {
        "block-diagonal": diagonal,
        "round-off coupling": diagonal + 1e-13 * coupling,
        "coupled": diagonal + coupling,
    }.items():
        states, inputs = block_model.rollout(x0, alpha, mu, gains, params)
        expected_states, expected_inputs = reference.rollout(x0, alpha, mu, gains, params)
        assert_close(states, expected_states, 1e-11)
        assert_close(inputs, expected_inputs, 1e-11)
        results[name] = states
    assert len(coupled_calls) == 1  # only the truly coupled gains leave the kernel loop
    # the coupling matters: the test would notice a rollout that dropped it
    assert np.max(np.abs(results["coupled"] - results["block-diagonal"])) > 1e-2


def test_the_cost_of_a_rollout_is_its_steps_cost(
    models: tuple[BlockDiscreteModel, DiscreteModel],
    rng: np.random.Generator,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The costs the closed loop summed (remembered for a line-search trial, no step taken
    again) are the step's costs of the rolled-out stages to the bit, and arguments that
    differ in one entry are evaluated again."""
    block_model, _ = models
    x0 = 0.5 * rng.standard_normal(block_model.n_x)
    alpha = 0.5 * rng.standard_normal((N_STAGES + 1, block_model.n_x))
    mu = 0.5 * rng.standard_normal((N_STAGES, block_model.n_u))
    params = rng.standard_normal((N_STAGES, block_model.n_p))
    states, inputs = block_model.rollout(x0, alpha, mu, _block_gains(block_model, rng), params)
    stepped, expected = block_model._step_and_cost(states[:-1], inputs, params)
    np.testing.assert_array_equal(stepped, states[1:])
    steps = _count_calls(monkeypatch, "_step_and_cost")
    np.testing.assert_array_equal(block_model.cost(states[:-1], inputs, params), expected)
    assert not steps
    other = inputs.copy()
    other[2, 0] += 0.1
    fresh = block_model.cost(states[:-1], other, params)
    np.testing.assert_array_equal(fresh, block_model._step_and_cost(states[:-1], other, params)[1])
    assert fresh[2] != expected[2]


def _tilings() -> dict[str, tuple[StageBlock, ...]]:
    blocks, _ = three_blocks()
    first, cart, second = blocks
    return {
        "gap": (dataclasses.replace(first, states=slice(4, 6)), cart, second),  # 6 uncovered
        "overlap": (first, cart, dataclasses.replace(second, states=slice(2, 4))),
        "missing block": (first, cart),
        "block twice": (first, cart, second, second),
    }


@pytest.mark.parametrize("case", list(_tilings()))
def test_blocks_that_do_not_tile_the_stack_are_rejected(case: str, kernel_cache: Path) -> None:
    blocks, sizes = _tilings()[case], three_blocks()[1]
    with pytest.raises(InputError, match="do not tile"):
        check_tiling(blocks, sizes)
    with pytest.raises(InputError, match="do not tile"):
        stack_blocks(blocks, *sizes)
    with pytest.raises(InputError, match="do not tile"):
        BlockDiscreteModel.build(blocks, sizes, DT, 1, kernel_cache)


def test_block_sizes_must_match_their_rows() -> None:
    blocks, _ = three_blocks()
    with pytest.raises(InputError, match="parameters do not tile"):
        check_tiling(blocks, (7, 4, 1))
    check_tiling(blocks, (7, 4, 3))  # a trailing parameter row only the constraints read
    with pytest.raises(InputError, match="do not match"):
        dataclasses.replace(blocks[0], states=slice(0, 3))
    with pytest.raises(InputError, match="do not match"):
        dataclasses.replace(blocks[0], weights=np.ones(3))


def _separable_problem(n_steps: int = 30) -> TrajectoryProblem:
    """The three blocks with their own targets, a terminal cost and a coupling constraint.

    The pendulums' targets (±0.08 rad) are 0.16 rad apart but ``|θ_A − θ_B| <= 0.1`` rad
    (plain barrier), so the constraint is active at the optimum.
    """
    blocks, (n_x, n_u, n_p) = three_blocks()
    dynamics, running_cost = stack_blocks(blocks, n_x, n_u, n_p)
    x, u, p = ca.SX.sym("x", n_x), ca.SX.sym("u", n_u), ca.SX.sym("p", n_p)
    goal = np.array([1.0, 0.0, 0.0, -0.08, 0.0, 0.08, 0.0])
    gap = ca.Function("gap", [x, u, p], [1.0 - ((x[5] - x[3]) / 0.1) ** 2])
    return TrajectoryProblem(
        dynamics,
        running_cost,
        ca.Function("m", [x], [10.0 * ca.sumsqr(x - goal)]),
        np.array([0.5, 0.3, 0.8, 0.0, 0.0, 0.0, 0.0]),
        0.1,
        n_steps,
        stage_parameters=np.tile([-0.08, 0.08], (n_steps, 1)),
        constraints=(PathConstraint(gap, "plain", 1.0, "gap"),),
        n_substeps=2,
        blocks=blocks,
    )


def test_solver_with_kernels_equals_solver_with_casadi(
    cache_root: Path,
    models: tuple[BlockDiscreteModel, DiscreteModel],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setenv("AUVPLAN_CACHE_DIR", str(cache_root))  # the kernels of ``models``
    problem = _separable_problem()
    assert isinstance(build_model(problem).discrete, BlockDiscreteModel)
    assert isinstance(
        build_model(problem, StageBackend(stage_kernels=False)).discrete, DiscreteModel
    )
    guess = Trajectory(
        np.tile(problem.initial_state, (problem.n_steps + 1, 1)),
        np.zeros((problem.n_steps, problem.n_inputs)),
    )
    kernels, casadi = (
        solve_pronto(problem, guess, options=ProntoOptions(stage_kernels=flag))
        for flag in (True, False)
    )
    assert kernels.status == casadi.status
    assert kernels.n_iter == casadi.n_iter
    assert kernels.cost == pytest.approx(casadi.cost, rel=1e-9)
    assert_close(kernels.trajectory.states, casadi.trajectory.states, 1e-6)
    assert_close(kernels.trajectory.inputs, casadi.trajectory.inputs, 1e-6)
    assert_close(kernels.regulator_gains, casadi.regulator_gains, 1e-6)
    assert kernels.status.value == "converged"
    assert 0.0 < kernels.min_slack < 0.1  # the constraint is active


def test_untranslatable_blocks_fall_back_to_casadi(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    monkeypatch.setenv("AUVPLAN_CACHE_DIR", str(tmp_path))
    x, u, p, w = ca.SX.sym("x", 1), ca.SX.sym("u", 1), ca.SX.sym("p", 0), ca.SX.sym("w", 0)
    block = StageBlock(
        ca.Function("f", [x, u, p], [ca.erfinv(0.5 * ca.tanh(x)) + u]),
        ca.Function("l", [x, u, p, w], [x**2 + u**2]),
        np.zeros(0),
        slice(0, 1),
        slice(0, 1),
        slice(0, 0),
    )
    problem = TrajectoryProblem(
        *stack_blocks([block], 1, 1, 0),
        ca.Function("m", [x], [x**2]),
        np.array([0.3]),
        0.1,
        5,
        blocks=(block,),
    )
    with caplog.at_level(logging.WARNING, logger="auvplan.optimization.model"):
        model = build_model(problem)
    assert isinstance(model.discrete, DiscreteModel)
    assert "stage kernels unavailable" in caplog.text
    states = np.full((5, 1), 0.3)
    inputs = np.full((5, 1), 0.1)
    expected = discretize_rk4(problem.dynamics, problem.running_cost, 0.1).step(
        states, inputs, np.zeros((5, 0))
    )
    np.testing.assert_array_equal(model.discrete.step(states, inputs, np.zeros((5, 0))), expected)


@pytest.fixture(scope="module")
def medusa_pair() -> tuple[BlockDiscreteModel, DiscreteModel]:
    """Two MEDUSA vehicles as fleet blocks (kernels from the shared cache, compiled once)."""
    model = build_vehicle_model(load_vehicle("medusa"), propeller_order=3)
    layout = FleetLayout(names=("blue", "green"), models=(model, model))
    functions = build_fleet_functions(
        layout,
        np.array([[100.0, 50.0, 0.3], [-40.0, 80.0, 1.2]]),
        FleetWeights(terrain=0.5, energy=1.0, terminal=1.0),
        FleetLimits(2.0, 1.0, np.zeros((0, 3)), (), ((0, 1, 500.0),)),
    )
    sizes = (layout.n_x, layout.n_u, layout.n_x)
    block_model = BlockDiscreteModel.build(functions.blocks, sizes, 0.5, 2)
    reference = discretize_rk4(functions.dynamics, functions.running_cost, 0.5, n_substeps=2)
    return block_model, reference


def test_medusa_fleet_blocks_equal_the_stacked_fleet_model(
    medusa_pair: tuple[BlockDiscreteModel, DiscreteModel], rng: np.random.Generator
) -> None:
    block_model, reference = medusa_pair
    assert len(block_model.groups) == 1  # both vehicles share one kernel set

    def states(n: int) -> np.ndarray:
        # north, east [m], psi [rad], u, v [m/s], r [rad/s], n_ps, n_sb [rev/s]
        low = np.array([-200.0, -200.0, -3.0, 0.2, -0.1, -0.2, 5.0, 5.0])
        high = np.array([200.0, 200.0, 3.0, 1.3, 0.1, 0.2, 40.0, 40.0])
        return np.concatenate([rng.uniform(low, high, (n, 8)) for _ in range(2)], axis=1)

    x, p = states(4), states(4)
    c = rng.uniform(-0.8, 0.8, (4, block_model.n_u))
    costate = rng.standard_normal((4, block_model.n_x))
    for actual, expected in zip(
        block_model.first_order(x, c, p), reference.first_order(x, c, p), strict=True
    ):
        assert_close(actual, expected, 1e-9)
    for actual, expected in zip(
        block_model.lagrangian_hessians(x, c, p, costate),
        reference.lagrangian_hessians(x, c, p, costate),
        strict=True,
    ):
        assert_close(actual, expected, 1e-9)
