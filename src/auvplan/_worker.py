"""A second process that runs the functions sent to it, one at a time, and stops at any moment.

Both places that use the second core beside a run — the command line's companion (kernel
warm-up, half the figures; :mod:`auvplan.api.companion`) and the decomposed fleet solve
(:mod:`auvplan.mission.decomposition`) — send work to one :class:`WorkerProcess` and read
the results back in the order sent, over a pipe of its own.

Why not :class:`multiprocessing.pool.Pool`: its ``terminate()`` can hang for ever. A worker
killed while it writes a result holds the result queue's lock (a semaphore shared between
the processes); the pool's task handler then waits for that lock, and ``terminate()`` for
the task handler (CPython issue 96995, open; seen here as a Ctrl-C during the figures that
left ``auvplan plan`` running). :meth:`WorkerProcess.close` kills the process and closes the
pipe: nothing waits on anything the dead process held.

The worker ignores a terminal's Ctrl-C (it is started in
:func:`~auvplan.interrupts.children_ignore_ctrl_c`); the process that started it reports
the interrupt and stops it. A wait for a result honours stop requests
(:func:`~auvplan.interrupts.checkpoint`).
"""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable
from multiprocessing import resource_tracker
from multiprocessing.connection import Connection
from multiprocessing.context import ForkContext, SpawnContext
from multiprocessing.reduction import ForkingPickler
from typing import Any, Final, Literal, Self

from auvplan.interrupts import checkpoint, children_ignore_ctrl_c

__all__ = ["WorkerLost", "WorkerProcess"]

#: How often a wait for a result checks for a stop request [s].
POLL_S: Final = 0.05


class WorkerLost(RuntimeError):
    """The worker process ended before it answered (killed, out of memory, a crash)."""


class WorkerProcess:
    """One worker process; results come back in the order the work was sent.

    Parameters
    ----------
    method : str
        The start method: ``"spawn"`` (a fresh interpreter, sharing nothing but the disk) or
        ``"fork"`` (a copy of this process, sharing its memory as it was at the start).
    initializer : callable, optional
        Run once in the worker before any work, with ``initargs`` (under ``"fork"`` they are
        inherited, not pickled).
    name : str
        The process's name.
    """

    def __init__(
        self,
        method: Literal["spawn", "fork"],
        initializer: Callable[..., object] | None = None,
        initargs: tuple[object, ...] = (),
        *,
        name: str = "auvplan-worker",
    ) -> None:
        if method == "fork":
            context: ForkContext | SpawnContext = multiprocessing.get_context("fork")
        else:
            # a spawned start uses multiprocessing's resource tracker, which unblocks SIGINT
            # when it starts: start it first, so that the block below holds
            resource_tracker.ensure_running()
            context = multiprocessing.get_context("spawn")
        self._connection, child = context.Pipe()
        with children_ignore_ctrl_c():  # Ctrl-C is this process's to handle
            self._process = context.Process(
                target=_serve, args=(child, initializer, initargs), name=name, daemon=True
            )
            self._process.start()
        child.close()
        self._waiting = 0  # work sent whose result has not been read

    def submit(self, function: Callable[..., object], *args: object) -> None:
        """Send ``function(*args)`` to the worker (both pickled here, unless they cannot be).

        Raises
        ------
        Exception
            What pickling ``function`` or ``args`` raised; nothing is sent then.
        """
        self._connection.send((function, args))
        self._waiting += 1

    def ready(self) -> bool:
        """Whether the oldest result not yet read has arrived (or the worker has ended)."""
        return self._waiting > 0 and self._connection.poll()

    def result(self) -> Any:
        """The oldest result not yet read; waits, honouring stop requests.

        Raises
        ------
        Exception
            What the function raised in the worker.
        WorkerLost
            If the worker ended without answering.
        """
        if self._waiting == 0:
            raise RuntimeError("no work was sent to the worker process")
        while not self._connection.poll(POLL_S):
            checkpoint()
        try:
            succeeded, value = self._connection.recv()
        except (EOFError, OSError) as error:
            self._process.join(POLL_S)
            code = self._process.exitcode
            raise WorkerLost(f"the second process ended (exit code {code})") from error
        self._waiting -= 1
        if not succeeded:
            raise value
        return value

    def close(self) -> None:
        """Kill the worker, whatever it is doing, and wait for it to end."""
        self._process.kill()
        self._process.join()
        self._process.close()
        self._connection.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()


def _serve(
    connection: Connection,
    initializer: Callable[..., object] | None,
    initargs: tuple[object, ...],
) -> None:
    """The worker's loop: run each function received, send back its result or its error.

    It ends when the other process closes the pipe or is gone.
    """
    if initializer is not None:
        initializer(*initargs)
    while True:
        try:
            message = connection.recv()
        except (EOFError, OSError):
            return
        except Exception as error:  # noqa: BLE001 (work that does not unpickle here)
            reply: tuple[bool, object] = (False, error)
        else:
            try:
                function, args = message
                reply = (True, function(*args))
            except Exception as error:  # noqa: BLE001 (sent to the other process, raised there)
                reply = (False, error)
        try:
            connection.send_bytes(_pickled(reply))
        except OSError:
            return


def _pickled(reply: tuple[bool, object]) -> memoryview:
    """``reply`` pickled; if it does not pickle, the error saying so.

    An error that does not pickle either goes as a :class:`RuntimeError` naming it.
    """
    try:
        return ForkingPickler.dumps(reply)
    except Exception as error:  # noqa: BLE001 (a result that does not pickle)
        try:
            return ForkingPickler.dumps((False, error))
        except Exception:  # noqa: BLE001
            return ForkingPickler.dumps((False, RuntimeError(f"{type(error).__name__}: {error}")))
