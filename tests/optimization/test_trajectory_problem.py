"""Problem definition, options and the IPOPT bridge's own guarantees."""

from __future__ import annotations

import dataclasses

import casadi as ca
import numpy as np
import pytest

from auvplan.errors import InputError
from auvplan.optimization import (
    PathConstraint,
    ProntoOptions,
    Trajectory,
    TrajectoryProblem,
    build_model,
    evaluate_cost,
    solve_ipopt,
    solve_pronto,
)

from ._problems import crossing_problem, unicycle_problem, zero_guess


def test_problem_defaults_and_validation() -> None:
    problem = unicycle_problem()
    assert problem.parameters.shape == (problem.n_steps, 0)
    np.testing.assert_array_equal(problem.state_weight, np.eye(4))
    np.testing.assert_array_equal(problem.input_weight, np.eye(2))
    assert problem.time[-1] == pytest.approx(problem.n_steps * problem.dt)
    with pytest.raises(InputError, match="initial_state"):
        TrajectoryProblem(
            problem.dynamics, problem.running_cost, problem.terminal_cost, np.zeros(3), 0.1, 5
        )
    with pytest.raises(InputError, match="dt"):
        TrajectoryProblem(
            problem.dynamics, problem.running_cost, problem.terminal_cost, np.zeros(4), 0.0, 5
        )
    with pytest.raises(InputError, match="n_substeps"):
        dataclasses.replace(problem, n_substeps=0)
    with pytest.raises(InputError, match="stage_parameters"):
        TrajectoryProblem(
            problem.dynamics,
            problem.running_cost,
            problem.terminal_cost,
            np.zeros(4),
            0.1,
            5,
            stage_parameters=np.zeros((4, 1)),
        )
    with pytest.raises(InputError, match="positive definite"):
        TrajectoryProblem(
            problem.dynamics,
            problem.running_cost,
            problem.terminal_cost,
            np.zeros(4),
            0.1,
            5,
            regulator_R=np.array([1.0, -1.0]),
        )
    x, u, p = ca.SX.sym("x", 4), ca.SX.sym("u", 2), ca.SX.sym("p", 0)
    with pytest.raises(InputError, match="kind"):
        PathConstraint(ca.Function("c", [x, u, p], [x[0]]), "soft")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="scale"):
        PathConstraint(ca.Function("c", [x, u, p], [x[0]]), scale=0.0)
    with pytest.raises(InputError, match="Trajectory"):
        Trajectory(np.zeros((5, 4)), np.zeros((5, 2)))


def test_options_validation_and_levels() -> None:
    assert ProntoOptions().epsilon_levels() == pytest.approx((1.0, 1e-1, 1e-2, 1e-3, 1e-4))
    assert ProntoOptions(eps_initial=1.0, eps_final=0.05, eps_factor=0.1).epsilon_levels() == (
        pytest.approx((1.0, 0.1, 0.05))
    )
    with pytest.raises(InputError, match="alpha"):
        ProntoOptions(alpha=1.5)
    with pytest.raises(InputError, match="eps_final"):
        ProntoOptions(eps_final=2.0)


def test_guess_shape_is_checked() -> None:
    problem = unicycle_problem()
    with pytest.raises(InputError, match="guess"):
        solve_pronto(problem, Trajectory(np.zeros((5, 4)), np.zeros((4, 2))))


def test_threaded_maps_give_identical_results() -> None:
    problem = crossing_problem()
    serial = solve_pronto(problem, zero_guess(problem), options=ProntoOptions(eps_final=1e-2))
    threaded = solve_pronto(
        problem, zero_guess(problem), options=ProntoOptions(eps_final=1e-2, n_threads=2)
    )
    np.testing.assert_allclose(
        threaded.trajectory.states, serial.trajectory.states, rtol=1e-12, atol=1e-12
    )
    assert len(threaded.history) == len(serial.history)


def test_ipopt_bridge_solves_the_same_discrete_problem() -> None:
    problem = crossing_problem()
    result = solve_ipopt(problem, zero_guess(problem))
    assert result.success
    assert result.max_defect < 1e-8
    model = build_model(problem)
    parts, min_slack = evaluate_cost(model, result.trajectory, 1.0, 0.5)
    # the bridge's cost is PRONTO's objective (no barrier) at the same trajectory
    assert result.cost == pytest.approx(parts.objective, rel=1e-12)
    assert min_slack > -1e-8
    barrier = solve_ipopt(problem, result.trajectory, barrier=(1.0, 0.5), hard_constraints=False)
    assert barrier.success
    # the barrier keeps the vehicles further apart and costs more than the hard optimum
    assert barrier.cost > result.cost
    parts_b, _ = evaluate_cost(model, barrier.trajectory, 1.0, 0.5)
    assert barrier.barrier_cost == pytest.approx(parts_b.barrier, rel=1e-10)
    with pytest.raises(InputError, match="barrier"):
        solve_ipopt(problem, zero_guess(problem), barrier=(0.0, 1.0))
