"""Model building and the explicit model cache; named choices of the options."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from auvplan.errors import InputError
from auvplan.optimization import (
    BarrierKind,
    FallbackModel,
    ModelCache,
    PathConstraint,
    ProntoOptions,
    StageBackend,
    TerminalRegulator,
    build_model,
    solve_pronto,
)

from ._problems import crossing_problem, unicycle_problem, zero_guess


def test_cache_returns_the_same_model_per_problem_and_options() -> None:
    cache = ModelCache(max_entries=2)
    problem = unicycle_problem()
    model = cache.get(problem)
    assert cache.get(problem) is model
    assert cache.get(problem, StageBackend(n_threads=2)) is not model
    # an equal but distinct problem object gets its own model (identity, never id reuse)
    twin = dataclasses.replace(problem)
    assert cache.get(twin) is not model
    # the oldest entry was evicted (max_entries = 2)
    assert cache.get(problem) is not model


def test_cached_model_evaluates_like_a_fresh_one() -> None:
    problem = unicycle_problem()
    cache = ModelCache()
    guess = zero_guess(problem)
    options = ProntoOptions()
    first = solve_pronto(problem, guess, options=options, cache=cache)
    again = solve_pronto(problem, guess, options=options, cache=cache)
    fresh = solve_pronto(problem, guess, options=options)
    np.testing.assert_array_equal(first.trajectory.states, again.trajectory.states)
    np.testing.assert_array_equal(first.trajectory.states, fresh.trajectory.states)
    fresh_model = build_model(problem)
    np.testing.assert_array_equal(
        fresh_model.discrete.cost(guess.states[:-1], guess.inputs, problem.parameters),
        cache.get(problem).discrete.cost(guess.states[:-1], guess.inputs, problem.parameters),
    )


def test_named_choices_accept_strings_and_reject_unknown_values() -> None:
    options = ProntoOptions(terminal_regulator="weight", fallback_model="cost")
    assert options.terminal_regulator is TerminalRegulator.WEIGHT
    assert options.fallback_model is FallbackModel.COST
    with pytest.raises(InputError, match=r"terminal_regulator.*'dare'"):
        ProntoOptions(terminal_regulator="riccati")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="fallback_model"):
        ProntoOptions(fallback_model="bfgs")  # type: ignore[arg-type]
    constraint = crossing_problem().constraints[0]
    assert constraint.kind is BarrierKind.HOCKEY
    plain = PathConstraint(constraint.function, kind="plain")
    assert plain.kind is BarrierKind.PLAIN
    assert plain.kind == "plain"


def test_a_solve_builds_only_the_functions_it_evaluates() -> None:
    """Stage Functions are built on first use (building costs seconds for vehicle fleets)."""
    problem = unicycle_problem()
    cache = ModelCache()
    solve_pronto(problem, zero_guess(problem), cache=cache)
    built = set(vars(cache.get(problem).discrete.functions))
    assert {"first_order", "lagrangian_hessian", "closed_loop_step"} <= built
    assert not {"dyn_hessian", "cost_hessian", "cost_gradient"} & built


def test_a_rebound_problem_shares_its_model_and_solves_like_a_fresh_one() -> None:
    problem = unicycle_problem()
    cache = ModelCache(max_entries=2)
    model = cache.get(problem)
    start = problem.initial_state + 0.1
    rebound = [
        cache.rebind(problem, initial_state=start, stage_parameters=problem.parameters.copy())
        for _ in range(3)
    ]
    assert cache.get(rebound[-1]).discrete is model.discrete
    assert cache.get(rebound[-1]).problem is rebound[-1]
    assert cache.get(problem) is model  # kept: the least recently used entries go first
    fresh = dataclasses.replace(problem, initial_state=start)
    np.testing.assert_array_equal(
        solve_pronto(rebound[-1], zero_guess(problem), cache=cache).trajectory.states,
        solve_pronto(fresh, zero_guess(problem)).trajectory.states,
    )
