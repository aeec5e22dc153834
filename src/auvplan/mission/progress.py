"""How the pipeline reports its progress, without knowing who listens.

A *progress reporter* is a callable ``progress(name, total=None)`` that returns a context
manager; the pipeline enters it around each stage (``"preplan"``, ``"A*"`` inside it,
``"deconflict"``, ``"optimize"`` ...) and calls the ``advance(label)`` function it yields once
per finished unit of work (``total`` units: one A* search per vehicle). :func:`no_progress`
reports nothing. The console reporter (rich bars on a terminal, log lines otherwise) is
:class:`auvplan.api.progress.ConsoleProgress`; the optimiser's iterations reach it through the
``callback`` of :func:`auvplan.mission.pipeline.run_mission`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, contextmanager
from typing import Protocol

from auvplan.interrupts import checkpoint


class ProgressReporter(Protocol):
    """``progress(name, total=None)``: a context manager around one stage (module notes)."""

    def __call__(
        self, name: str, *, total: int | None = None
    ) -> AbstractContextManager[Callable[[str], None]]:
        """Enter stage ``name`` of ``total`` units (``None``: unknown); yield ``advance``."""
        ...


@contextmanager
def no_progress(name: str, *, total: int | None = None) -> Iterator[Callable[[str], None]]:
    """The reporter that reports nothing.

    Examples
    --------
    >>> with no_progress("A*", total=2) as advance:
    ...     advance("blue")
    """
    del name, total  # a reporter's signature; nothing to report

    def advance(label: str) -> None:
        del label

    yield advance


def with_checkpoints(progress: ProgressReporter) -> ProgressReporter:
    """``progress`` that also honours stop requests (:func:`auvplan.interrupts.checkpoint`).

    A pending SIGINT/SIGTERM is raised as a stage begins, after each unit of work and as the
    stage ends: the safe points between path searches and stages.
    """

    @contextmanager
    def reporter(name: str, *, total: int | None = None) -> Iterator[Callable[[str], None]]:
        checkpoint()
        with progress(name, total=total) as advance:

            def advance_and_check(label: str) -> None:
                advance(label)
                checkpoint()

            yield advance_and_check
        checkpoint()

    return reporter


__all__ = ["ProgressReporter", "no_progress", "with_checkpoints"]
