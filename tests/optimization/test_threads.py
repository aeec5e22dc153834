"""Worker threads of the batched kernels: pieces tile the batch; a forked child has its own pool."""

from __future__ import annotations

import os
import platform
import subprocess
import sys
import threading
import warnings

import numpy as np
import pytest

from auvplan.optimization import _threads


def test_pieces_tile_the_items_one_per_thread_and_none_over_the_largest() -> None:
    for n_items in (1, 2, 7, 8, 20):
        for threads in (1, 2, 3, 5):
            pieces = _threads.pieces(n_items, threads, 3)
            covered = np.concatenate([np.arange(n_items)[rows] for rows in pieces])
            np.testing.assert_array_equal(covered, np.arange(n_items))  # in order, once each
            sizes = [rows.stop - rows.start for rows in pieces]
            assert min(sizes) >= 1
            assert max(sizes) <= 3
            assert max(sizes) - min(sizes) <= 1
            assert len(pieces) >= min(threads, n_items)
    assert len(_threads.pieces(8, 1, 3)) == 3  # 3, 3 and 2 items


def test_map_threads_keeps_the_order_of_the_items() -> None:
    assert _threads.map_threads(lambda i: i * i, list(range(7)), 3) == [i * i for i in range(7)]


def test_the_calling_thread_computes_the_first_item_and_a_worker_the_others() -> None:
    ident = _threads.map_threads(lambda _: threading.get_ident(), [0, 1, 2], 2)
    assert ident[0] == threading.get_ident()
    assert threading.get_ident() not in ident[1:]


def test_a_forked_child_makes_its_own_worker_threads() -> None:
    """A pool made before a fork has no threads in the child: the child must not use it."""
    parent_pool = _threads._pool(2)
    assert parent_pool.submit(lambda: 1).result(timeout=10) == 1  # its threads are running
    reader, writer = os.pipe()
    with warnings.catch_warnings():  # Python ≥ 3.12 warns of fork() beside threads
        warnings.simplefilter("ignore", DeprecationWarning)
        child = os.fork()
    if child == 0:  # pragma: no cover (the child reports through the pipe)
        try:
            pool = _threads._pool(2)
            answer = pool.submit(lambda: 42).result(timeout=10)
            os.write(writer, b"new" if pool is not parent_pool and answer == 42 else b"old")
        finally:
            os._exit(0)
    os.close(writer)
    _, status = os.waitpid(child, 0)
    assert os.read(reader, 3) == b"new"
    assert status == 0


#: A fresh interpreter (glibc's thresholds are process-wide): starts the worker threads or not,
#: then frees a 16 MiB array and allocates it again, printing the page faults of the second.
REUSE = """
import resource, sys
import numpy as np
from auvplan.optimization import _threads
if sys.argv[1] == "threads":
    _threads.map_threads(lambda i: i, [0, 1], 2)
first = np.ones(2 << 20)
del first
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
second = np.ones(2 << 20)
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


@pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="glibc's malloc thresholds")
def test_with_worker_threads_freed_arrays_are_reused_without_new_pages() -> None:
    """A freed 16 MiB array's memory is reused (4,096 pages are not faulted in again)."""

    def faults(mode: str) -> int:
        run = subprocess.run(
            [sys.executable, "-c", REUSE, mode], capture_output=True, text=True, check=True
        )
        return int(run.stdout)

    alone = faults("alone")  # glibc's default: mapped, unmapped and its pages faulted again
    if alone < 64:  # hugepages: too few faults to tell
        pytest.skip(f"{alone} page faults for 16 MiB: hugepages hide them")
    assert faults("threads") < alone / 8
