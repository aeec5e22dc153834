"""SIGINT and SIGTERM as requests to stop, honoured where the run can unwind cleanly.

A signal handler that raises runs at whatever bytecode the main thread reaches next — which
may be inside a C call or a numba-compiled function's wrapper (CPython then reports
``SystemError: ... returned a result with an exception set``) or in the middle of renaming an
output folder. So while :func:`stop_requests` is active (the command line activates it for
the whole run) the handlers only *record* the signal, and :func:`checkpoint` raises it at
points chosen to be safe: between optimiser iterations, path searches, stages, figures and
files. The exception is :class:`KeyboardInterrupt` for SIGINT and :class:`Terminated` for
SIGTERM; both derive from :class:`BaseException`, so ``except Exception`` does not swallow
them and every ``with`` block on the way out (staging folders, worker processes) cleans up.

* :func:`held` marks a section that must finish once begun (the output folder's swap): a
  checkpoint inside it does not raise, and the signal is raised when the section ends.
* A second signal while the first is still pending (nothing reached a checkpoint yet) raises
  at once, outside a held section: the user insists.
* Without :func:`stop_requests` (a library user in a notebook) Python's own handlers apply,
  and :func:`held` records signals only for the duration of its section, then delivers them.
* Worker processes started in :func:`children_ignore_ctrl_c` ignore a terminal's Ctrl-C from
  their first instruction; the process that started them stops them.
* :func:`finished`: once the work is done, a late signal can no longer change the outcome.

Signal handlers belong to the main thread; in any other thread these functions do nothing.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from types import FrameType

#: The signals that ask a run to stop.
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Terminated(BaseException):
    """SIGTERM, raised at a checkpoint like :class:`KeyboardInterrupt` is for SIGINT."""


@dataclass
class _State:
    """The main thread's record: signals received and not yet raised, and the nesting depths."""

    pending: list[int] = field(default_factory=list)
    installed: int = 0  # nesting depth of install() and stop_requests()
    held: int = 0  # nesting depth of held()


_state = _State()


def _exception(signum: int) -> BaseException:
    return KeyboardInterrupt() if signum == signal.SIGINT else Terminated()


def _record(signum: int, _frame: FrameType | None) -> None:
    """The handler: record ``signum``; a second one outside a held section raises at once."""
    _state.pending.append(signum)
    if len(_state.pending) > 1 and _state.held == 0:
        del _state.pending[:]
        raise _exception(signum)


def _in_main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def install() -> None:
    """Make SIGINT and SIGTERM stop requests for the rest of the process (the console script).

    Unlike :func:`stop_requests` nothing is restored; :func:`finished` ends it when the work
    is done.
    """
    if _in_main_thread():
        for number in STOP_SIGNALS:
            signal.signal(number, _record)
        _state.installed += 1


@contextmanager
def _recording() -> Iterator[None]:
    """:func:`_record` handles SIGINT and SIGTERM in the block; the previous handlers after."""
    previous = {number: signal.signal(number, _record) for number in STOP_SIGNALS}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, signal.SIG_DFL if handler is None else handler)


@contextmanager
def stop_requests() -> Iterator[None]:
    """While the block runs, SIGINT and SIGTERM are recorded and raised at checkpoints.

    Signals still pending when the block ends are dropped (the work they asked to stop is
    over); the previous handlers are restored.
    """
    if not _in_main_thread():
        yield
        return
    with _recording():
        _state.installed += 1
        try:
            yield
        finally:
            _state.installed -= 1
            if not _state.installed:
                del _state.pending[:]


def checkpoint() -> None:
    """Raise the first pending stop request, unless inside a :func:`held` section.

    Cheap (a list test): call it between units of work that take at most about a second.
    """
    if _state.pending and not _state.held:
        signum = _state.pending[0]
        del _state.pending[:]
        raise _exception(signum)


@contextmanager
def held() -> Iterator[None]:
    """Run the block to its end whatever signal arrives; then act on the signal.

    With :func:`stop_requests` active the signal is raised as its exception when the block
    ends (if the block itself succeeded). Without it, SIGINT and SIGTERM are recorded for the
    block's duration and then re-delivered to the handlers that were in place.
    """
    if not _in_main_thread():
        yield
        return
    if _state.installed:
        _state.held += 1
        try:
            yield
        finally:
            _state.held -= 1
        checkpoint()
        return
    try:
        with _recording():
            _state.held += 1
            try:
                yield
            finally:
                _state.held -= 1
    finally:
        received, _state.pending[:] = list(_state.pending), []
        if received:  # to the handlers that were in place again
            signal.raise_signal(received[0])


@contextmanager
def children_ignore_ctrl_c() -> Iterator[None]:
    """Processes started in the block ignore SIGINT (a terminal's Ctrl-C) from their start.

    Ctrl-C reaches every process of the terminal's process group. An ignored disposition
    survives ``exec`` and Python then installs no ``KeyboardInterrupt`` handler, so a worker
    started here never prints a traceback of its own, even while it imports; the process that
    started it stops it. Here SIGINT is blocked for the block's duration (a Ctrl-C meanwhile
    stays pending: Linux never discards a blocked signal) and ignored, then the handler and
    the mask are restored and a pending SIGINT is delivered.
    """
    if not (hasattr(signal, "pthread_sigmask") and _in_main_thread()):
        yield
        return
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    handler = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, signal.SIG_DFL if handler is None else handler)
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)


def finished() -> None:
    """The work is done: SIGINT and SIGTERM are ignored for the rest of the process.

    While the interpreter shuts down it restores the default action of every signal with a
    Python handler (not of an ignored one), and a signal then — delivered to any thread, such
    as a BLAS worker — would kill a process whose output is already complete (exit -15).
    """
    if _in_main_thread():
        for number in STOP_SIGNALS:
            signal.signal(number, signal.SIG_IGN)


__all__ = [
    "STOP_SIGNALS",
    "Terminated",
    "checkpoint",
    "children_ignore_ctrl_c",
    "finished",
    "held",
    "install",
    "stop_requests",
]
