"""Posterior Cramér-Rao bound: analytic values on planar seabeds."""

from __future__ import annotations

import numpy as np
import pytest
from _navigation_synthetic import make_grid

from auvplan.navigation import posterior_crb

GRADIENT = np.array([0.08, -0.05])  # m/m, north and east


def _plane(north: np.ndarray, east: np.ndarray) -> np.ndarray:
    return 50.0 + GRADIENT[0] * north + GRADIENT[1] * east


def test_static_information_adds_up_along_the_gradient() -> None:
    grid = make_grid(_plane)
    n_updates, variance, prior = 40, 0.7, 6.0
    positions = np.column_stack(
        [np.linspace(200, 600, n_updates), np.linspace(300, 500, n_updates)]
    )
    offsets = np.zeros((n_updates, 1, 2))
    bound = posterior_crb(
        grid, positions, offsets, np.full((n_updates, 1), variance), np.zeros(n_updates - 1), prior
    )
    for k in (0, 9, n_updates - 1):
        information = np.eye(2) / prior**2 + (k + 1) * np.outer(GRADIENT, GRADIENT) / variance
        np.testing.assert_allclose(bound[k], np.linalg.inv(information), rtol=1e-9)


def test_steady_state_with_process_noise_solves_the_scalar_riccati_equation() -> None:
    """Along the gradient p = (-aq + sqrt(a²q² + 4aq)) / (2a): a = |g|²/r, q process variance."""
    grid = make_grid(_plane)
    n_updates, variance, step = 400, 1.3, 0.4
    positions = np.full((n_updates, 2), 500.0)
    beams = np.zeros((n_updates, 3, 2))
    beams[:, 1, 1], beams[:, 2, 1] = -20.0, 20.0  # three soundings: three times the information
    bound = posterior_crb(
        grid,
        positions,
        beams,
        np.full((n_updates, 3), variance),
        np.full(n_updates - 1, step),
        10.0,
    )
    a, q = 3.0 * GRADIENT @ GRADIENT / variance, step**2
    expected = (-a * q + np.sqrt(a**2 * q**2 + 4.0 * a * q)) / (2.0 * a)
    direction = GRADIENT / np.linalg.norm(GRADIENT)
    assert direction @ bound[-1] @ direction == pytest.approx(expected, rel=1e-9)
    # across the gradient nothing is learnt: the prior plus the random walk
    across = np.array([-direction[1], direction[0]])
    assert across @ bound[-1] @ across == pytest.approx(100.0 + (n_updates - 1) * q, rel=1e-9)


def test_no_information_off_the_map() -> None:
    grid = make_grid(_plane)
    bound = posterior_crb(
        grid, np.full((3, 2), -50.0), np.zeros((3, 1, 2)), np.ones((3, 1)), np.ones(2), 2.0
    )
    np.testing.assert_allclose(bound[-1], (4.0 + 2.0) * np.eye(2))
