"""The second process (:mod:`auvplan._worker`): results in order, errors carried, and a stop
that returns whatever the worker is doing — above all while it writes a result nobody reads,
the moment at which ``multiprocessing.Pool.terminate()`` hangs (CPython issue 96995; a
Ctrl-C during the figures once left ``auvplan plan`` running in CI)."""

from __future__ import annotations

import math
import operator
import os
import random
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

from auvplan._worker import WorkerLost, WorkerProcess

#: A result large enough to fill the pipe many times over [B].
LARGE = 8 << 20


@pytest.mark.parametrize("method", ["spawn", "fork"])
def test_results_come_back_in_order_and_errors_as_raised(method: str) -> None:
    with WorkerProcess(method) as worker:  # type: ignore[arg-type]
        worker.submit(operator.add, 2, 3)
        worker.submit(math.sqrt, -1.0)
        worker.submit(threading.Lock)  # a result that does not pickle
        worker.submit(operator.mul, b"x", LARGE)
        assert worker.result() == 5
        with pytest.raises(ValueError, match="math domain error"):
            worker.result()
        with pytest.raises(TypeError, match="pickle"):
            worker.result()
        assert worker.result() == b"x" * LARGE


def test_work_that_does_not_pickle_is_refused_here_and_the_worker_goes_on() -> None:
    with WorkerProcess("spawn") as worker:
        with pytest.raises(AttributeError):  # a local function has no importable name
            worker.submit(lambda: 1)
        assert not worker.ready()  # nothing was sent
        worker.submit(operator.neg, 4)
        assert worker.result() == -4


def test_a_worker_that_dies_is_reported_not_waited_for() -> None:
    with WorkerProcess("spawn") as worker:
        worker.submit(os._exit, 7)
        with pytest.raises(WorkerLost, match="exit code 7"):
            worker.result()


def test_the_stop_returns_while_the_worker_writes_a_result_nobody_reads() -> None:
    worker = WorkerProcess("spawn")
    worker.submit(operator.mul, b"x", LARGE)
    deadline = time.monotonic() + 60.0
    while not worker.ready():  # the first bytes are in the pipe: the worker is writing
        assert time.monotonic() < deadline
        time.sleep(0.01)
    pid = worker._process.pid
    assert pid is not None
    worker.close()  # returns: the worker is killed and reaped
    assert not _alive(pid)


def _alive(pid: int) -> bool:
    """Whether ``pid`` is a live process (not a zombie)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def test_stops_at_random_moments_around_a_large_result_all_return() -> None:
    """A hundred stops drawn around the moment the worker starts sending 8 MB, in a fresh
    interpreter with a deadline: a stop that waits for a lock the killed worker held hangs."""
    script = textwrap.dedent(
        f"""
        import operator, random, time
        from auvplan._worker import WorkerProcess
        rng = random.Random({random.Random(5).randrange(1 << 30)})
        for _ in range(100):
            worker = WorkerProcess("spawn")
            worker.submit(time.sleep, 0.0)
            worker.result()  # started and serving
            worker.submit(time.sleep, 0.05)
            worker.submit(operator.mul, b"x", {LARGE})
            time.sleep(rng.uniform(0.03, 0.09))
            worker.close()
        print("all returned")
        """
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=300, check=False
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout == "all returned\n"
