from __future__ import annotations

import numpy as np
import pytest

from auvplan.deconfliction import CoordinationProblem, headings_along, positions_along
from auvplan.errors import InputError

LINE = np.array([[0.0, 0.0], [10.0, 0.0]])


def make(**overrides: object) -> CoordinationProblem:
    args: dict[str, object] = {
        "paths": (LINE, LINE + np.array([0.0, 20.0])),
        "safety_radius": 1.0,
        "cruise_speeds": np.array([1.0, 2.0]),
        "time_step": 0.3,
    }
    args.update(overrides)
    return CoordinationProblem(**args)  # type: ignore[arg-type]


def test_grid_derived_quantities() -> None:
    problem = make()
    assert problem.path_lengths.tolist() == [10.0, 10.0]
    np.testing.assert_allclose(problem.step_lengths, [0.3, 0.6])
    assert problem.n_steps.tolist() == [34, 17]  # ceil(10 / 0.3), ceil(10 / 0.6)
    for i in range(2):
        s = problem.grid_progress(i, np.arange(problem.n_steps[i] + 1))
        assert s[0] == 0.0
        assert s[-1] == problem.path_lengths[i]  # the last grid point is the goal exactly
        assert np.all(np.diff(s) > 0)
        assert np.all(np.diff(s) <= problem.step_lengths[i] + 1e-12)
    np.testing.assert_allclose(problem.nominal_arrival_times, [10.0, 5.0])


def test_exact_multiple_does_not_add_a_step() -> None:
    problem = make(
        paths=(np.array([[0.0, 0.0], [60.0, 0.0]]),), cruise_speeds=np.array([1.0]), time_step=0.01
    )
    assert problem.n_steps.tolist() == [6000]


def test_repeated_points_are_dropped() -> None:
    problem = make(
        paths=(np.array([[0.0, 0.0], [0.0, 0.0], [3.0, 4.0]]),), cruise_speeds=np.array([1.0])
    )
    assert problem.paths[0].shape == (2, 2)
    assert problem.path_lengths[0] == 5.0


@pytest.mark.parametrize(
    ("overrides", "fragment"),
    [
        ({"paths": ()}, "non-empty"),
        ({"paths": (np.zeros((1, 2)), LINE)}, "shape"),
        ({"paths": (np.zeros((3, 3)), LINE)}, "shape"),
        ({"paths": (np.array([[0.0, 0.0], [np.nan, 1.0]]), LINE)}, "non-finite"),
        ({"paths": (np.zeros((2, 2)), LINE)}, "zero length"),
        ({"safety_radius": 0.0}, "safety_radius"),
        ({"cruise_speeds": np.array([1.0])}, "cruise_speeds"),
        ({"cruise_speeds": np.array([1.0, -1.0])}, "cruise_speeds"),
        ({"time_step": 0.0}, "time_step"),
        ({"time_step": 1e-9}, "grid steps"),
        ({"cruise_speeds": np.array([1.0, 1e-17])}, "cruise speed"),
    ],
)
def test_invalid_input_is_named(overrides: dict[str, object], fragment: str) -> None:
    with pytest.raises(InputError, match=fragment) as info:
        make(**overrides)
    assert "\n" not in str(info.value)


def test_positions_and_headings_along_a_corner() -> None:
    path = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, -3.0]])  # north, then west
    arc = np.array([0.0, 4.0, 7.0])
    np.testing.assert_allclose(
        positions_along(path, arc, np.array([-1.0, 2.0, 5.0, 9.0])),
        [[0, 0], [2, 0], [4, -1], [4, -3]],
    )
    psi = headings_along(path, arc, np.array([0.0, 2.0, 3.75, 5.5, 7.0]))
    # north = 0, west = -pi/2 (clockwise from north); halfway between the segment midpoints
    np.testing.assert_allclose(psi, [0.0, 0.0, -np.pi / 4, -np.pi / 2, -np.pi / 2])
