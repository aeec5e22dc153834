"""solve_pronto against CasADi+IPOPT and CasADi+FATROP on the identical discretised problems."""

from __future__ import annotations

import dataclasses
import itertools
import shutil
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from auvplan.errors import InputError, SolverError
from auvplan.optimization import (
    PathConstraint,
    ProntoIteration,
    ProntoOptions,
    ProntoStatus,
    TrajectoryProblem,
    build_model,
    converged,
    project_guess,
    pronto,
    solve_fatrop,
    solve_ipopt,
    solve_pronto,
)
from auvplan.optimization.reference import _objective_scale

from ._problems import (
    crossing_problem,
    obstacle_problem,
    pendulum_problem,
    unicycle_problem,
    zero_guess,
)


def _quadratic_tail(
    history: tuple[ProntoIteration, ...],
    n_tail: int = 2,
    constant: float = 10.0,
    epsilon: float | None = None,
) -> None:
    """The last ``n_tail`` decrements of a barrier level satisfy ``d_{k+1} ≤ C d_k²``.

    For a log barrier with weight ``w = ε dt`` the objective divided by ``w`` is the
    self-concordant one, so the constant of quadratic convergence scales as ``1 / w``.
    """
    epsilon = history[-1].epsilon if epsilon is None else epsilon
    final = [h for h in history if h.epsilon == epsilon]
    decrements = [h.decrement for h in final]
    assert len(decrements) >= n_tail + 1, decrements
    for earlier, later in zip(decrements[-n_tail - 1 : -1], decrements[-n_tail:], strict=True):
        assert later <= constant * earlier**2 or later < 1e-13, decrements


def _constraint_slacks(
    problem: TrajectoryProblem, states: np.ndarray, inputs: np.ndarray
) -> np.ndarray:
    model = build_model(problem)
    assert model.constraints is not None
    return model.constraints.values(states[:-1], inputs, problem.parameters) / model.slack_scales


@pytest.mark.parametrize("n_substeps", [1, 2])
@pytest.mark.parametrize("make_problem", [unicycle_problem, pendulum_problem])
def test_unconstrained_cost_equals_ipopt(make_problem, n_substeps: int) -> None:
    problem = dataclasses.replace(make_problem(), n_substeps=n_substeps)
    guess = zero_guess(problem)
    result = solve_pronto(problem, guess, options=ProntoOptions(tol=1e-10, rtol=1e-12))
    assert result.status is ProntoStatus.CONVERGED, result.message
    assert result.barrier_cost == 0.0
    reference = solve_ipopt(problem, result.history and guess)
    assert reference.success
    assert result.cost == pytest.approx(reference.cost, rel=1e-6)
    np.testing.assert_allclose(result.trajectory.states, reference.trajectory.states, atol=1e-4)
    _quadratic_tail(result.history, constant=100.0)


@pytest.mark.parametrize("make_problem", [obstacle_problem, crossing_problem])
def test_constrained_cost_equals_ipopt_with_barrier_and_hard_constraints(make_problem) -> None:
    problem = make_problem()
    guess = zero_guess(problem)
    result = solve_pronto(problem, guess)
    assert result.status is ProntoStatus.CONVERGED, result.message
    assert result.epsilon == pytest.approx(ProntoOptions().eps_final)
    slacks = _constraint_slacks(problem, result.trajectory.states, result.trajectory.inputs)
    assert np.min(slacks) > 0.0  # strictly feasible at the end
    assert result.min_slack == pytest.approx(np.min(slacks))
    # same local minimum: start IPOPT at the PRONTO solution
    barrier = solve_ipopt(problem, result.trajectory, barrier=(result.epsilon, result.delta))
    assert barrier.success
    assert result.objective == pytest.approx(barrier.objective, rel=1e-4)
    hard = solve_ipopt(problem, result.trajectory)
    assert hard.success
    assert (
        np.min(_constraint_slacks(problem, hard.trajectory.states, hard.trajectory.inputs)) > -1e-8
    )
    # the barrier optimum is feasible, so it cannot beat the constrained optimum; at ε = 1e-4 it
    # is close to it
    assert result.cost >= hard.cost - 1e-8
    assert result.cost == pytest.approx(hard.cost, rel=2e-3)
    _quadratic_tail(result.history, n_tail=2, epsilon=1.0)
    _quadratic_tail(result.history, n_tail=1, constant=10.0 / (result.epsilon * problem.dt))
    levels = sorted({h.epsilon for h in result.history}, reverse=True)
    assert levels == pytest.approx(list(ProntoOptions().epsilon_levels()))


def test_infeasible_initial_trajectory_is_allowed() -> None:
    """The zero guess of the crossing drives both vehicles through each other."""
    problem = crossing_problem()
    model = build_model(problem)
    guess = zero_guess(problem)
    desired = problem.parameters
    guess_states = np.vstack([problem.initial_state, desired])
    from auvplan.optimization import Trajectory

    straight = Trajectory(guess_states, np.gradient(guess_states, problem.dt, axis=0)[:-1])
    assert model.constraints is not None
    initial_slack = np.min(
        model.constraints.values(straight.states[:-1], straight.inputs, problem.parameters)
    )
    assert initial_slack < 0.0
    result = solve_pronto(problem, straight)
    assert result.success, result.message
    assert result.min_slack > 0.0
    assert result.history[0].min_slack < 0.0
    assert guess.states.shape == result.trajectory.states.shape


def test_callback_receives_records_and_can_stop() -> None:
    problem = unicycle_problem()
    seen: list[ProntoIteration] = []

    def callback(record: ProntoIteration) -> None:
        seen.append(record)
        if len(seen) == 2:
            raise StopIteration

    result = solve_pronto(problem, zero_guess(problem), callback=callback)
    assert result.status is ProntoStatus.MAX_ITER
    assert not result.success
    assert len(seen) == 2
    assert seen == list(result.history)


def test_max_iter_status() -> None:
    problem = pendulum_problem()
    result = solve_pronto(problem, zero_guess(problem), options=ProntoOptions(max_iter=2))
    assert result.status is ProntoStatus.MAX_ITER
    assert len(result.history) == 2
    assert result.history[1].cost < result.history[0].cost


@pytest.mark.parametrize("make_problem", [unicycle_problem, crossing_problem])
def test_a_projected_guess_is_solved_as_it_is_with_the_same_iterates(make_problem) -> None:
    """From ``P(guess)`` with ``projected=True``: the solve from the guess, to the bit."""
    problem = make_problem()
    guess, options = zero_guess(problem), ProntoOptions()
    projected = project_guess(build_model(problem), guess, options)[0]
    expected = solve_pronto(problem, guess, options=options)
    result = solve_pronto(problem, projected, options=options, projected=True)
    assert result.status is expected.status is ProntoStatus.CONVERGED
    assert [r.cost for r in result.history] == [r.cost for r in expected.history]
    np.testing.assert_array_equal(result.trajectory.states, expected.trajectory.states)
    np.testing.assert_array_equal(result.regulator_gains, expected.regulator_gains)


def test_a_projected_guess_without_a_direction_returns_its_regulator(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """No direction computed (the ladder failed at once): the regulator along the guess."""
    problem = unicycle_problem()
    options = ProntoOptions()
    model = build_model(problem)
    projected = project_guess(model, zero_guess(problem), options)[0]

    def fail(*args: object, **kwargs: object) -> None:
        raise SolverError("no descent direction")

    monkeypatch.setattr(pronto, "compute_direction", fail)
    result = solve_pronto(problem, projected, options=options, projected=True)
    assert result.status is ProntoStatus.LINE_SEARCH_FAILED
    assert result.history == ()
    expected = pronto.first_order_model(model, projected, result.epsilon, result.delta).gains
    np.testing.assert_array_equal(result.regulator_gains, expected)
    assert np.any(result.regulator_gains != 0.0)


def test_a_guess_that_is_not_a_trajectory_is_refused_as_projected() -> None:
    problem = unicycle_problem()
    projected = project_guess(build_model(problem), zero_guess(problem), ProntoOptions())[0]
    off = dataclasses.replace(projected, states=projected.states.copy())
    off.states[20, 1] += 1e-3
    with pytest.raises(InputError, match=r"step 19 is off by 0\.001 in state 1"):
        solve_pronto(problem, off, projected=True)
    moved = dataclasses.replace(projected, states=projected.states + 0.5)
    with pytest.raises(InputError, match="its start differs from x0"):
        solve_pronto(problem, moved, projected=True)


@pytest.mark.parametrize("make_problem", [unicycle_problem, crossing_problem])
def test_fatrop_reaches_the_optimum_of_pronto_and_ipopt(make_problem) -> None:
    """FATROP on the stage-ordered NLP (its structure detected) finds the hard-constrained
    optimum IPOPT finds, from the same start; PRONTO's barrier optimum is within 0.2 %."""
    problem = make_problem()
    result = solve_pronto(problem, zero_guess(problem))
    assert result.status is ProntoStatus.CONVERGED, result.message
    fatrop = solve_fatrop(problem, result.trajectory)
    ipopt = solve_ipopt(problem, result.trajectory)
    assert fatrop.success, fatrop.message
    assert fatrop.max_defect < 1e-7
    assert fatrop.cost == pytest.approx(ipopt.cost, rel=1e-6)
    assert result.cost == pytest.approx(fatrop.cost, rel=2e-3)
    if problem.constraints:
        slacks = _constraint_slacks(problem, fatrop.trajectory.states, fatrop.trajectory.inputs)
        assert np.min(slacks) > -1e-7


def test_repeated_reference_solves_are_the_same_solve() -> None:
    """``repeats`` solves the NLP again from the same start: the same iterations and result
    (a benchmark then reports the fastest solve); fewer than one is refused."""
    problem = unicycle_problem()
    start = solve_pronto(problem, zero_guess(problem)).trajectory
    once, thrice = (solve_fatrop(problem, start, repeats=r) for r in (1, 3))
    assert thrice.n_iter == once.n_iter
    np.testing.assert_array_equal(thrice.trajectory.states, once.trajectory.states)
    assert thrice.cost == once.cost
    with pytest.raises(InputError, match="repeats"):
        solve_ipopt(problem, start, repeats=0)


@pytest.mark.skipif(shutil.which("gcc") is None and shutil.which("cc") is None, reason="no C")
@pytest.mark.parametrize("make_problem", [crossing_problem, obstacle_problem])
@pytest.mark.parametrize("solve", [solve_fatrop, solve_ipopt])
def test_compiled_solvers_reach_the_optimum_of_ipopt(
    make_problem, solve, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """FATROP and IPOPT with the stage Function and its derivatives compiled to C (one
    library, cached by content) find the hard-constrained optimum of IPOPT on CasADi's
    virtual machine from the same start; a second solve loads the cached library and
    returns the same trajectory."""
    monkeypatch.setenv("AUVPLAN_CACHE_DIR", str(tmp_path))
    problem = make_problem()
    start = solve_pronto(problem, zero_guess(problem)).trajectory
    compiled = solve(problem, start, compiled=True)
    libraries = list((tmp_path / "casadi").glob("auvplan_*.so"))
    assert len(libraries) == 1  # compiled to C, not left on the virtual machine
    ipopt = solve_ipopt(problem, start)
    assert compiled.success, compiled.message
    assert compiled.max_defect < 1e-7
    assert compiled.cost == pytest.approx(ipopt.cost, rel=1e-6)
    np.testing.assert_allclose(compiled.trajectory.inputs, ipopt.trajectory.inputs, atol=1e-4)
    slacks = _constraint_slacks(problem, compiled.trajectory.states, compiled.trajectory.inputs)
    assert np.min(slacks) > -1e-7
    again = solve(problem, start, compiled=True)
    assert list((tmp_path / "casadi").glob("auvplan_*.so")) == libraries
    np.testing.assert_array_equal(again.trajectory.states, compiled.trajectory.states)


def test_fatrop_objective_scale_is_ipopts_gradient_rule() -> None:
    """``σ_f = min(1, 100 / ‖∇f(w_0)‖_∞)``: a gradient of 2000 is scaled by 0.05, one
    within 100 is left alone."""
    w = ca.MX.sym("w", 2)
    steep = 1000.0 * w[0] ** 2 + w[1]  # ∇f(1, 0) = (2000, 1)
    assert _objective_scale(steep, w, np.array([1.0, 0.0])) == pytest.approx(0.05)
    assert _objective_scale(w[0] ** 2, w, np.array([3.0, 0.0])) == 1.0


def _far_bound_problem() -> TrajectoryProblem:
    """The unicycle with a turn-rate bound far from active (it moves the optimum < 1e-4)."""
    x, u, p = ca.SX.sym("x", 4), ca.SX.sym("u", 2), ca.SX.sym("p", 0)
    bound = ca.Function("turn", [x, u, p], [40.0 - u[0]])
    return dataclasses.replace(
        unicycle_problem(), constraints=(PathConstraint(bound, "plain", 40.0, "turn rate"),)
    )


def test_levels_the_barrier_does_not_move_are_skipped(monkeypatch: pytest.MonkeyPatch) -> None:
    """A bound far from active, which moves the optimum by less than the tolerance: after the
    first level the solve goes to the last ε (visiting the levels between would take no
    step) and ends where the full continuation ends; a tighter tolerance visits them all.
    (Probes off: they would end the solve at the first level, see the next test.)"""
    problem = _far_bound_problem()
    options = ProntoOptions(tol=1e-4, rtol=0.0)
    monkeypatch.setattr(pronto, "_worth_probing", lambda *_: False)  # never probe
    skipped = solve_pronto(problem, zero_guess(problem), options=options)
    monkeypatch.setattr(pronto, "SKIP_MARGIN", 1e-300)  # never predicted converged
    full = solve_pronto(problem, zero_guess(problem), options=options)
    assert skipped.status is full.status is ProntoStatus.CONVERGED
    levels = ProntoOptions().epsilon_levels()
    assert sorted({h.epsilon for h in full.history}) == sorted(levels)
    assert sorted({h.epsilon for h in skipped.history}) == [levels[-1], levels[0]]
    assert len(skipped.history) == len(full.history) - (len(levels) - 2)
    assert skipped.cost == pytest.approx(full.cost, rel=1e-12)
    np.testing.assert_array_equal(skipped.trajectory.states, full.trajectory.states)
    monkeypatch.undo()
    tight = solve_pronto(problem, zero_guess(problem), options=ProntoOptions(tol=1e-6))
    assert sorted({h.epsilon for h in tight.history}) == sorted(levels)


def test_a_probe_at_the_last_level_replaces_the_level_ends(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """After two full Newton steps at the first level whose decrements predict the last
    level's test to pass at the new point, that point is tested at the last ε first: the
    solve ends there, at the trajectory the skipping continuation ends at (to the bit),
    without the first level's own test and the prediction."""
    problem = _far_bound_problem()
    levels = ProntoOptions().epsilon_levels()
    options = ProntoOptions(tol=1e-4, rtol=0.0)
    probed = solve_pronto(problem, zero_guess(problem), options=options)
    monkeypatch.setattr(pronto, "_worth_probing", lambda *_: False)
    plain = solve_pronto(problem, zero_guess(problem), options=options)
    assert probed.status is plain.status is ProntoStatus.CONVERGED
    epsilons = [h.epsilon for h in probed.history]
    assert epsilons == [levels[0]] * (len(epsilons) - 1) + [levels[-1]]
    assert len(probed.history) == len(plain.history) - 1
    np.testing.assert_array_equal(probed.trajectory.states, plain.trajectory.states)


def test_a_failed_probe_leaves_the_iterates_alone(monkeypatch: pytest.MonkeyPatch) -> None:
    """With a tolerance the last level's decrement at the first level's end (1.5e-5) does not
    meet, the prediction makes no probe; a probe forced there fails, and the solve goes
    on with the iterates of a solve without probes, its record between them, and makes no
    further probe."""
    problem = _far_bound_problem()
    options = ProntoOptions(tol=1.2e-5, rtol=0.0)
    predicted = solve_pronto(problem, zero_guess(problem), options=options)
    monkeypatch.setattr(pronto, "_worth_probing", lambda *_: True)
    forced = solve_pronto(problem, zero_guess(problem), options=options)
    monkeypatch.setattr(pronto, "_worth_probing", lambda *_: False)
    plain = solve_pronto(problem, zero_guess(problem), options=options)
    assert predicted.status is forced.status is plain.status is ProntoStatus.CONVERGED
    assert [h.cost for h in predicted.history] == [h.cost for h in plain.history]
    history = forced.history
    probes = [  # failed probes: records at the last ε followed by a larger ε
        i for i in range(len(history) - 1) if history[i].epsilon < history[i + 1].epsilon
    ]
    assert len(probes) == 1
    assert history[probes[0]].decrement >= options.tol
    kept = [h for i, h in enumerate(history) if i not in probes]
    assert [h.cost for h in kept] == [h.cost for h in plain.history]
    np.testing.assert_array_equal(forced.trajectory.states, plain.trajectory.states)


def test_a_level_ends_when_the_next_levels_shift_outweighs_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Two vehicles crossing with a separation barrier that moves the optimum at every level:
    some levels end with a decrement above their own tolerance, a tenth of the next level's
    barrier shift; the solve takes fewer directions than with every level solved to its
    tolerance and ends at the same optimum (within the stopping test's bound)."""
    problem = crossing_problem()
    options = ProntoOptions()
    early = solve_pronto(problem, zero_guess(problem), options=options)
    monkeypatch.setattr(pronto, "_outweighed", lambda *_: False)
    full = solve_pronto(problem, zero_guess(problem), options=options)
    assert early.status is full.status is ProntoStatus.CONVERGED
    assert len(early.history) < len(full.history)
    history = early.history
    level_ends = [h for h, after in itertools.pairwise(history) if after.epsilon < h.epsilon]
    assert any(
        not converged(h.decrement, h.cost, options.inner_tol, options.inner_rtol)
        for h in level_ends
    )
    bound = max(options.tol, options.rtol * abs(full.cost))
    assert abs(early.cost - full.cost) < bound
