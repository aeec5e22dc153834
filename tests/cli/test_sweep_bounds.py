"""Issue 28: ``auvplan sweep`` refuses what used to hang, overflow or crash: one line, exit 2.

Seed ranges are counted before they are expanded, ``--vary`` values have a nesting limit,
``$AUVPLAN_JOBS`` is read without a traceback, and a ``--scheduler`` that is not a dask
scheduler (a web server here) is refused within the connect timeout, before any scenario file
is written. Where the old code hung, the command runs as a process with a timeout.
"""

from __future__ import annotations

import http.server
import threading
import time
from collections.abc import Iterator
from importlib import resources
from pathlib import Path

import pytest
from _cli import one_error_line, run_cli, run_cli_process

from auvplan.sweep.runner import CONNECT_TIMEOUT_S

DEMO = resources.files("auvplan").joinpath("data", "missions", "demo.toml").read_text()


@pytest.fixture
def mission(tmp_path: Path) -> Path:
    """The demo mission file (only parsed: every case fails before a run)."""
    path = tmp_path / "demo.toml"
    path.write_text(DEMO, encoding="utf-8")
    return path


def test_a_seed_range_is_counted_before_it_is_expanded(mission: Path, tmp_path: Path) -> None:
    """0..200000 took the quadratic repeat check; 0..99999999999 ran out of memory."""
    out = tmp_path / "out"
    for seeds, count in (("0..200000", "200001"), ("0..99999999999", "100000000000")):
        code, err = run_cli_process(
            ["sweep", str(mission), "-o", str(out), "--seeds", seeds], timeout=60
        )
        assert code == 2
        assert f"{count} seeds, more than 100000 runs" in one_error_line(err)
    assert sorted(path.name for path in tmp_path.iterdir()) == ["demo.toml"]


def test_seeds_given_twice_are_found_across_ranges(
    mission: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    code, _, err = run_cli(["sweep", str(mission), "-o", str(out), "--seeds", "0..9,20,5"], capsys)
    assert code == 2
    assert "seed 5 given twice" in one_error_line(err)
    assert not out.exists()


def test_vary_values_nested_too_deep_are_one_line(
    mission: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """3000 nested brackets were a RecursionError in the TOML parser."""
    out = tmp_path / "out"
    value = "[" * 3000 + "1" + "]" * 3000
    code, _, err = run_cli(
        ["sweep", str(mission), "-o", str(out), "--vary", f"weights.terrain={value}"], capsys
    )
    assert code == 2
    assert "nested 3000 deep, more than 16 brackets or braces" in one_error_line(err)
    assert not out.exists()


@pytest.mark.parametrize("jobs", ["²", "abc", " 2"])
def test_auvplan_jobs_is_read_without_a_traceback(
    mission: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    jobs: str,
) -> None:
    """'²'.isdigit() but int('²') raised when any parser was built; 'abc' said 'got -1'."""
    monkeypatch.setenv("AUVPLAN_JOBS", jobs)
    out = tmp_path / "out"
    code, _, err = run_cli(["sweep", str(mission), "-o", str(out), "--seeds", "2..1"], capsys)
    assert code == 2
    assert "--seeds '2..1': range '2..1' runs backwards" in one_error_line(err)
    code, _, err = run_cli(["plan", str(mission), "-o", str(out)], capsys)
    assert code == 2
    assert one_error_line(err).endswith(f"must be 1 or 2, got {jobs!r}")
    assert not out.exists()


@pytest.fixture
def web_server() -> Iterator[str]:
    """``tcp://127.0.0.1:PORT`` of a web server (it answers, but it is no dask scheduler)."""
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), http.server.BaseHTTPRequestHandler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"tcp://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()


def test_a_scheduler_address_that_is_no_scheduler_is_one_line_and_writes_nothing(
    web_server: str, tmp_path: Path
) -> None:
    """The web server made dask hang past its timeout (or read a 3 EiB frame length)."""
    pytest.importorskip("distributed")
    out = tmp_path / "out"
    argv = ["sweep", "scenarios", "-o", str(out), "--seeds", "0", "--scheduler", web_server]
    started = time.perf_counter()
    code, err = run_cli_process(argv, timeout=60 + CONNECT_TIMEOUT_S)
    seconds = time.perf_counter() - started
    assert code == 2
    line = one_error_line(err)
    assert f"--scheduler {web_server}: no dask scheduler answered within 10 s" in line
    assert seconds < 45 + CONNECT_TIMEOUT_S
    assert not out.exists()  # no DIR/scenarios/, no DIR at all
