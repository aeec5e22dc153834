"""Running a sweep's runs in parallel on :mod:`dask.distributed`.

By default a :class:`~distributed.LocalCluster` of worker *processes* (one thread each) runs
the missions, so a run that crashes its process (or is killed for memory) takes down only its
worker: the nanny starts a new one, and the run becomes a row with status ``worker died``.
The same runs go to an existing cluster given by its scheduler address, or to the cluster of
a :class:`distributed.Client` the caller made (and closes); its workers must import auvplan
and see ``DIR`` at the same path.

**One plan per mission.** Runs with the same digest (:class:`~auvplan.sweep.spec.SweepRun`:
the same mission, folder and stage; runs of a mission file that differ only in their seed)
are planned once: the first such run plans, and every other one waits for it and gets its
folder's files hard-linked into its own (:func:`execute_shared`), then its own evaluation.
A finished folder of that digest (of this grid, or of the run without a seed) is used in the
same way, so a sweep resumed with more seeds plans nothing new.

Each run (:func:`execute_run`, in a worker) plans its mission and writes the normal ``plan``
output into ``DIR/runs/<run-id>/`` all-or-nothing (:func:`auvplan.io.output.staged_output_dir`),
with ``sweep_run.json`` (:mod:`auvplan.sweep.table`). A run whose folder already holds the
finished run is not submitted again (resumable sweeps); a run that raises writes no folder
and is tried again by the next invocation.

With :attr:`RunOptions.navigation` each plan is then flown through the TAN simulator
(:mod:`auvplan.sweep.navigation`) in the same task, which adds ``navigation.json`` to its
folder; a finished run whose folder lacks that file (or holds one of other settings) is
submitted for the evaluation alone (:func:`execute_evaluation`). The Monte-Carlo seed is the
run's seed (``--seeds``), else the options' own: runs sharing a plan are evaluated each with
its own seed. An evaluation that fails leaves the plan as
it is and sets the record's ``navigation_error``.

dask is imported only when a sweep runs; without it, the error names the extra to install.
"""

from __future__ import annotations

import contextlib
import importlib
import importlib.util
import logging
import re
import shutil
import socket
import struct
import threading
import time
import traceback
import uuid
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Final

from auvplan.errors import AuvplanError, InputError
from auvplan.record.files import NAVIGATION_FILE
from auvplan.sweep.navigation import (
    NavigationOptions,
    evaluate_run_folder,
    has_plan,
    is_evaluated,
)
from auvplan.sweep.spec import SweepRun, run_identifier
from auvplan.sweep.table import RUN_RECORD_FILE, RunRecord, read_run_folder, run_record_document

#: Folder of the run folders inside the sweep's output folder.
RUNS_FOLDER: Final = "runs"
#: Status of a run whose worker process died (crash, out of memory), and the reason given.
WORKER_DIED: Final = "worker died"
WORKER_DIED_REASON: Final = "its worker process died (a crash, or killed for memory)"
#: Seconds to wait for a ``--scheduler`` to answer.
CONNECT_TIMEOUT_S: Final = 10.0
#: Largest first message [bytes] a dask scheduler sends (its handshake: a few hundred bytes).
MAX_HANDSHAKE_BYTES: Final = 2**20
INSTALL_HINT: Final = "pip install 'auvplan[sweep]'"

logger = logging.getLogger(__name__)

#: Writes a run's figures into its staging folder: ``(MissionResult, folder) -> paths``.
FigureWriter = Callable[[Any, Path], list[Path]]


@dataclass(frozen=True)
class RunOptions:
    """How each run is made.

    ``stage`` is the last pipeline stage (``preplan``, ``deconflict``, ``full``);
    ``write_figures`` (e.g. :func:`auvplan.viz.report.save_mission_figures`, a module-level
    function so that it pickles by reference) adds figures to each run folder; ``quiet_logs``
    keeps the runs' log records out of the worker's stderr (they are still collected into
    each record's ``messages``); ``navigation`` (``--evaluate``) evaluates each plan's
    terrain-aided navigation (module notes).
    """

    stage: str = "full"
    write_figures: FigureWriter | None = None
    quiet_logs: bool = True
    navigation: NavigationOptions | None = None


@dataclass(frozen=True)
class SweepProgress:
    """Counts after a run ended (``record``) or at the start (``record`` is ``None``).

    ``total`` counts every run of the grid, ``skipped`` those finished by an earlier
    invocation, ``finished`` those ended now (``failed`` of them without a plan), ``running``
    an estimate (the cluster's threads, at most the runs not yet ended).
    """

    total: int
    skipped: int
    finished: int
    failed: int
    running: int
    record: RunRecord | None = None


#: One run at a time per process. Runs given to the threads of one worker (a threaded
#: ``LocalCluster(processes=False)`` client) would write NetCDF through HDF5 at once, which
#: is not thread-safe (a segmentation fault), and share the process's warning and log capture
#: and peak-memory counter; they take turns instead (reentrant: a run evaluates its plan).
_ONE_RUN_AT_A_TIME: Final = threading.RLock()


def run_folder(directory: Path, run: SweepRun) -> Path:
    """``directory/runs/<run-id>``: where ``run`` writes its output."""
    return directory / RUNS_FOLDER / run.run_id


def run_sweep(
    runs: Sequence[SweepRun],
    directory: Path,
    *,
    options: RunOptions = RunOptions(),
    client: Any = None,
    scheduler: str | None = None,
    n_workers: int | None = None,
    progress: Callable[[SweepProgress], None] | None = None,
    on_ready: Callable[[], None] | None = None,
) -> list[RunRecord]:
    """Run every unfinished run of ``runs`` on dask; the records in the order of ``runs``.

    Runs of the same digest are planned once (module notes).

    Parameters
    ----------
    runs : sequence of SweepRun
        From :func:`auvplan.sweep.spec.build_runs`.
    directory : Path
        The sweep's output folder; run folders go to ``directory/runs/``.
    options : RunOptions
        Stage, figures, logging of each run.
    client : distributed.Client, optional
        A client of a cluster the caller made; used as it is and left open.
    scheduler : str, optional
        Address of a running dask scheduler (``tcp://host:8786``).
    n_workers : int, optional
        Worker processes of the LocalCluster made without ``client`` or ``scheduler``
        (default: the CPU count).
    progress : callable, optional
        Called with a :class:`SweepProgress` at the start and after every run.
    on_ready : callable, optional
        Called once the cluster answers (or when no run is left to submit), before any run
        is submitted: e.g. writing the files the runs read, so that a sweep that cannot reach
        its cluster writes nothing.

    Raises
    ------
    InputError
        If more than one of ``client``, ``scheduler`` and ``n_workers`` is given, ``client``
        is not a :class:`distributed.Client`, dask.distributed is not installed (the message
        names the extra), or the scheduler does not answer as a dask scheduler within
        ``CONNECT_TIMEOUT_S`` (:func:`probe_scheduler`).

    Examples
    --------
    >>> from distributed import Client, LocalCluster  # doctest: +SKIP
    >>> with LocalCluster(n_workers=2) as cluster, Client(cluster) as client:  # doctest: +SKIP
    ...     records = run_sweep(runs, Path("sweep"), client=client)
    """
    cluster_given = {"client": client, "scheduler": scheduler, "n_workers": n_workers}
    given = [name for name, value in cluster_given.items() if value is not None]
    if len(given) > 1:
        raise InputError(f"run_sweep: give one of {' and '.join(given)}, not both")
    directory = Path(directory).resolve()
    records: dict[str, RunRecord] = {}
    to_evaluate: set[str] = set()
    for run in runs:
        finished = read_run_folder(run_folder(directory, run), run)
        if finished is not None:
            records[run.run_id] = replace(finished, skipped=True)
            if _needs_evaluation(finished, run, options.navigation):
                to_evaluate.add(run.run_id)
    pending = [run for run in runs if run.run_id not in records or run.run_id in to_evaluate]
    report = progress or (lambda _event: None)
    ready = on_ready or (lambda: None)
    if not pending:
        ready()
        report(SweepProgress(len(runs), len(records), 0, 0, 0))
        return [records[run.run_id] for run in runs]
    plans: dict[str, Any] = _finished_plans(directory, runs, records)  # digest -> record/future
    with _dask_client(client, scheduler, n_workers) as (cluster, as_completed, killed_worker):
        ready()
        for run in pending:
            if run.run_id not in to_evaluate:
                _remove_stale_staging(run_folder(directory, run))

        def event(finished: int, failed: int, record: RunRecord | None = None) -> SweepProgress:
            threads = sum(cluster.nthreads().values()) or 1
            running = min(threads, len(pending) - finished)
            return SweepProgress(
                len(runs), len(runs) - len(pending), finished, failed, running, record
            )

        report(event(0, 0))
        batch = uuid.uuid4().hex[:8]  # keys unique on a shared scheduler
        futures: dict[Any, SweepRun] = {}
        for index, run in enumerate(pending):
            key = f"auvplan-run-{batch}-{index}"
            folder = run_folder(directory, run)
            if run.run_id in to_evaluate:
                evaluation = (records[run.run_id], run, options.navigation)
                future = cluster.submit(execute_evaluation, *evaluation, key=key, pure=False)
            elif run.digest in plans:  # a finished record, or the future of the run that plans
                shared = (plans[run.digest], run, folder, options)
                future = cluster.submit(execute_shared, *shared, key=key, pure=False)
            else:
                future = cluster.submit(execute_run, run, folder, options, key=key, pure=False)
                plans[run.digest] = future
            futures[future] = run
        n_failed = 0
        for n_finished, future in enumerate(as_completed(futures), start=1):
            run = futures[future]
            try:
                record = future.result()
            except killed_worker:
                _remove_stale_staging(run_folder(directory, run))
                record = RunRecord(
                    run.run_id, run.values, run.seed, WORKER_DIED, WORKER_DIED_REASON
                )
            except Exception as error:  # noqa: BLE001 (the cluster lost the task: a row)
                record = _failure(run, error)
            if run.run_id in to_evaluate and record.failed:  # the plan is still there
                record = replace(records[run.run_id], navigation_error=record.reason)
            records[run.run_id] = record
            n_failed += record.failed
            report(event(n_finished, n_failed, record))
    return [records[run.run_id] for run in runs]


def execute_run(run: SweepRun, folder: Path, options: RunOptions) -> RunRecord:
    """Plan ``run``'s mission and write its folder; runs in a dask worker (or anywhere).

    Every exception becomes a failed :class:`RunRecord` (status: the exception's class, reason:
    its one-line message; an exception that is not an :class:`~auvplan.errors.AuvplanError` is
    a bug and its reason says where it was raised), so one run never ends the sweep. Runs in
    the threads of one process take turns (:data:`_ONE_RUN_AT_A_TIME`).
    """
    with _ONE_RUN_AT_A_TIME:
        return _plan_run(run, folder, options)


def _plan_run(run: SweepRun, folder: Path, options: RunOptions) -> RunRecord:
    """:func:`execute_run`'s work, with the process to itself."""
    from auvplan.io.output import staged_output_dir
    from auvplan.io.results import write_json
    from auvplan.mission.config import parse_mission
    from auvplan.mission.outputs import plan_record
    from auvplan.mission.pipeline import Stage, run_mission
    from auvplan.record import write_record

    started = time.perf_counter()
    with _collected_warnings(quiet=options.quiet_logs) as messages:
        is_peak_reset = _reset_peak_memory()
        try:
            config = parse_mission(run.document, base_dir=run.base_dir, source=run.source)
            result = run_mission(config, stage=Stage(options.stage))
            with staged_output_dir(folder) as staging:
                write_record(plan_record(result), staging)
                if options.write_figures is not None:
                    options.write_figures(result, staging)
                document = run_record_document(
                    run,
                    wall_s=time.perf_counter() - started,
                    peak_rss_mb=_peak_memory_mb() if is_peak_reset else None,
                    messages=messages,
                )
                write_json(document, staging / RUN_RECORD_FILE)
        except Exception as error:  # noqa: BLE001 (any failure is the run's row)
            return _failure(run, error, wall_s=time.perf_counter() - started)
    return _read_back(run, folder, options)


def execute_shared(plan: RunRecord, run: SweepRun, folder: Path, options: RunOptions) -> RunRecord:
    """Give ``run`` the plan of ``plan``, a run of the same digest; nothing is planned.

    ``plan``'s folder is hard-linked into ``folder`` (all or nothing,
    :func:`auvplan.io.output.link_entries`) without its ``navigation.json`` and
    ``sweep_run.json``; ``run``'s own ``sweep_run.json`` names the run that planned
    (``plan_of``) and carries its wall time, peak memory and messages. Then ``run`` is
    evaluated with its own seed when ``options.navigation`` asks. A ``plan`` that failed
    without a folder gives ``run`` the same status and reason. Other failures are records,
    as in :func:`execute_run`.
    """
    with _ONE_RUN_AT_A_TIME:
        return _share_plan(plan, run, folder, options)


def _share_plan(plan: RunRecord, run: SweepRun, folder: Path, options: RunOptions) -> RunRecord:
    """:func:`execute_shared`'s work, with the process to itself."""
    from auvplan.io.output import link_entries, staged_output_dir
    from auvplan.io.results import write_json

    origin = plan.plan_of or plan.run_id
    if plan.folder is None:
        return RunRecord(
            run.run_id, run.values, run.seed, plan.status, plan.reason, wall_s=plan.wall_s,
            plan_of=origin,
        )  # fmt: skip
    try:
        with staged_output_dir(folder) as staging:
            link_entries(plan.folder, staging, skip={NAVIGATION_FILE, RUN_RECORD_FILE})
            document = run_record_document(
                run,
                wall_s=plan.wall_s or 0.0,
                peak_rss_mb=plan.peak_rss_mb,
                messages=plan.messages,
                plan_of=origin,
            )
            write_json(document, staging / RUN_RECORD_FILE)
    except Exception as error:  # noqa: BLE001 (any failure is the run's row)
        return replace(_failure(run, error), plan_of=origin)
    return _read_back(run, folder, options)


def _read_back(run: SweepRun, folder: Path, options: RunOptions) -> RunRecord:
    """The record of the run just written to ``folder``, evaluated when ``options`` ask."""
    record = read_run_folder(folder, run)
    if record is None:
        raise InputError(f"run {run.run_id}: its folder {folder} cannot be read back")
    if _needs_evaluation(record, run, options.navigation):
        return execute_evaluation(record, run, options.navigation)
    return record


def _finished_plans(
    directory: Path, runs: Sequence[SweepRun], finished: dict[str, RunRecord]
) -> dict[str, RunRecord]:
    """Digest -> the record of a finished folder holding that plan.

    The finished runs of the grid, else the folder of a seeded run's values without a seed
    (an earlier sweep of the same mission without ``--seeds``).
    """
    plans: dict[str, RunRecord | None] = {}
    for run in runs:
        if run.run_id in finished:
            plans.setdefault(run.digest, finished[run.run_id])
    for run in runs:
        if run.seed is None or run.digest in plans:  # each digest looked for once
            continue
        unseeded = replace(run, run_id=run_identifier(run.values, None), seed=None)
        plans[run.digest] = read_run_folder(run_folder(directory, unseeded), unseeded)
    return {digest: record for digest, record in plans.items() if record is not None}


def execute_evaluation(
    record: RunRecord, run: SweepRun, options: NavigationOptions | None
) -> RunRecord:
    """Evaluate the navigation along a finished run's plan; ``record`` with its outcome.

    Writes ``navigation.json`` into the run's folder. A failure (an
    :class:`~auvplan.errors.AuvplanError`, e.g. a track that starts off the map) sets
    ``navigation_error`` and leaves the folder as it was; any other exception is a bug and
    propagates.
    """
    if options is None or record.folder is None:
        return record
    try:
        with _ONE_RUN_AT_A_TIME:
            evaluate_run_folder(record.folder, _run_options(options, run))
    except Exception as error:  # noqa: BLE001 (a failed evaluation is the row's note)
        return replace(record, navigation_error=_reason(error))
    return record


def _run_options(options: NavigationOptions, run: SweepRun) -> NavigationOptions:
    """``options`` with the run's seed, when it has one."""
    return options if run.seed is None else replace(options, seed=run.seed)


def _needs_evaluation(record: RunRecord, run: SweepRun, options: NavigationOptions | None) -> bool:
    """Whether ``--evaluate`` asks for a navigation.json that the run's folder lacks."""
    folder = record.folder
    if options is None or folder is None or record.failed or not has_plan(folder):
        return False
    return not is_evaluated(folder, _run_options(options, run))


def _failure(run: SweepRun, error: BaseException, *, wall_s: float | None = None) -> RunRecord:
    """The record of a run that raised ``error``."""
    return RunRecord(
        run.run_id, run.values, run.seed, type(error).__name__, _reason(error), wall_s=wall_s
    )


def _reason(error: BaseException) -> str:
    """One line for ``error``; one that is not an AuvplanError is a bug and says where."""
    reason = " ".join(str(error).split()) or type(error).__name__
    if not isinstance(error, AuvplanError):
        frame = traceback.extract_tb(error.__traceback__)[-1:] if error.__traceback__ else []
        where = f" at {Path(frame[0].filename).name}:{frame[0].lineno}" if frame else ""
        reason = f"{reason} (unexpected{where}: a bug, please report it)"
    return reason


def _remove_stale_staging(folder: Path) -> None:
    """Delete staging folders a killed run left next to ``folder`` (``.<id>.*.partial``)."""
    if folder.parent.is_dir():
        for stale in folder.parent.glob(f".{folder.name}.*.partial"):
            shutil.rmtree(stale, ignore_errors=True)


def require_dask() -> None:
    """Raise InputError naming the extra to install unless dask.distributed can be imported.

    Cheap (nothing is imported): lets the command line fail before any work.
    """
    if importlib.util.find_spec("dask") is None or importlib.util.find_spec("distributed") is None:
        raise InputError(
            f"auvplan sweep needs dask.distributed, which is not installed: {INSTALL_HINT}"
        )


@contextlib.contextmanager
def _dask_client(
    client: Any, scheduler: str | None, n_workers: int | None
) -> Iterator[tuple[Any, Any, Any]]:
    """``(client, as_completed, KilledWorker)`` of the cluster; closed (and stopped) after.

    A ``client`` given is used as it is and left open.
    """
    require_dask()
    dask = importlib.import_module("dask")
    distributed = importlib.import_module("distributed")
    as_completed = distributed.as_completed
    killed_worker = distributed.scheduler.KilledWorker
    if client is not None:
        if not isinstance(client, distributed.Client):
            raise InputError(
                f"run_sweep: client must be a distributed.Client, not {type(client).__name__} "
                "(a scheduler address goes to scheduler=)"
            )
        yield client, as_completed, killed_worker
        return
    if scheduler is not None:
        probe_scheduler(scheduler)
        try:
            client = distributed.Client(scheduler, timeout=CONNECT_TIMEOUT_S)
        except (OSError, TimeoutError, ValueError) as error:
            message = " ".join(str(error).split())[:200]
            raise InputError(f"--scheduler {scheduler}: cannot connect ({message})") from None
        with client:
            yield client, as_completed, killed_worker
        return
    # A run that kills its worker is not tried again on another one; the in-process
    # scheduler and nannies log only errors (the user's terminal shows the progress).
    with (
        _logger_level("distributed", logging.ERROR),
        dask.config.set({"distributed.scheduler.allowed-failures": 0}),
        distributed.LocalCluster(
            n_workers=n_workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",  # a free port: no clash with another cluster's 8787
            silence_logs=logging.ERROR,
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        yield client, as_completed, killed_worker


def probe_scheduler(address: str, *, timeout: float = CONNECT_TIMEOUT_S) -> None:
    """Check that a ``tcp://`` ``address`` answers as a dask scheduler within ``timeout`` [s].

    A dask server speaks first: on a new connection it sends its handshake, one framed
    message (an 8-byte length, then that many bytes of msgpack frames). The probe reads it
    with the timeout and decodes it with dask's own frame reader, so that an address where
    something else listens (a web server, which waits for a request, or a server that sends
    text, whose first bytes read as an exabyte length) is refused in bounded time before
    :class:`distributed.Client` is given it. Other schemes (``tls://``, ``inproc://``...)
    are left to the client.

    Raises
    ------
    InputError
        If the address is malformed, cannot be reached, or does not answer as a dask
        scheduler within ``timeout``.
    """
    addressing = importlib.import_module("distributed.comm.addressing")
    try:
        scheme, location = addressing.parse_address(address)
        if scheme != "tcp":
            return
        host, port = addressing.parse_host_port(location, 8786)
    except ValueError as error:
        raise InputError(f"--scheduler {address}: not an address ({error})") from None
    deadline = time.monotonic() + timeout
    try:
        with socket.create_connection((host, port), timeout=timeout) as connection:
            (n_bytes,) = struct.unpack("Q", _receive(connection, 8, deadline))
            if not 0 < n_bytes <= MAX_HANDSHAKE_BYTES:
                raise ValueError(f"its first message claims {n_bytes} bytes")
            message = _receive(connection, n_bytes, deadline)
    except TimeoutError:
        raise InputError(
            f"--scheduler {address}: no dask scheduler answered within {timeout:g} s"
        ) from None
    except OSError as error:
        reason = error.strerror or type(error).__name__
        raise InputError(f"--scheduler {address}: cannot connect ({reason})") from None
    except ValueError as error:
        raise InputError(f"--scheduler {address}: not a dask scheduler ({error})") from None
    if not isinstance(_handshake(message), dict):
        raise InputError(f"--scheduler {address}: not a dask scheduler (no dask handshake)")


def _receive(connection: socket.socket, n_bytes: int, deadline: float) -> bytes:
    """Exactly ``n_bytes`` from ``connection`` before ``deadline`` (``time.monotonic``).

    Raises ``TimeoutError`` at the deadline and ``ValueError`` if the peer closes first.
    """
    received = bytearray()
    while len(received) < n_bytes:
        remaining = deadline - time.monotonic()
        if remaining <= 0.0:
            raise TimeoutError
        connection.settimeout(remaining)
        chunk = connection.recv(n_bytes - len(received))
        if not chunk:
            raise ValueError(f"it closed the connection after {len(received)} bytes")
        received += chunk
    return bytes(received)


def _handshake(message: bytes) -> Any:
    """The value dask's frame reader decodes from a message, or None if it cannot."""
    utils = importlib.import_module("distributed.protocol.utils")
    core = importlib.import_module("distributed.protocol.core")
    try:
        frames, missing = utils.unpack_frames(message, partial=True)
        return None if missing else core.loads(frames, deserialize=False)
    except Exception:  # noqa: BLE001 (any decoding failure: not a dask peer)
        return None


@contextlib.contextmanager
def _logger_level(name: str, level: int) -> Iterator[None]:
    named = logging.getLogger(name)
    previous = named.level
    named.setLevel(level)
    try:
        yield
    finally:
        named.setLevel(previous)


class _ThreadRecords(logging.Handler):
    """Collects the text of WARNING+ records logged by the current thread."""

    def __init__(self, messages: list[str]) -> None:
        super().__init__(logging.WARNING)
        self.messages = messages
        self.thread = threading.get_ident()

    def emit(self, record: logging.LogRecord) -> None:
        if record.thread == self.thread:
            self.messages.append(" ".join(record.getMessage().split()))


@contextlib.contextmanager
def _collected_warnings(*, quiet: bool) -> Iterator[list[str]]:
    """The warnings auvplan logs in this thread during the block; with ``quiet`` only there."""
    messages: list[str] = []
    package = logging.getLogger("auvplan")
    handler = _ThreadRecords(messages)
    propagate = package.propagate
    package.addHandler(handler)
    if quiet:  # our own single-threaded workers: their stderr is the user's terminal
        package.propagate = False
    try:
        yield messages
    finally:
        package.removeHandler(handler)
        package.propagate = propagate


def _reset_peak_memory() -> bool:
    """Reset this process's peak resident memory (Linux ``clear_refs``); False if not possible."""
    try:
        Path("/proc/self/clear_refs").write_text("5", encoding="ascii")
    except OSError:
        return False
    return True


def _peak_memory_mb() -> float | None:
    """Peak resident memory [MiB] of this process since :func:`_reset_peak_memory` (VmHWM)."""
    try:
        status = Path("/proc/self/status").read_text(encoding="ascii")
    except OSError:
        return None
    match = re.search(r"^VmHWM:\s+(\d+) kB", status, re.MULTILINE)
    return None if match is None else int(match[1]) / 1024.0


__all__ = [
    "RUNS_FOLDER",
    "WORKER_DIED",
    "RunOptions",
    "SweepProgress",
    "execute_evaluation",
    "execute_run",
    "probe_scheduler",
    "require_dask",
    "run_folder",
    "run_sweep",
]
