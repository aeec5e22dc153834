"""Approximate log barrier, hockey stick and their composition."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvplan.errors import InputError
from auvplan.optimization.barrier import (
    barrier_expression,
    composed_barrier,
    hockey_stick,
    log_barrier,
)
from auvplan.optimization.pronto import infeasible_restart_delta


def _central(fun, z: np.ndarray, h: float = 1e-6) -> np.ndarray:
    return (fun(z + h) - fun(z - h)) / (2 * h)


@pytest.mark.parametrize("delta", [1e-3, 0.1, 0.5, 2.0])
def test_log_barrier_is_c2_at_delta(delta: float) -> None:
    below = log_barrier(np.array([delta * (1 - 1e-12)]), delta)
    above = log_barrier(np.array([delta * (1 + 1e-12)]), delta)
    for lower, upper in zip(below, above, strict=True):
        np.testing.assert_allclose(lower, upper, rtol=1e-9)
    # the values at delta are those of -log: -log δ, -1/δ, 1/δ²
    value, first, second = log_barrier(np.array([delta]), delta)
    np.testing.assert_allclose(
        [value[0], first[0], second[0]], [-np.log(delta), -1 / delta, 1 / delta**2]
    )


@pytest.mark.parametrize("is_hockey", [False, True])
def test_derivatives_match_finite_differences(is_hockey: bool) -> None:
    delta = 0.3
    s = np.concatenate([np.linspace(-2, 3, 41), [0.31, 0.29, 1e-3]])
    s = s[np.abs(s - delta) > 1e-3]  # away from the switch, where FD straddles two branches

    def value(x: np.ndarray) -> np.ndarray:
        return composed_barrier(x, delta, is_hockey=is_hockey)[0]

    def first(x: np.ndarray) -> np.ndarray:
        return composed_barrier(x, delta, is_hockey=is_hockey)[1]

    _, d1, d2 = composed_barrier(s, delta, is_hockey=is_hockey)
    np.testing.assert_allclose(d1, _central(value, s), rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(d2, _central(first, s), rtol=1e-6, atol=1e-6)


def test_barrier_finite_for_infeasible_and_convex() -> None:
    s = np.linspace(-5, 5, 201)
    value, first, second = log_barrier(s, 0.5)
    assert np.all(np.isfinite(value))
    assert np.all(first < 0)  # decreasing: grows towards (and beyond) the edge
    assert np.all(second > 0)  # convex


def test_hockey_stick_is_c2_at_zero_and_vanishes_far_away() -> None:
    left = hockey_stick(np.array([-1e-12]))
    right = hockey_stick(np.array([1e-12]))
    for lower, upper in zip(left, right, strict=True):
        np.testing.assert_allclose(lower, upper, atol=1e-11)
    value, _, _ = composed_barrier(np.array([5.0, 10.0, 40.0]), 1e-3, is_hockey=True)
    assert np.all(value >= 0.0)
    assert value[0] < 1e-3
    assert value[2] == pytest.approx(0.0, abs=1e-15)
    # the plain barrier keeps rewarding distance
    assert log_barrier(np.array([40.0]), 1e-3)[0][0] < -3.0


@settings(max_examples=60, deadline=None)
@given(
    a=st.floats(1e-6, 50.0),
    b=st.floats(1e-6, 50.0),
    delta=st.floats(1e-6, 1.0),
)
def test_barrier_grows_towards_the_edge(a: float, b: float, delta: float) -> None:
    """Property: finite inside the feasible set and larger closer to the edge."""
    near, far = min(a, b), max(a, b)
    values = log_barrier(np.array([near, far]), delta)[0]
    assert np.all(np.isfinite(values))
    assert values[0] >= values[1]
    hockey = composed_barrier(np.array([near, far]), delta, is_hockey=True)[0]
    assert np.all(np.isfinite(hockey))
    assert hockey[0] >= hockey[1]


@pytest.mark.parametrize("is_hockey", [False, True])
def test_casadi_expression_equals_numpy(is_hockey: bool) -> None:
    s = ca.SX.sym("s")
    fun = ca.Function("b", [s], [barrier_expression(s, 0.2, is_hockey=is_hockey)])
    grid = np.linspace(-3, 3, 37)
    expected = composed_barrier(grid, 0.2, is_hockey=is_hockey)[0]
    got = np.array([float(fun(v)) for v in grid])
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)


def test_rejects_non_positive_delta() -> None:
    with pytest.raises(InputError, match="delta"):
        log_barrier(np.ones(2), 0.0)


@settings(max_examples=60, deadline=None)
@given(
    delta=st.floats(1e-4, 1.0),
    violation=st.floats(0.0, 100.0),
)
def test_an_infeasible_restart_pulls_harder_at_the_boundary(delta: float, violation: float) -> None:
    """The re-solve's barrier slope at ``s = 0`` beats the old one at the violation."""
    smaller = infeasible_restart_delta(delta, -violation)
    assert 0.0 < smaller <= 0.5 * delta
    _, old_pull, _ = log_barrier(np.array([-violation]), delta)
    _, new_pull, _ = log_barrier(np.array([0.0]), smaller)
    assert abs(new_pull[0]) >= 2.0 * abs(old_pull[0]) * (1 - 1e-12)
