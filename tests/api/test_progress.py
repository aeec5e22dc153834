"""Console progress: plain log lines off a terminal, a rich display on one."""

from __future__ import annotations

import io
import logging
import sys

import pytest
from rich.console import Console

from auvplan.api.progress import ConsoleProgress
from auvplan.optimization import DirectionType, ProntoIteration


def iteration(index: int, epsilon: float) -> ProntoIteration:
    return ProntoIteration(
        iteration=index, cost=100.0 - index, decrement=10.0**-index, step=1.0,
        direction=DirectionType.NEWTON, epsilon=epsilon, delta=1e-3, min_slack=0.5,
        wall_time=0.1 * index, n_backtracks=0,
    )  # fmt: skip


def run_stages(progress: ConsoleProgress) -> None:
    with progress("preplan"), progress("A*", total=25) as advance:
        for index in range(25):
            advance(f"vehicle{index + 1}")
    with progress("optimize"):
        for index, epsilon in enumerate((1.0, 1.0, 0.1, 0.01, 0.01)):
            progress.iteration(iteration(index, epsilon))


def progress_lines(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.name == "auvplan.api.progress"]


def test_off_a_terminal_progress_is_plain_log_lines(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger="auvplan")
    screen = io.StringIO()
    with ConsoleProgress(epsilon_levels=(1.0, 0.1, 0.01), console=Console(file=screen)) as progress:
        run_stages(progress)
    assert screen.getvalue() == ""  # no live display
    lines = progress_lines(caplog)
    a_star = [line for line in lines if line.startswith("A* ")]
    # every third of 25 searches (a tenth, rounded up) and the last, with the time left
    assert [line.split(":")[0] for line in a_star] == [f"A* {k}/25" for k in (*range(3, 25, 3), 25)]
    assert a_star[-1].startswith("A* 25/25: vehicle25 (")
    assert "about 0 s left" in a_star[-1]
    levels = [line for line in lines if "barrier level" in line]
    assert [line.split(" (")[0] for line in levels] == [
        "optimize: barrier level 1/3", "optimize: barrier level 2/3",
        "optimize: barrier level 3/3",
    ]  # fmt: skip
    assert "at iteration 2, cost 98" in levels[1]
    assert "s left" in levels[1]
    assert [line.split(":")[0] for line in lines if "done in" in line] == [
        "A*", "preplan", "optimize",
    ]  # fmt: skip


def test_on_a_terminal_progress_is_a_live_display(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger="auvplan")
    screen = io.StringIO()
    console = Console(file=screen, force_terminal=True, width=140)
    handler = logging.StreamHandler(sys.stderr)
    logging.getLogger().addHandler(handler)
    try:
        with ConsoleProgress(epsilon_levels=(1.0, 0.1, 0.01), console=console) as progress:
            run_stages(progress)
            logging.getLogger("auvplan.test").warning("a warning above the bars")
            assert handler.stream is not sys.stderr  # log lines go through the console
        assert handler.stream is sys.stderr
    finally:
        logging.getLogger().removeHandler(handler)
    shown = screen.getvalue()
    assert "A*" in shown
    assert "25/25" in shown
    assert "ETA" in shown
    assert "optimize  it 4  h 96  −Dh·ζ 1.0e-04  ε 1e-02" in shown
    assert "a warning above the bars" in shown
    assert progress_lines(caplog) == []


def test_a_decomposed_solve_reports_its_vehicles_not_each_ones_barrier_levels(
    caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.INFO, logger="auvplan")
    with (
        ConsoleProgress(epsilon_levels=(1.0, 0.1), live=False) as progress,
        progress("optimize"),
        progress("sweep 1", total=2) as advance,
    ):
        for name in ("blue", "green"):
            for index, epsilon in enumerate((1.0, 0.1)):
                progress.iteration(iteration(index, epsilon))
            advance(name)
    lines = progress_lines(caplog)
    assert not [line for line in lines if "barrier level" in line]
    assert [line.split(" (")[0] for line in lines if line.startswith("sweep 1 ")] == [
        "sweep 1 1/2: blue", "sweep 1 2/2: green",
    ]  # fmt: skip
