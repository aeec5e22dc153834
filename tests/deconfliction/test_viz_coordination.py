from __future__ import annotations

import numpy as np
import pytest

from auvplan.deconfliction import CoordinationProblem, deconflict
from auvplan.errors import InputError
from auvplan.viz.coordination import plot_coordination_space, plot_timed_paths


@pytest.fixture(scope="module")
def crossing() -> tuple[CoordinationProblem, object]:
    paths = (np.array([[-10.0, 0.0], [10.0, 0.0]]), np.array([[0.0, -10.0], [0.0, 10.0]]))
    problem = CoordinationProblem(paths, 1.0, np.ones(2), 0.5)
    return problem, deconflict(problem)


def test_coordination_space_draws_the_schedule(crossing) -> None:  # type: ignore[no-untyped-def]
    problem, result = crossing
    figure = plot_coordination_space(problem, result, pair=(1, 0))
    ax = figure.axes[0]
    line = next(line for line in ax.get_lines() if line.get_label() == "deconflicted")
    np.testing.assert_array_equal(line.get_xdata(), result.progress[1])
    np.testing.assert_array_equal(line.get_ydata(), result.progress[0])
    assert ax.get_xlim() == (0.0, 20.0)
    with pytest.raises(InputError, match="pair"):
        plot_coordination_space(problem, result, pair=(0, 0))


def test_timed_paths_marks_the_certified_minimum(crossing) -> None:  # type: ignore[no-untyped-def]
    problem, result = crossing
    figure = plot_timed_paths(problem, result)
    ax_map, ax_sep = figure.axes[:2]
    assert ax_map.get_xlabel() == "east [m]"
    assert ax_sep.get_ylabel() == "pairwise distance [m]"
    marker = next(line for line in ax_sep.get_lines() if "certified" in str(line.get_label()))
    assert marker.get_ydata()[0] == pytest.approx(result.min_separation)
