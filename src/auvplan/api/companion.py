"""A second process beside a mission run: first-run kernel compilation, and half the figures.

Planning a mission runs on one core; on the two-core laptops our users plan on, the other
core idles. A :class:`Companion` is a worker process on it (spawned, not forked: it shares
nothing with the mission's process but the disk caches) that

* on the first run with a mission's vehicle types and solver settings
  (:meth:`Companion.warm_up`), runs :func:`auvplan.mission.warmup.warm_up`: it compiles the
  optimiser's kernels (about 30 s) while the mission's process compiles and runs its path
  searches; stage 3 waits for it (:meth:`Companion.wait_for_warm_up`, the pipeline's
  ``before_optimization``) and then reads the kernels from
  numba's disk cache;
* renders about half the figures of the output folder (:meth:`Companion.render_figures`)
  while the mission's process renders the rest.

A first run is recognised by a marker file in the kernel cache (:func:`warm_marker`), named
by a hash of the small warm-up missions and of the installed sources, written once a
warm-up succeeded. A warm-up that fails (e.g. an unusual vehicle file) is logged and
ignored: the mission compiles its kernels itself, as without a companion. The ``auvplan``
command line uses a companion; a script may too, from its ``if __name__ == "__main__":``
block (spawning re-imports the main module)::

    with Companion() as companion:
        mission_plan = auvplan.plan(config, companion=companion)
        mission_plan.save("out", companion=companion)
"""

from __future__ import annotations

import functools
import hashlib
import importlib
import io
import logging
import os
import time
import warnings
from contextlib import AbstractContextManager
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Final

import numba

import auvplan
from auvplan._worker import WorkerProcess
from auvplan.errors import InputError
from auvplan.mission.config import MissionConfig
from auvplan.mission.warmup import warm_up, warm_up_missions
from auvplan.optimization._kernel_cache import cache_root

if TYPE_CHECKING:
    from auvplan._figures import RenderedFigure
    from auvplan.mission.pipeline import MissionResult

logger = logging.getLogger(__name__)

#: The figures that the worker draws: about half of the drawing time of a run (the maps,
#: coordination and separation figures take about as long as these).
WORKER_FIGURES: Final = frozenset({"paths", "paths_cost", "paths_energy_only", "time_series"})


def warm_marker(config: MissionConfig) -> Path:
    """The marker of a finished warm-up for ``config`` (module notes).

    The name hashes the small missions of :func:`~auvplan.mission.warmup.warm_up_missions`,
    the numba version and the size and time of every source file of the installed package,
    so that a new version or an edited checkout warms up again.
    """
    digest = hashlib.sha256(numba.__version__.encode())
    for small in warm_up_missions(config):
        digest.update(small.model_dump_json(exclude={"mission"}).encode())  # not the clock
    package = Path(auvplan.__file__).parent
    for source in sorted(package.rglob("*.py")):
        stat = source.stat()
        digest.update(f"{source.relative_to(package)} {stat.st_size} {stat.st_mtime_ns}".encode())
    return cache_root() / "warm" / digest.hexdigest()[:24]


class Companion(AbstractContextManager["Companion"]):
    """The worker process (module notes); started on first use, stopped on exit."""

    def __init__(self) -> None:
        self._worker: WorkerProcess | None = None
        self._warm_up: tuple[Path, float] | None = None  # marker, start [s]: sent, not read

    def start(self) -> WorkerProcess:
        """Spawn the worker now, so that its imports overlap the mission's own work."""
        if self._worker is None:
            self._worker = WorkerProcess("spawn", _prepare, name="auvplan-companion")
        return self._worker

    def warm_up(self, config: MissionConfig) -> bool:
        """Start the warm-up of ``config`` unless it already ran here; True if it started."""
        marker = warm_marker(config)
        if marker.exists():
            return False
        worker = self.start()
        logger.info(
            "first run with these vehicles and solver settings: compiling the optimiser's "
            "kernels in a second process (once)"
        )
        worker.submit(warm_up, config)
        self._warm_up = (marker, time.perf_counter())
        return True

    def wait_for_warm_up(self) -> None:
        """Wait for a running warm-up to finish (:meth:`_finish_warm_up`)."""
        if self._warm_up is not None:
            assert self._worker is not None
            if not self._worker.ready():
                logger.info("waiting for the optimiser's kernels (compiling in a second process)")
            self._finish_warm_up()

    def _finish_warm_up(self) -> None:
        """Mark a finished warm-up done, or log why it failed (the mission then compiles)."""
        assert self._warm_up is not None
        assert self._worker is not None
        marker, started = self._warm_up
        self._warm_up = None
        try:
            self._worker.result()
        except Exception as error:  # noqa: BLE001 (the mission compiles what it needs itself)
            logger.info("kernel warm-up failed (%s); the optimiser compiles its kernels", error)
            return
        logger.info("optimiser's kernels compiled in %.0f s", time.perf_counter() - started)
        try:
            marker.parent.mkdir(parents=True, exist_ok=True)
            marker.touch()
        except OSError as error:  # a read-only cache: the next run warms up again
            logger.info("cannot mark the warm-up done (%s)", error)

    def render_figures(
        self, result: MissionResult, *, figure_format: str, dpi: int
    ) -> dict[str, RenderedFigure]:
        """The figures of ``result`` (:func:`~auvplan.viz.report.render_mission_figures`).

        The worker renders those of :data:`WORKER_FIGURES` while this process renders the
        rest; the run is pickled over (a few MB). A warm-up still running is waited for
        first (the worker does one thing at a time).
        """
        from auvplan.viz.report import figure_builders, render_mission_figures

        stems = list(figure_builders(result))
        theirs = [stem for stem in stems if stem in WORKER_FIGURES]
        self.wait_for_warm_up()
        worker = self.start()
        draw = functools.partial(render_mission_figures, figure_format=figure_format, dpi=dpi)
        failure: Exception | None = None
        try:
            worker.submit(functools.partial(draw, stems=theirs), result)
        except Exception as error:  # noqa: BLE001 (e.g. a result that does not pickle)
            failure = error
        ours = draw(result, stems=set(stems) - set(theirs))
        if failure is None:
            try:
                drawn: dict[str, RenderedFigure] = worker.result()
            except Exception as error:  # noqa: BLE001 (e.g. the worker was killed)
                failure = error
        if failure is not None:
            logger.info("figures of the second process failed (%s); drawing them here", failure)
            drawn = draw(result, stems=theirs)
        rendered = {**ours, **drawn}
        return {stem: rendered[stem] for stem in stems}

    def close(self) -> None:
        """Stop the worker.

        A warm-up still compiling is abandoned (numba writes its cache files whole or not
        at all); a finished one is marked done.
        """
        if self._worker is not None:
            if self._warm_up is not None and self._worker.ready():
                self._finish_warm_up()
            self._worker.close()
            self._worker = None

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()


def _prepare() -> None:
    """The worker's start: import what it will run while the mission's process plans.

    It ignores SIGINT (:class:`~auvplan._worker.WorkerProcess`): Ctrl-C in a terminal
    reaches every process of the group, and the mission's process, which reports it, stops
    the worker (:meth:`Companion.close`). Its logs
    and warnings are dropped: the mission's process reports.
    """
    logging.getLogger("auvplan").addHandler(logging.NullHandler())
    logging.getLogger("auvplan").propagate = False
    warnings.simplefilter("ignore")
    for module in ("auvplan.mission.warmup", "auvplan.viz.report"):  # pipeline; matplotlib
        importlib.import_module(module)
    from matplotlib.figure import Figure

    figure = Figure(figsize=(1, 1))  # the first drawing loads the fonts
    figure.subplots().set_title("warm-up")
    figure.savefig(io.BytesIO(), format="png")


def resolve_jobs(given: int | None) -> int:
    """The processes of a run: ``given``, else ``$AUVPLAN_JOBS``, else 2 with 2+ cores, else 1.

    2 runs a :class:`Companion` beside the mission; 1 runs in this process only.

    Raises
    ------
    InputError
        If the number given (or the variable's text, quoted) is not 1 or 2.
    """
    text = os.environ.get("AUVPLAN_JOBS", "") if given is None else str(given)
    if text in ("1", "2"):
        return int(text)
    if text:
        shown = text if given is not None else repr(text)
        raise InputError(f"--jobs (or $AUVPLAN_JOBS) must be 1 or 2, got {shown}")
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return 2 if (cores or 1) >= 2 else 1


__all__ = ["Companion", "resolve_jobs", "warm_marker"]
