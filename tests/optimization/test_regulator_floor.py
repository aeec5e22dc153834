"""The projection regulator designed at a floored (controllable) linearisation point."""

from __future__ import annotations

import dataclasses

import numpy as np

from auvplan.optimization import ProntoOptions, solve_pronto
from auvplan.optimization.model import build_model
from auvplan.optimization.projection import design_regulator, regulator_gains

from ._problems import unicycle_problem, zero_guess

SPEED_FLOOR = np.array([0.0, 0.0, 0.0, 0.5])  # the unicycle's speed is its 4th state


def _gains(floor: np.ndarray | None) -> np.ndarray:
    problem = dataclasses.replace(unicycle_problem(n_steps=20), regulator_floor=floor)
    model = build_model(problem)
    guess = zero_guess(problem)  # at rest: heading and position do not respond to the inputs
    A, B = model.discrete.jacobians(guess.states[:-1], guess.inputs, problem.parameters)
    return regulator_gains(model, guess, A, B, ProntoOptions())


def test_zero_floor_is_the_exact_design() -> None:
    np.testing.assert_array_equal(_gains(np.zeros(4)), _gains(None))


def test_floor_designs_at_the_raised_states() -> None:
    problem = dataclasses.replace(unicycle_problem(n_steps=20), regulator_floor=SPEED_FLOOR)
    model = build_model(problem)
    guess = zero_guess(problem)
    raised = guess.states[:-1].copy()
    raised[:, 3] = 0.5
    A, B = model.discrete.jacobians(raised, guess.inputs, problem.parameters)
    expected = design_regulator(A, B, problem.state_weight, problem.input_weight)
    np.testing.assert_allclose(_gains(SPEED_FLOOR), expected, rtol=1e-12, atol=1e-14)


def test_floor_makes_the_rest_state_steerable() -> None:
    # at rest an east error can hardly be corrected through the yaw rate
    assert np.all(np.abs(_gains(None)[:, 0, 1]) < 1e-3)
    assert np.all(np.abs(_gains(SPEED_FLOOR)[:, 0, 1]) > 0.5)


def test_floor_changes_the_path_not_the_optimum() -> None:
    problem = unicycle_problem()
    floored = dataclasses.replace(problem, regulator_floor=SPEED_FLOOR)
    options = ProntoOptions(tol=1e-10, rtol=1e-12)
    exact = solve_pronto(problem, zero_guess(problem), options=options)
    with_floor = solve_pronto(floored, zero_guess(floored), options=options)
    assert exact.success
    assert with_floor.success
    np.testing.assert_allclose(with_floor.cost, exact.cost, rtol=1e-8)
