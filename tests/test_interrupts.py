"""Stop requests: signals recorded by the handler, raised only at checkpoints."""

from __future__ import annotations

import os
import signal
from collections.abc import Callable

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
