"""Stop requests: signals recorded by the handler, raised only at checkpoints."""

from __future__ import annotations

import os
import signal
from collections.abc import Callable
from pathlib import Path

import numba
import numpy as np
import pytest

from auvplan import interrupts
from auvplan.interrupts import Terminated, checkpoint, held, stop_requests


def _send(signum: int) -> None:
    os.kill(os.getpid(), signum)


@pytest.mark.parametrize(
    ("signum", "raised"), [(signal.SIGINT, KeyboardInterrupt), (signal.SIGTERM, Terminated)]
)
def test_a_signal_is_raised_at_the_next_checkpoint_only(
    signum: int, raised: type[BaseException]
) -> None:
    with stop_requests():
        _send(signum)
        total = sum(range(1000))  # plain work goes on: the handler only records
        with pytest.raises(raised):
            checkpoint()
        checkpoint()  # raised once, then forgotten
    assert total == 499500


@numba.njit(cache=False)
def _busy(n: int) -> float:
    total = 0.0
    for i in range(n):
        total += np.sqrt(i)
    return total


def test_a_signal_inside_compiled_code_waits_for_the_checkpoint() -> None:
    """The failure mode of raising handlers: SystemError from a numba function's return."""
    _busy(10)
    with stop_requests():
        _send(signal.SIGTERM)
        value = _busy(100_000)
        with pytest.raises(Terminated):
            checkpoint()
    assert value > 0


def test_a_held_section_finishes_before_the_signal_is_raised() -> None:
    steps: list[str] = []
    with stop_requests(), pytest.raises(KeyboardInterrupt):  # noqa: PT012
        with held():
            _send(signal.SIGINT)
            checkpoint()  # does not raise inside
            steps.append("finished")
        steps.append("after")  # never: raised as the section ends
    assert steps == ["finished"]


def test_a_second_signal_stops_at_once() -> None:
    with stop_requests():
        _send(signal.SIGINT)
        with pytest.raises(KeyboardInterrupt):
            _send(signal.SIGINT)  # the user insists: raised by the handler itself


def test_a_signal_after_the_block_is_dropped_and_handlers_restored() -> None:
    before = signal.getsignal(signal.SIGTERM)
    with stop_requests():
        _send(signal.SIGTERM)
    assert signal.getsignal(signal.SIGTERM) == before
    checkpoint()  # nothing pending


def test_without_stop_requests_held_delivers_the_signal_to_the_previous_handler() -> None:
    received: list[int] = []
    record: Callable[[int, object], None] = lambda signum, _frame: received.append(signum)  # noqa: E731
    previous = signal.signal(signal.SIGTERM, record)
    try:
        with held():
            _send(signal.SIGTERM)
            assert received == []
        assert received == [signal.SIGTERM]
        assert signal.getsignal(signal.SIGTERM) is record
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_install_keeps_the_handlers(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(interrupts, "_state", interrupts._State())
    previous = {number: signal.getsignal(number) for number in interrupts.STOP_SIGNALS}
    try:
        interrupts.install()
        with stop_requests():
            pass
        _send(signal.SIGTERM)  # after the run: recorded, not fatal
        assert interrupts._state.pending == [signal.SIGTERM]
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


_CHILD_SCRIPT = """
import multiprocessing, os, signal
from multiprocessing import resource_tracker
from auvplan import interrupts

def sigint_ignored():
    status = open(f"/proc/{os.getpid()}/status").read()
    line = next(row for row in status.splitlines() if row.startswith("SigIgn:"))
    return bool(int(line.split()[1], 16) & (1 << (signal.SIGINT - 1)))

if __name__ == "__main__":
    received = []
    signal.signal(signal.SIGINT, lambda signum, frame: received.append(signum))
    resource_tracker.ensure_running()  # as the companion does
    with interrupts.children_ignore_ctrl_c():
        pool = multiprocessing.get_context("spawn").Pool(1)
        os.kill(os.getpid(), signal.SIGINT)
        held_back = received == []
    print(held_back, received == [signal.SIGINT], pool.apply(sigint_ignored))
    pool.terminate()
"""


def test_a_worker_started_in_the_block_ignores_ctrl_c_and_none_is_lost(tmp_path: Path) -> None:
    """A spawned worker (as the companion starts it) ignores SIGINT from its first instruction
    (no KeyboardInterrupt while it imports); a SIGINT to the parent meanwhile is delivered to the
    parent's handler afterwards. In a fresh single-threaded process, as the command line is."""
    import subprocess
    import sys

    script = tmp_path / "spawn_worker.py"
    script.write_text(_CHILD_SCRIPT)
    done = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, check=False, timeout=120
    )
    assert (done.returncode, done.stdout, done.stderr) == (0, "True True True\n", "")


def test_after_the_work_a_signal_cannot_change_the_exit_code() -> None:
    """The console script blocks SIGINT/SIGTERM once main returned: the interpreter's shutdown
    restores the default handlers, and a late SIGTERM would otherwise kill it (exit -15)."""
    import subprocess
    import sys

    code = (
        "import os, signal, sys\n"
        "from auvplan import interrupts\n"
        "interrupts.install()\n"
        "interrupts.finished()\n"
        "sys.stdout.write('done')\n"
        "os.kill(os.getpid(), signal.SIGTERM)\n"
        "os.kill(os.getpid(), signal.SIGINT)\n"
        "sys.exit(0)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert (done.returncode, done.stdout, done.stderr) == (0, "done", "")
