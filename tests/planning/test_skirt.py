"""Skirting discs: the repaired path stays outside every disc, keeps its ends, and takes the
side of the centre it passed (or the other side when that one is blocked)."""

from __future__ import annotations

import numpy as np
import pytest

from auvplan.planning import path_length, skirt_discs
from auvplan.planning.smoothing import resample_polyline


def _gap(path: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """Distance [m] from ``centre`` of every point of ``path`` densified to 1 cm steps."""
    dense = resample_polyline(path, 0.01)
    return np.hypot(*(dense - centre).T)


@pytest.mark.parametrize("offset", [-2.5, -0.7, 0.0, 0.7, 2.5])
def test_a_straight_pass_becomes_the_rim_on_its_own_side(offset: float) -> None:
    line = np.array([[offset, -20.0], [offset, 20.0]])
    centre, radius = np.array([0.0, 0.0]), 3.0
    out = skirt_discs(line, centre[None], np.array([radius]))
    assert np.min(_gap(out, centre)) >= radius * (1 - 1e-9)  # between the samples too
    np.testing.assert_array_equal(out[[0, -1]], line)
    if offset != 0.0:  # stays on the side it passed: north of the centre stays north
        assert np.sign(out[np.argmax(np.abs(out[:, 0])), 0]) == np.sign(offset)
    # the detour is the rim arc: half the circumference replaces at most the diameter
    assert path_length(out) == pytest.approx(
        40.0 - 2 * np.sqrt(radius**2 - offset**2) + 2 * radius * np.arccos(abs(offset) / radius),
        rel=2e-3,
    )


def test_a_path_clear_of_the_discs_is_returned_unchanged() -> None:
    line = np.array([[5.0, -20.0], [5.0, 20.0]])
    assert skirt_discs(line, np.array([[0.0, 0.0]]), np.array([3.0])) is line


def test_a_blocked_side_sends_the_path_round_the_other() -> None:
    line = np.array([[1.0, -20.0], [1.0, 20.0]])  # passes north of the centre

    def north_blocked(north: np.ndarray, east: np.ndarray) -> np.ndarray:
        return np.asarray(north > 2.5)

    out = skirt_discs(line, np.array([[0.0, 0.0]]), np.array([3.0]), is_blocked=north_blocked)
    assert out[:, 0].min() < -2.9
    assert out[:, 0].max() <= 1.0 + 1e-9


def test_overlapping_discs_are_both_skirted() -> None:
    """A rendezvous: three goal discs that overlap, a path straight through them."""
    centres = np.array([[0.0, -2.0], [0.5, 2.0], [-0.3, 6.0]])
    radii = np.array([3.0, 3.0, 2.5])
    line = np.array([[0.2, -30.0], [0.2, 30.0]])
    out = skirt_discs(line, centres, radii)
    for centre, radius in zip(centres, radii, strict=True):
        assert np.min(_gap(out, centre)) >= radius * (1 - 1e-9)
    np.testing.assert_array_equal(out[[0, -1]], line)


@pytest.mark.parametrize("seed", range(12))
def test_random_discs_on_a_winding_path_are_all_cleared(seed: int) -> None:
    rng = np.random.default_rng(seed)
    east = np.linspace(0.0, 200.0, 80)
    path = np.column_stack((15.0 * np.sin(east / 25.0 + rng.uniform(0, 6)), east))
    centres = np.column_stack((rng.uniform(-20, 20, 6), rng.uniform(20, 180, 6)))
    radii = rng.uniform(3.0, 12.0, 6)
    out = skirt_discs(path, centres, radii)
    np.testing.assert_array_equal(out[[0, -1]], path[[0, -1]])
    for centre, radius in zip(centres, radii, strict=True):
        assert np.min(_gap(out, centre)) >= radius * (1 - 1e-9)
    assert path_length(out) < 3.0 * path_length(path)  # round the discs, not round the world


def test_a_crossing_blocked_both_ways_is_left_as_it_was() -> None:
    line = np.array([[0.0, -20.0], [0.0, 20.0]])

    def walls(north: np.ndarray, east: np.ndarray) -> np.ndarray:
        return np.asarray(np.abs(north) > 2.0)

    out = skirt_discs(line, np.array([[0.0, 0.0]]), np.array([3.0]), is_blocked=walls)
    assert np.max(np.abs(out[:, 0])) == 0.0


def test_discs_too_small_to_draw_leave_the_path_as_it_is() -> None:
    """Radii that buffer to nothing (e.g. a safety radius of 1e-300 m) skirt nothing."""
    path = np.array([[0.0, -10.0], [0.0, 10.0]])
    assert skirt_discs(path, np.array([[0.0, 0.0]]), np.array([1e-300])) is path
