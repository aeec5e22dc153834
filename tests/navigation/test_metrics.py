"""Run metrics: NEES against numpy's inverse, MB-System's convergence rule, divergence windows."""

from __future__ import annotations

import numpy as np
import pytest

from auvplan.navigation import convergence_time, has_diverged, nees, rmse


def test_nees_matches_the_explicit_inverse(rng: np.random.Generator) -> None:
    factors = rng.normal(size=(50, 2, 2))
    covariance = factors @ factors.transpose(0, 2, 1) + 0.1 * np.eye(2)
    errors = rng.normal(size=(50, 2))
    expected = np.einsum("ka,kab,kb->k", errors, np.linalg.inv(covariance), errors)
    np.testing.assert_allclose(nees(errors, covariance), expected, rtol=1e-10)


def test_nees_of_a_degenerate_covariance() -> None:
    covariance = np.array([[[1.0, 0.0], [0.0, 0.0]]] * 2)
    values = nees(np.array([[1.0, 0.0], [1.0, 1.0]]), covariance)
    assert values[1] == np.inf  # error along a direction the filter is certain about
    assert values[0] >= 0.0


def test_convergence_needs_the_full_run_of_updates() -> None:
    time = 3.0 * np.arange(600)
    sigma = np.full(600, 9.0)
    sigma[50:240] = 4.0  # 190 updates: not enough
    sigma[300:] = 5.0  # the rule counts sigma <= 5 m
    assert convergence_time(time, sigma) == pytest.approx(3.0 * 499)
    assert np.isnan(convergence_time(time[:450], sigma[:450]))


def test_divergence_needs_a_sustained_window() -> None:
    values = np.zeros(200)
    values[10:39] = 50.0  # 29 updates outside 3 sigma: a blip
    assert not has_diverged(values)
    values[100:130] = 9.5
    assert has_diverged(values)


def test_rmse_per_run() -> None:
    np.testing.assert_allclose(rmse(np.array([[3.0, 4.0], [0.0, 0.0]])), [np.sqrt(12.5), 0.0])
