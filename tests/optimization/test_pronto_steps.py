"""The named PRONTO steps, each tested alone (regulator, projection, costate, LQ, Armijo)."""

from __future__ import annotations

import dataclasses
import itertools

import casadi as ca
import numpy as np
import pytest
import scipy.linalg

from auvplan.optimization import (
    DirectionType,
    LqDirection,
    PathConstraint,
    ProntoOptions,
    StageWeights,
    Trajectory,
    TrajectoryProblem,
    _kernels,
    armijo_step,
    build_model,
    compute_costate,
    converged,
    derivative_check,
    design_regulator,
    evaluate_cost,
    linearize,
    project,
    project_guess,
    second_order_weights,
    solve_lq_direction,
    solve_pronto,
)
from auvplan.optimization.lq import quadratic_form
from auvplan.optimization.model import ProntoModel
from auvplan.optimization.steps import (
    LocalModel,
    compute_direction,
    predicted_decrement,
    shift_decrement,
)

from ._problems import (
    crossing_problem,
    lq_problem,
    obstacle_problem,
    pendulum_problem,
    random_guess,
    unicycle_problem,
    zero_guess,
)


def _dense_kkt_solution(problem: TrajectoryProblem) -> tuple[np.ndarray, np.ndarray]:
    """Independent oracle: the LQ problem as one dense equality-constrained QP (numpy solve)."""
    model = build_model(problem).discrete
    n_x, n_u, n_steps = problem.n_states, problem.n_inputs, problem.n_steps
    states = ca.SX.sym("X", n_x, n_steps)  # x_1 .. x_N
    inputs = ca.SX.sym("U", n_u, n_steps)
    full = ca.horzcat(problem.initial_state, states)
    objective = problem.terminal_cost(full[:, n_steps])
    defects = []
    for k in range(n_steps):
        p_k = problem.parameters[k]
        objective += model.cost_function(full[:, k], inputs[:, k], p_k)
        defects.append(model.step_function(full[:, k], inputs[:, k], p_k) - full[:, k + 1])
    w = ca.vertcat(ca.vec(states), ca.vec(inputs))
    hess, grad = ca.hessian(objective, w)
    g = ca.vertcat(*defects)
    jac = ca.jacobian(g, w)
    numeric = ca.Function("qp", [w], [hess, grad, jac, g])
    h_val, g_val, e_val, c_val = (np.asarray(v.full()) for v in numeric(np.zeros(w.numel())))
    n_w, n_c = h_val.shape[0], e_val.shape[0]
    kkt = np.block([[h_val, e_val.T], [e_val, np.zeros((n_c, n_c))]])
    rhs = np.concatenate([-g_val.ravel(), -c_val.ravel()])
    solution = np.linalg.solve(kkt, rhs)[:n_w]
    xs = solution[: n_x * n_steps].reshape(n_steps, n_x)
    us = solution[n_x * n_steps :].reshape(n_steps, n_u)
    return np.vstack([problem.initial_state, xs]), us


def test_lq_one_newton_step_reaches_the_optimum(rng: np.random.Generator) -> None:
    problem = lq_problem()
    result = solve_pronto(problem, random_guess(problem, rng, 1.0))
    assert result.success
    assert result.history[0].step == 1.0
    assert result.history[0].direction is DirectionType.NEWTON
    assert result.n_iter == 1
    assert result.history[1].decrement < 1e-12 * result.history[0].decrement
    states, inputs = _dense_kkt_solution(problem)
    np.testing.assert_allclose(result.trajectory.states, states, atol=1e-10, rtol=0)
    np.testing.assert_allclose(result.trajectory.inputs, inputs, atol=1e-10, rtol=0)


def test_regulator_converges_to_the_infinite_horizon_lqr() -> None:
    a = np.array([[1.0, 0.1], [0.0, 1.0]])
    b = np.array([[0.005], [0.1]])
    q, r = np.diag([2.0, 0.5]), np.array([[0.3]])
    n_steps = 400
    gains = design_regulator(
        np.broadcast_to(a, (n_steps, 2, 2)).copy(), np.broadcast_to(b, (n_steps, 2, 1)).copy(), q, r
    )
    p = scipy.linalg.solve_discrete_are(a, b, q, r)
    expected = np.linalg.solve(r + b.T @ p @ b, b.T @ p @ a)
    # terminal matrix from the DARE: every stage is the stationary gain
    np.testing.assert_allclose(gains[0], expected, rtol=1e-10)
    np.testing.assert_allclose(gains[-1], expected, rtol=1e-10)
    weight_terminal = design_regulator(
        np.broadcast_to(a, (n_steps, 2, 2)).copy(),
        np.broadcast_to(b, (n_steps, 2, 1)).copy(),
        q,
        r,
        terminal="weight",
    )
    np.testing.assert_allclose(weight_terminal[0], expected, rtol=1e-8)
    assert not np.allclose(weight_terminal[-1], expected, rtol=1e-3)


def _are_residual(a, b, q, r, p):
    """Largest entry of the DARE's residual relative to ``P``."""
    gain = np.linalg.solve(r + b.T @ p @ b, b.T @ p @ a)
    return np.abs(a.T @ p @ a - p - a.T @ p @ b @ gain + q).max() / np.abs(p).max()


@pytest.mark.parametrize("seed", range(6))
def test_doubling_are_matches_qz_and_solves_the_equation(seed: int) -> None:
    """Random stabilisable systems (some unstable, some with integrators like a vehicle's
    position): the doubling's P is scipy's QZ solution and satisfies the ARE."""
    rng = np.random.default_rng(seed)
    n, m = 8, 2
    a = rng.normal(size=(n, n)) * (0.4 if seed % 2 else 0.25) + np.eye(n) * (0.6 + 0.1 * seed)
    if seed >= 4:  # positions: integrators of other states, nothing feeds back on them
        a[:2, :] = 0.0
        a[:2, :2] = np.eye(2)
        a[:2, 2:4] = 0.5 * rng.normal(size=(2, 2))
        a[2:, :2] = 0.0
    b = rng.normal(size=(n, m))
    q = np.diag(rng.uniform(0.1, 2.0, n))
    r = np.diag(rng.uniform(0.1, 1.0, m))
    p, converged_ = _kernels.discrete_are(a, b, q, r)
    assert converged_
    np.testing.assert_allclose(p, scipy.linalg.solve_discrete_are(a, b, q, r), rtol=1e-9, atol=0)
    assert _are_residual(a, b, q, r, p) < 1e-11
    np.testing.assert_array_equal(p, p.T)


def test_doubling_are_reports_an_unstabilisable_system() -> None:
    """An unstable mode no input reaches has no stabilising solution: the doubling diverges,
    says so, and the regulator falls back on ``Q_r`` for its terminal matrix."""
    a = np.diag([1.5, 0.5])
    b = np.array([[0.0], [1.0]])
    q, r = np.eye(2), np.eye(1)
    _, converged_ = _kernels.discrete_are(a, b, q, r)
    assert not converged_
    n_steps = 50
    gains = design_regulator(
        np.broadcast_to(a, (n_steps, 2, 2)).copy(), np.broadcast_to(b, (n_steps, 2, 1)).copy(), q, r
    )
    weight_terminal = design_regulator(
        np.broadcast_to(a, (n_steps, 2, 2)).copy(),
        np.broadcast_to(b, (n_steps, 2, 1)).copy(),
        q,
        r,
        terminal="weight",
    )
    np.testing.assert_array_equal(gains, weight_terminal)


@pytest.mark.parametrize("make_problem", [unicycle_problem, pendulum_problem, crossing_problem])
def test_projection_is_idempotent(make_problem, rng: np.random.Generator) -> None:
    problem = make_problem()
    model = build_model(problem)
    curve = random_guess(problem, rng, 0.3)
    projected, gains = project_guess(model, curve, ProntoOptions())
    again = project(model, projected, gains)
    np.testing.assert_allclose(again.states, projected.states, rtol=0, atol=1e-13)
    np.testing.assert_allclose(again.inputs, projected.inputs, rtol=0, atol=1e-13)
    # a projected curve is a trajectory of the discrete dynamics, from x0
    step = model.discrete.step(projected.states[:-1], projected.inputs, problem.parameters)
    np.testing.assert_allclose(projected.states[1:], step, rtol=1e-13, atol=1e-13)
    np.testing.assert_array_equal(projected.states[0], problem.initial_state)


def _three_substeps(make_problem):
    def make() -> TrajectoryProblem:
        return dataclasses.replace(make_problem(), n_substeps=3)

    return make


@pytest.mark.parametrize(
    "make_problem",
    [
        unicycle_problem,
        pendulum_problem,
        obstacle_problem,
        crossing_problem,
        _three_substeps(pendulum_problem),
        _three_substeps(obstacle_problem),
    ],
)
@pytest.mark.parametrize("use_search_direction", [True, False])
def test_derivative_check_passes_at_random_trajectories(
    make_problem, use_search_direction: bool, rng: np.random.Generator
) -> None:
    problem = make_problem()
    direction = None
    if not use_search_direction:
        direction = Trajectory(
            np.zeros((problem.n_steps + 1, problem.n_states)),
            rng.standard_normal((problem.n_steps, problem.n_inputs)),
        )
    check = derivative_check(problem, random_guess(problem, rng, 0.2), direction, epsilon=0.5)
    assert check.slope_error < 1e-6, check
    assert check.curvature_error < 1e-4, check
    if use_search_direction:
        assert check.slope < 0.0


def test_newton_direction_is_the_model_minimiser(rng: np.random.Generator) -> None:
    """Consistency of §4.1: Dh·ζ = −D²g_model(ζ, ζ) for the exact LQ minimiser."""
    problem = unicycle_problem()
    model = build_model(problem)
    optimum = solve_pronto(problem, zero_guess(problem)).trajectory
    nearby = Trajectory(
        optimum.states, optimum.inputs + 0.05 * rng.standard_normal(optimum.inputs.shape)
    )
    xi, _ = project_guess(model, nearby, ProntoOptions())
    lin = linearize(model, xi, 0.0, 1.0)
    gains = design_regulator(lin.A, lin.B, problem.state_weight, problem.input_weight)
    costate = compute_costate(lin, gains)
    weights = second_order_weights(model, xi, lin, costate)
    direction = solve_lq_direction(lin, weights)
    assert direction.direction is DirectionType.NEWTON
    # the LQ minimiser of a convex model: Dh·ζ = −ζᵀ W ζ
    assert direction.slope == pytest.approx(
        -quadratic_form(weights, direction.z, direction.v), rel=1e-10
    )
    # the closed-loop costate: λ_N = m_x and λ_k = a_k − K_kᵀ b_k + (A_k − B_k K_k)ᵀ λ_{k+1}
    np.testing.assert_allclose(costate[-1], lin.m_x)
    k = 7
    closed = lin.A[k] - lin.B[k] @ gains[k]
    np.testing.assert_allclose(
        costate[k], lin.a[k] - gains[k].T @ lin.b[k] + closed.T @ costate[k + 1], rtol=1e-12
    )


def test_costate_satisfies_stationarity_at_the_optimum() -> None:
    problem = unicycle_problem()
    result = solve_pronto(problem, zero_guess(problem), options=ProntoOptions(tol=1e-14, rtol=0.0))
    assert result.success
    model = build_model(problem)
    lin = linearize(model, result.trajectory, 0.0, 1.0)
    costate = compute_costate(lin, result.regulator_gains)
    residual = lin.b + np.einsum("kij,ki->kj", lin.B, costate[1:])
    assert np.max(np.abs(residual)) < 1e-7 * np.max(np.abs(lin.b))


def _double_well() -> TrajectoryProblem:
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p", 0)
    f = ca.Function("f", [x, u, p], [ca.vertcat(x[1], u)])
    cost = ca.Function("l", [x, u, p], [0.01 * u**2 + (x[0] ** 2 - 1) ** 2])
    m = ca.Function("m", [x], [x[1] ** 2])
    return TrajectoryProblem(f, cost, m, np.array([0.1, 0.0]), 0.1, 50)


def test_fallback_ladder_engages_and_descends() -> None:
    problem = _double_well()
    result = solve_pronto(problem, zero_guess(problem))
    kinds = [record.direction for record in result.history]
    assert kinds[0] is DirectionType.CONVEXIFIED  # the Newton model is indefinite at x ≈ 0
    assert kinds[-1] is DirectionType.NEWTON  # Newton near the (well-bottom) minimiser
    costs = [record.cost for record in result.history]
    assert all(later < earlier for earlier, later in itertools.pairwise(costs))
    assert result.success


def test_ladder_uses_clipped_weights_when_newton_fails() -> None:
    problem = _double_well()
    model = build_model(problem)
    xi = project_guess(model, zero_guess(problem), ProntoOptions())[0]
    lin = linearize(model, xi, 0.0, 1.0)
    gains = design_regulator(lin.A, lin.B, problem.state_weight, problem.input_weight)
    weights = second_order_weights(model, xi, lin, compute_costate(lin, gains))
    direction = solve_lq_direction(lin, weights)  # no quasi model: clip the Newton weights
    assert direction.direction is DirectionType.CONVEXIFIED
    assert direction.slope < 0
    n = problem.n_steps
    negative = StageWeights(-weights.Q, weights.S, -np.ones((n, 1, 1)), -np.eye(2))
    steepest = StageWeights(
        np.broadcast_to(np.eye(2), (n, 2, 2)).copy(),
        np.zeros((n, 2, 1)),
        np.ones((n, 1, 1)),
        np.eye(2),
    )
    direction = solve_lq_direction(
        lin, negative, quasi_weights=lambda: negative, steepest_weights=steepest
    )
    assert direction.direction is DirectionType.CONVEXIFIED
    assert direction.slope < 0


def test_armijo_rejects_diverging_candidates() -> None:
    """x' = x³ + u blows up for large steps: inf/NaN candidates must be rejected."""
    x, u, p = ca.SX.sym("x"), ca.SX.sym("u"), ca.SX.sym("p", 0)
    problem = TrajectoryProblem(
        ca.Function("f", [x, u, p], [x**3 + u]),
        ca.Function("l", [x, u, p], [u**2 + (x - 1) ** 2]),
        ca.Function("m", [x], [x**2]),
        np.array([0.5]),
        0.1,
        20,
    )
    model = build_model(problem)
    xi, _ = project_guess(model, zero_guess(problem), ProntoOptions())
    lin = linearize(model, xi, 0.0, 1.0)
    gains = np.zeros((20, 1, 1))  # open loop: the projection can diverge
    weights = second_order_weights(model, xi, lin, compute_costate(lin, gains))
    direction = solve_lq_direction(lin, weights)
    huge = type(direction)(
        direction.z * 1e4, direction.v * 1e4, direction.slope * 1e4, direction.direction
    )
    with np.errstate(all="ignore"):
        blown = project(model, Trajectory(xi.states + huge.z, xi.inputs + huge.v), gains)
    assert not np.all(np.isfinite(blown.states))
    result = armijo_step(
        model, xi, huge, gains, lin.cost.total, epsilon=0.0, delta=1.0, max_backtracks=60
    )
    assert result.accepted
    assert result.step < 1e-3
    assert np.all(np.isfinite(result.trajectory.states))
    assert result.cost.total < lin.cost.total
    failed = armijo_step(
        model, xi, huge, gains, lin.cost.total, epsilon=0.0, delta=1.0, max_backtracks=3
    )
    assert not failed.accepted


def test_armijo_rejects_infeasible_candidates_once_feasible() -> None:
    problem = obstacle_problem()
    model = build_model(problem)
    result = solve_pronto(problem, zero_guess(problem), options=ProntoOptions(eps_final=1e-2))
    xi = result.trajectory
    _, slack = evaluate_cost(model, xi, result.epsilon, result.delta)
    assert slack > 0
    # reference states pushed straight into the obstacle centre, tracked by the regulator
    z = np.zeros_like(xi.states)
    z[:, 0] = 2.0 - xi.states[:, 0]
    z[:, 1] = 0.15 - xi.states[:, 1]
    push = LqDirection(z, np.zeros_like(xi.inputs), 0.0, DirectionType.STEEPEST)
    lin = linearize(model, xi, result.epsilon, result.delta)
    gains = design_regulator(lin.A, lin.B, 100.0 * problem.state_weight, problem.input_weight)
    common = {"epsilon": result.epsilon, "delta": result.delta, "max_backtracks": 40}
    # with a huge reference cost the sufficient-decrease test passes for any finite candidate
    free = armijo_step(model, xi, push, gains, 1e12, require_feasible=False, **common)
    assert free.accepted
    assert free.step == 1.0
    assert free.min_slack < 0.0  # the full step enters the obstacle
    strict = armijo_step(model, xi, push, gains, 1e12, require_feasible=True, **common)
    assert strict.accepted
    assert strict.step < 1.0
    assert strict.min_slack > 0.0


def test_converged() -> None:
    assert converged(1e-7, 1.0, 1e-6, 0.0)
    assert not converged(1e-5, 1.0, 1e-6, 0.0)
    assert converged(1e-5, 1e2, 1e-6, 1e-6)  # relative bound 1e-4 above the absolute one
    assert not converged(1e-3, 1e2, 1e-6, 1e-6)
    assert not converged(1e-5, -1e-2, 1e-6, 1e-6)  # |h| scales the relative bound


def test_linearization_at_another_barrier_weight_equals_linearizing_there(
    rng: np.random.Generator,
) -> None:
    """Known answer: every barrier term is proportional to ε, the rest does not depend on it."""
    problem = obstacle_problem()
    model = build_model(problem)
    xi, _ = project_guess(model, random_guess(problem, rng), ProntoOptions())
    delta = 0.5
    moved = linearize(model, xi, 1.0, delta).at_barrier_weight(1e-3)
    direct = linearize(model, xi, 1e-3, delta)
    assert direct.cost.barrier != 0.0
    for name in ("a", "b", "m_x", "barrier_weight", "barrier_outer", "A", "B"):
        np.testing.assert_allclose(
            getattr(moved, name), getattr(direct, name), rtol=1e-12, atol=1e-14, err_msg=name
        )
    assert moved.cost.total == pytest.approx(direct.cost.total, rel=1e-12)
    assert moved.epsilon == direct.epsilon


def _turn_bound_start() -> tuple[ProntoModel, Trajectory, LocalModel, LqDirection]:
    """The unicycle with a one-sided turn-rate bound far from active, its projected zero
    guess, and the model and direction there at ε = 1."""
    x, u, p = ca.SX.sym("x", 4), ca.SX.sym("u", 2), ca.SX.sym("p", 0)
    bound = ca.Function("turn", [x, u, p], [6.0 - u[0]])
    problem = dataclasses.replace(
        unicycle_problem(), constraints=(PathConstraint(bound, "plain", 6.0, "turn rate"),)
    )
    model = build_model(problem)
    xi, _ = project_guess(model, zero_guess(problem), ProntoOptions())
    local, direction = compute_direction(model, xi, 1.0, 0.5)
    return model, xi, local, direction


def test_predicted_decrement_at_the_same_weight_is_the_directions() -> None:
    """At its own ε the prediction is the direction's decrement; at another ε it has the exact
    gradient (only the weights are the first ε's), so it is much closer to the exact decrement
    there than the first ε's decrement is (a one-sided turn-rate bound, far from active)."""
    model, xi, local, direction = _turn_bound_start()
    same, _ = predicted_decrement(local, direction, 1.0)
    assert same == pytest.approx(-direction.slope, rel=1e-12)
    predicted, cost = predicted_decrement(local, direction, 1e-4)
    exact_local, exact = compute_direction(model, xi, 1e-4, 0.5)
    assert cost == pytest.approx(exact_local.linearization.cost.total, rel=1e-12)
    assert abs(predicted + exact.slope) < 0.25 * abs(same + exact.slope)


def test_the_barrier_shift_decrement_is_quadratic_in_the_weight_change() -> None:
    """``shift_decrement`` measures ``Δg = (ε'/ε − 1) ∇b`` alone: zero at the model's own ε,
    ``(ε'/ε − 1)²`` times one fixed quadratic form elsewhere (so it is not the whole
    gradient's decrement), and with ``g + Δg`` the full prediction at ``ε'`` obeys
    ``√d(ε') ≤ √d(ε) + √shift`` (the triangle inequality of the model's norm)."""
    _, _, local, direction = _turn_bound_start()
    assert shift_decrement(local, direction, 1.0) == pytest.approx(0.0, abs=1e-14)
    small = shift_decrement(local, direction, 0.5)
    large = shift_decrement(local, direction, 1e-4)
    assert small > 0.0
    assert large == pytest.approx(small * ((1e-4 - 1.0) / (0.5 - 1.0)) ** 2, rel=1e-9)
    full, _ = predicted_decrement(local, direction, 1e-4)
    assert full**0.5 <= (-direction.slope) ** 0.5 + large**0.5 + 1e-12
    assert large != pytest.approx(full, rel=1e-3)
