"""Progress of a mission run on the console: rich bars on a terminal, log lines otherwise.

:class:`ConsoleProgress` is a :class:`~auvplan.mission.progress.ProgressReporter` and, through
:meth:`ConsoleProgress.iteration`, the optimiser's per-iteration ``callback``. Used as a
context manager around :func:`~auvplan.mission.pipeline.run_mission`, it shows

* on a terminal (or in Jupyter with ipywidgets), a rich progress display: one line per stage
  with its elapsed time, a bar with the estimated time left where the amount of work is known
  (one A* search per vehicle; the optimiser's barrier levels ``ε``, with the iteration, cost ``h``,
  decrement ``−Dh·ζ`` and ``ε`` of the last iteration), and the log above it;
* otherwise (a file, a pipe, a CI log), plain log lines of logger ``auvplan.api.progress`` at
  INFO level: each stage's duration, every tenth of a known amount of work with the time
  left, and each new barrier level of the optimiser.

The time left is the elapsed time scaled by the work still to do (ETA of a constant rate).
"""

from __future__ import annotations

import importlib.util
import io
import logging
import math
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from types import TracebackType
from typing import TYPE_CHECKING, Self, TextIO

if TYPE_CHECKING:
    from rich.console import Console
    from rich.progress import Progress, TaskID

    from auvplan.optimization import ProntoIteration

logger = logging.getLogger(__name__)

#: Plain mode logs a known amount of work at about this many steps.
PLAIN_STEPS = 10


@dataclass
class _Stage:
    """A stage in progress: its name, units of work, and its rich task (live mode).

    ``units``: entered with a ``total`` of units it counts; the optimiser's iterations are
    shown on the innermost stage, unless it counts units (the decomposed solve's vehicles).
    """

    name: str
    total: int | None
    units: bool = False
    started: float = field(default_factory=time.perf_counter)
    done: int = 0
    level: int = -1
    task: TaskID | None = None

    def time_left(self, fraction: float) -> float:
        """Seconds left at a constant rate once ``fraction`` (> 0) of the work is done."""
        return (time.perf_counter() - self.started) * (1.0 - fraction) / fraction


class ConsoleProgress:
    """Stage and optimiser progress for the console (module notes).

    Parameters
    ----------
    epsilon_levels : sequence of float
        The optimiser's barrier weights, largest first
        (:meth:`auvplan.optimization.ProntoOptions.epsilon_levels`): its bar counts them.
    console : rich.console.Console, optional
        Where the live display goes (default: standard error).
    live : bool, optional
        Force the rich display (``True``) or plain log lines (``False``); by default live on
        a terminal or in Jupyter.

    Examples
    --------
    >>> with ConsoleProgress(live=False) as progress:
    ...     with progress("A*", total=2) as advance:
    ...         advance("blue")
    ...         advance("green")
    """

    def __init__(
        self,
        *,
        epsilon_levels: Sequence[float] = (),
        console: Console | None = None,
        live: bool | None = None,
    ) -> None:
        self._levels = tuple(epsilon_levels)
        self._console = console
        self._live = live
        self._stages: list[_Stage] = []
        self._display: Progress | None = None
        self._redirected: list[tuple[logging.StreamHandler[TextIO], TextIO]] = []

    def __enter__(self) -> Self:
        console = self._console
        if console is None:
            from rich.console import Console

            console = Console(stderr=True)
        live = console.is_terminal or (console.is_jupyter and _has_widgets())
        is_live = live if self._live is None else self._live
        if is_live:
            self._log_through(console)  # before the display replaces sys.stderr by its proxy
            self._display = _rich_display(console)
            self._display.start()
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        if self._display is not None:
            self._display.stop()
            self._display = None
        for handler, stream in self._redirected:
            handler.setStream(stream)
        self._redirected.clear()

    @contextmanager
    def __call__(self, name: str, *, total: int | None = None) -> Iterator[Callable[[str], None]]:
        """Report stage ``name`` of ``total`` units while the block runs; yields ``advance``."""
        stage = _Stage(name, total, units=total is not None)
        if self._display is not None:
            stage.task = self._display.add_task(name, total=total)
        self._stages.append(stage)
        try:
            yield lambda label: self._advance(stage, label)
        finally:
            self._stages.remove(stage)
        seconds = time.perf_counter() - stage.started
        if self._display is not None and stage.task is not None:
            self._display.update(stage.task, total=stage.total or 1, completed=stage.total or 1)
            self._display.stop_task(stage.task)
        else:
            logger.info("%s: done in %.1f s", name, seconds)

    def iteration(self, record: ProntoIteration) -> None:
        """The optimiser's ``callback``: show iteration, cost, decrement and ``ε``."""
        stage = next((s for s in reversed(self._stages) if not s.units), None)
        if stage is None or self._stages[-1].units:  # a unit (a vehicle's solve) reports
            return
        levels = self._levels if record.epsilon > 0.0 else ()
        level = sum(value > record.epsilon * (1.0 + 1e-9) for value in levels)
        stage.total = len(levels) or None
        text = (
            f"{stage.name}  it {record.iteration}  h {record.cost:.6g}  "
            f"−Dh·ζ {record.decrement:.1e}  ε {record.epsilon:.0e}"
        )
        if self._display is not None and stage.task is not None:
            self._display.update(stage.task, description=text, total=stage.total, completed=level)
        elif level != stage.level:
            left = f", about {stage.time_left(level / len(levels)):.0f} s left" if level else ""
            logger.info(
                "%s: barrier level %d/%d (ε = %.0e) at iteration %d, cost %.6g, %.1f s%s",
                stage.name, level + 1, max(len(levels), 1), record.epsilon, record.iteration,
                record.cost, time.perf_counter() - stage.started, left,
            )  # fmt: skip
        stage.level = level

    def _advance(self, stage: _Stage, label: str) -> None:
        stage.done += 1
        if self._display is not None and stage.task is not None:
            self._display.update(
                stage.task, completed=stage.done, description=f"{stage.name} {label}"
            )
            return
        total = stage.total
        if total is None:
            logger.info("%s: %s done", stage.name, label)
            return
        if stage.done % math.ceil(total / PLAIN_STEPS) and stage.done != total:
            return
        fraction = stage.done / total
        logger.info(
            "%s %d/%d: %s (%.1f s, about %.0f s left)", stage.name, stage.done, total, label,
            time.perf_counter() - stage.started, stage.time_left(fraction),
        )  # fmt: skip

    def _log_through(self, console: Console) -> None:
        """Send the root logger's standard-error lines through ``console`` (above the bars)."""
        for handler in logging.getLogger().handlers:
            if isinstance(handler, logging.StreamHandler) and handler.stream in (
                sys.stderr,
                sys.__stderr__,
            ):
                original = handler.setStream(_ConsoleStream(console))
                if original is not None:
                    self._redirected.append((handler, original))


class _ConsoleStream(io.TextIOBase):
    """A text stream that prints through a rich console (so a live display stays intact)."""

    def __init__(self, console: Console) -> None:
        self._console = console

    def write(self, text: str) -> int:
        self._console.out(text.rstrip("\n"), highlight=False)
        return len(text)


def _has_widgets() -> bool:
    """Whether ipywidgets is installed: rich's display in Jupyter needs it (else it warns)."""
    return importlib.util.find_spec("ipywidgets") is not None


def _rich_display(console: Console) -> Progress:
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        SpinnerColumn,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    return Progress(
        SpinnerColumn(finished_text="✓"),
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
        console=console,
    )


__all__ = ["ConsoleProgress"]
