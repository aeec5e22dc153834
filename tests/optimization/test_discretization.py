"""RK4 DiscreteModel: every derivative block vs central differences; map vs loop oracle."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from auvplan.errors import InputError
from auvplan.optimization import discretize_constraints, discretize_rk4, make_terminal_cost

N_STAGES = 6
H = 1e-6


def _model_functions() -> tuple[ca.Function, ca.Function, ca.Function]:
    x = ca.SX.sym("x", 3)
    u = ca.SX.sym("u", 2)
    p = ca.SX.sym("p", 2)
    f = ca.Function(
        "f",
        [x, u, p],
        [
            ca.vertcat(
                x[2] * ca.cos(x[1]) + p[0], x[0] * u[0] - ca.sin(x[2]), u[1] * x[1] ** 2 + p[1]
            )
        ],
    )
    cost = ca.Function(
        "l",
        [x, u, p],
        [ca.sumsqr(x - ca.vertcat(p, 0)) * ca.exp(0.1 * x[0]) + u[0] ** 2 * x[2] + u[1] ** 4],
    )
    c = ca.Function("c", [x, u, p], [ca.vertcat(x[0] ** 2 * x[1] - u[0], ca.sin(u[1]) * x[2] + 1)])
    return f, cost, c


@pytest.fixture
def points(rng: np.random.Generator) -> tuple[np.ndarray, ...]:
    return (
        rng.normal(size=(N_STAGES, 3)),
        rng.normal(size=(N_STAGES, 2)),
        rng.normal(size=(N_STAGES, 2)),
        rng.normal(size=(N_STAGES, 3)),
    )


def _fd_columns(fun, base: np.ndarray, size: int) -> list[np.ndarray]:
    """Central differences of ``fun`` w.r.t. each column of ``base`` (all stages at once)."""
    out = []
    for j in range(size):
        step = np.zeros(size)
        step[j] = H
        out.append((fun(base + step) - fun(base - step)) / (2 * H))
    return out


@pytest.fixture(params=[1, 3], ids=["1 substep", "3 substeps"])
def n_substeps(request: pytest.FixtureRequest) -> int:
    return int(request.param)


def test_step_matches_per_stage_loop_and_rk4_formula(
    points: tuple[np.ndarray, ...], n_substeps: int
) -> None:
    f, cost, _ = _model_functions()
    dt = 0.2
    model = discretize_rk4(f, cost, dt, n_substeps=n_substeps)
    assert model.n_substeps == n_substeps
    X, U, P, _ = points
    batched = model.step(X, U, P)
    h = dt / n_substeps
    for k in range(N_STAGES):  # loop oracle: hand-written RK4 substeps with the continuous f

        def rate(state: np.ndarray, k: int = k) -> np.ndarray:
            return np.asarray(f(state, U[k], P[k])).ravel()

        x, stage_cost = X[k], 0.0
        for _ in range(n_substeps):
            k1 = rate(x)
            k2 = rate(x + h / 2 * k1)
            k3 = rate(x + h / 2 * k2)
            k4 = rate(x + h * k3)
            q = [
                float(cost(s, U[k], P[k])) for s in (x, x + h / 2 * k1, x + h / 2 * k2, x + h * k3)
            ]
            stage_cost += h / 6 * (q[0] + 2 * q[1] + 2 * q[2] + q[3])
            x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        np.testing.assert_allclose(batched[k], x, rtol=1e-13)
        assert model.cost(X, U, P)[k] == pytest.approx(stage_cost, rel=1e-13)


def test_linear_system_step_is_fourth_order_taylor() -> None:
    a = np.array([[0.0, 1.0], [-2.0, -0.3]])
    b = np.array([[0.0], [1.0]])
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p", 0)
    model = discretize_rk4(
        ca.Function("f", [x, u, p], [a @ x + b @ u]), ca.Function("l", [x, u, p], [0]), 0.1
    )
    f_x, f_u = model.jacobians(np.zeros((1, 2)), np.zeros((1, 1)), np.zeros((1, 0)))
    m = 0.1 * a
    taylor = np.eye(2) + m + m @ m / 2 + m @ m @ m / 6 + m @ m @ m @ m / 24
    np.testing.assert_allclose(f_x[0], taylor, rtol=1e-14)
    gamma = 0.1 * (np.eye(2) + m / 2 + m @ m / 6 + m @ m @ m / 24) @ b
    np.testing.assert_allclose(f_u[0], gamma, rtol=1e-14)


def test_jacobians_and_weighted_hessians_vs_central_differences(
    points: tuple[np.ndarray, ...], n_substeps: int
) -> None:
    f, cost, _ = _model_functions()
    model = discretize_rk4(f, cost, 0.3, n_substeps=n_substeps)
    X, U, P, lam = points
    f_x, f_u = model.jacobians(X, U, P)
    fd_x = _fd_columns(lambda Z: model.step(Z, U, P), X, 3)
    fd_u = _fd_columns(lambda Z: model.step(X, Z, P), U, 2)
    np.testing.assert_allclose(f_x, np.stack(fd_x, axis=2), rtol=1e-7, atol=1e-7)
    np.testing.assert_allclose(f_u, np.stack(fd_u, axis=2), rtol=1e-7, atol=1e-7)
    h_xx, h_xu, h_uu = model.weighted_hessians(X, U, P, lam)

    def weighted_x(Xs: np.ndarray, Us: np.ndarray) -> np.ndarray:
        return np.einsum("ki,kij->kj", lam, model.jacobians(Xs, Us, P)[0])

    def weighted_u(Xs: np.ndarray, Us: np.ndarray) -> np.ndarray:
        return np.einsum("ki,kij->kj", lam, model.jacobians(Xs, Us, P)[1])

    np.testing.assert_allclose(
        h_xx, np.stack(_fd_columns(lambda Z: weighted_x(Z, U), X, 3), axis=2), rtol=1e-6, atol=1e-7
    )
    np.testing.assert_allclose(
        h_xu, np.stack(_fd_columns(lambda Z: weighted_x(X, Z), U, 2), axis=2), rtol=1e-6, atol=1e-7
    )
    np.testing.assert_allclose(
        h_uu, np.stack(_fd_columns(lambda Z: weighted_u(X, Z), U, 2), axis=2), rtol=1e-6, atol=1e-7
    )


def test_cost_derivatives_vs_central_differences(
    points: tuple[np.ndarray, ...], n_substeps: int
) -> None:
    f, cost, _ = _model_functions()
    model = discretize_rk4(f, cost, 0.3, n_substeps=n_substeps)
    X, U, P, lam = points
    l_x, l_u = model.cost_gradients(X, U, P)
    np.testing.assert_allclose(
        l_x,
        np.stack(_fd_columns(lambda Z: model.cost(Z, U, P), X, 3), axis=1),
        rtol=1e-7,
        atol=1e-7,
    )
    np.testing.assert_allclose(
        l_u,
        np.stack(_fd_columns(lambda Z: model.cost(X, Z, P), U, 2), axis=1),
        rtol=1e-7,
        atol=1e-7,
    )
    c_xx, c_xu, c_uu = model.cost_hessians(X, U, P)
    fd_xx = _fd_columns(lambda Z: model.cost_gradients(Z, U, P)[0], X, 3)
    fd_xu = _fd_columns(lambda Z: model.cost_gradients(X, Z, P)[0], U, 2)
    fd_uu = _fd_columns(lambda Z: model.cost_gradients(X, Z, P)[1], U, 2)
    np.testing.assert_allclose(c_xx, np.stack(fd_xx, axis=2), rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(c_xu, np.stack(fd_xu, axis=2), rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(c_uu, np.stack(fd_uu, axis=2), rtol=1e-6, atol=1e-7)
    # combined calls agree with the separate ones
    first = model.first_order(X, U, P)
    np.testing.assert_allclose(first[0], model.jacobians(X, U, P)[0])
    np.testing.assert_allclose(first[2], model.cost(X, U, P))
    np.testing.assert_allclose(first[3], l_x)
    lag = model.lagrangian_hessians(X, U, P, lam)
    dyn = model.weighted_hessians(X, U, P, lam)
    for total, cost_part, dyn_part in zip(lag, (c_xx, c_xu, c_uu), dyn, strict=True):
        np.testing.assert_allclose(total, cost_part + dyn_part, rtol=1e-12, atol=1e-12)


def test_constraint_and_terminal_derivatives(points: tuple[np.ndarray, ...]) -> None:
    _, _, c = _model_functions()
    cons = discretize_constraints((c,), 3, 2, 2)
    X, U, P, _ = points
    values, jacobians = cons.jacobians(X, U, P)
    np.testing.assert_allclose(values, cons.values(X, U, P))
    # row j of the Jacobian is the weighted sum with weights e_j
    rows = [jacobians.weighted_sum(np.tile(e, (N_STAGES, 1))) for e in np.eye(2)]
    gradients = np.stack(rows, axis=1)  # (N, n_c, n_x + n_u)
    np.testing.assert_allclose(
        gradients[:, :, :3],
        np.stack(_fd_columns(lambda Z: cons.values(Z, U, P), X, 3), axis=2),
        rtol=1e-7,
        atol=1e-8,
    )
    np.testing.assert_allclose(
        gradients[:, :, 3:],
        np.stack(_fd_columns(lambda Z: cons.values(X, Z, P), U, 2), axis=2),
        rtol=1e-7,
        atol=1e-8,
    )
    w = np.linspace(-1, 2, N_STAGES * 2).reshape(N_STAGES, 2)
    h_xx, h_xu, h_uu = (
        np.zeros((N_STAGES, 3, 3)),
        np.zeros((N_STAGES, 3, 2)),
        np.zeros((N_STAGES, 2, 2)),
    )
    cons.add_weighted_hessians(X, U, P, w, (h_xx, h_xu, h_uu))
    fd_xx = _fd_columns(lambda Z: cons.jacobians(Z, U, P)[1].weighted_sum(w)[:, :3], X, 3)
    fd_xu = _fd_columns(lambda Z: cons.jacobians(X, Z, P)[1].weighted_sum(w)[:, :3], U, 2)
    fd_uu = _fd_columns(lambda Z: cons.jacobians(X, Z, P)[1].weighted_sum(w)[:, 3:], U, 2)
    np.testing.assert_allclose(h_xx, np.stack(fd_xx, axis=2), rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(h_xu, np.stack(fd_xu, axis=2), rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(h_uu, np.stack(fd_uu, axis=2), rtol=1e-6, atol=1e-7)
    # the Gauss-Newton part Σ_j w_j ∇c_j ∇c_jᵀ from the nonzeros equals the dense outer products
    outer = (np.zeros((N_STAGES, 3, 3)), np.zeros((N_STAGES, 3, 2)), np.zeros((N_STAGES, 2, 2)))
    jacobians.add_outer_products(w, outer)
    dense = np.einsum("kj,kja,kjb->kab", w, gradients, gradients)
    for block, expected in zip(
        outer, (dense[:, :3, :3], dense[:, :3, 3:], dense[:, 3:, 3:]), strict=True
    ):
        np.testing.assert_allclose(block, expected, rtol=1e-12, atol=1e-12)
    x = ca.SX.sym("x", 3)
    terminal = make_terminal_cost(ca.Function("m", [x], [ca.exp(x[0]) * x[1] + x[2] ** 3]), 3)
    point = X[0]
    value, grad, hess = terminal.evaluate(point)
    assert value == pytest.approx(terminal.value(point))
    fd = np.array(
        [(terminal.value(point + e) - terminal.value(point - e)) / (2 * H) for e in np.eye(3) * H]
    )
    np.testing.assert_allclose(grad, fd, rtol=1e-7)
    fd2 = np.array(
        [
            (terminal.evaluate(point + e)[1] - terminal.evaluate(point - e)[1]) / (2 * H)
            for e in np.eye(3) * H
        ]
    )
    np.testing.assert_allclose(hess, fd2, rtol=1e-6, atol=1e-8)


def test_rollout_is_closed_loop_simulation(
    points: tuple[np.ndarray, ...], rng: np.random.Generator, n_substeps: int
) -> None:
    f, cost, _ = _model_functions()
    model = discretize_rk4(f, cost, 0.1, n_substeps=n_substeps)
    X, U, P, _ = points
    gains = 0.2 * rng.normal(size=(N_STAGES, 2, 3))
    states, inputs = model.rollout(X[0], X, U, gains, P)
    x = X[0]
    for k in range(N_STAGES):
        u = U[k] + gains[k] @ (X[k] - x)
        np.testing.assert_allclose(inputs[k], u, rtol=1e-12)
        x = model.step(x[None], u[None], P[k : k + 1])[0]
        np.testing.assert_allclose(states[k + 1], x, rtol=1e-12)


def test_mx_models_fall_back_and_agree(points: tuple[np.ndarray, ...], n_substeps: int) -> None:
    """An MX model that cannot be expanded to SX (uses a lookup table) still works."""
    table = ca.interpolant(
        "table", "linear", [np.linspace(-10, 10, 5)], np.linspace(-10, 10, 5) ** 1
    )
    x, u, p = ca.MX.sym("x", 3), ca.MX.sym("u", 2), ca.MX.sym("p", 2)
    f = ca.Function("f", [x, u, p], [ca.vertcat(table(x[0]) * 0 + u[0], x[2], u[1] + p[0])])
    cost = ca.Function("l", [x, u, p], [ca.sumsqr(u)])
    model = discretize_rk4(f, cost, 0.1, n_substeps=n_substeps)
    X, U, P, _ = points
    expected = X + 0.1 * np.stack(
        [U[:, 0], X[:, 2] + 0.05 * (U[:, 1] + P[:, 0]), U[:, 1] + P[:, 0]], 1
    )
    np.testing.assert_allclose(model.step(X, U, P), expected, rtol=1e-12)


def test_rejects_bad_inputs() -> None:
    f, cost, _ = _model_functions()
    with pytest.raises(InputError, match="dt"):
        discretize_rk4(f, cost, -1.0)
    x = ca.SX.sym("x", 3)
    with pytest.raises(InputError, match="inputs"):
        discretize_rk4(ca.Function("g", [x], [x]), cost, 0.1)
    with pytest.raises(InputError, match="n_substeps"):
        discretize_rk4(f, cost, 0.1, n_substeps=0)
    model = discretize_rk4(f, cost, 0.1)
    with pytest.raises(InputError, match="U"):
        model.step(np.zeros((3, 3)), np.zeros((2, 2)), np.zeros((3, 2)))


@pytest.mark.parametrize("n_substeps", [1, 2])
def test_compiled_functions_match_the_virtual_machine(
    points: tuple[np.ndarray, ...], tmp_path, rng: np.random.Generator, n_substeps: int
) -> None:
    f, cost, _ = _model_functions()
    vm = discretize_rk4(f, cost, 0.2, n_substeps=n_substeps)
    compiled = discretize_rk4(
        f, cost, 0.2, n_substeps=n_substeps, compile_c=True, cache_dir=tmp_path
    )
    libraries = sorted(tmp_path.glob("*.so"))
    if not libraries:
        pytest.skip("no working C compiler")
    assert "external" in compiled.step_function.class_name().lower() or compiled.step_function.is_a(
        "External"
    )
    X, U, P, lam = points
    np.testing.assert_allclose(compiled.step(X, U, P), vm.step(X, U, P), rtol=1e-13)
    for got, expected in zip(compiled.first_order(X, U, P), vm.first_order(X, U, P), strict=True):
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-13)
    for got, expected in zip(
        compiled.lagrangian_hessians(X, U, P, lam),
        vm.lagrangian_hessians(X, U, P, lam),
        strict=True,
    ):
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)
    gains = 0.1 * rng.normal(size=(N_STAGES, 2, 3))
    for got, expected in zip(
        compiled.rollout(X[0], X, U, gains, P), vm.rollout(X[0], X, U, gains, P), strict=True
    ):
        np.testing.assert_allclose(got, expected, rtol=1e-12)
    # a second model with the same expressions reuses the cached library
    again = discretize_rk4(f, cost, 0.2, n_substeps=n_substeps, compile_c=True, cache_dir=tmp_path)
    assert sorted(tmp_path.glob("*.so")) == libraries
    np.testing.assert_allclose(again.step(X, U, P), vm.step(X, U, P), rtol=1e-13)
