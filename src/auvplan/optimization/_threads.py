"""Worker threads for the optimiser's batched kernels: points or stages split into pieces.

The numba kernels release the GIL (``nogil``), so pieces of a batch evaluated on threads run
side by side. Every point (stage) is computed by the same arithmetic whichever piece it falls
in: results do not depend on the number of threads.
"""

from __future__ import annotations

import ctypes
import functools
import os
import platform
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

__all__ = ["map_threads", "pieces"]

_T = TypeVar("_T")
_R = TypeVar("_R")


def pieces(n_items: int, threads: int, largest: int) -> list[slice]:
    """Contiguous near-equal slices of ``range(n_items)``: one per thread, none over ``largest``."""
    count = max(min(threads, n_items), -(-n_items // largest), 1)
    return [slice(i * n_items // count, (i + 1) * n_items // count) for i in range(count)]


#: glibc's ``mallopt`` parameters ``M_TRIM_THRESHOLD`` and ``M_MMAP_THRESHOLD``.
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
#: Blocks below this many bytes come from the heap [B]: glibc's own largest dynamic threshold
#: (``DEFAULT_MMAP_THRESHOLD_MAX`` on 64-bit); free memory above the heap's top is handed
#: back to the system beyond twice it, as glibc's dynamic rule would.
MMAP_THRESHOLD = 32 << 20


def keep_freed_memory() -> None:
    """Let glibc reuse the memory of freed arrays below :data:`MMAP_THRESHOLD` (process-wide).

    An iteration frees arrays of a few MiB (sweeps, Hessians, clipped weights) and the next
    one allocates the same again. glibc adapts its thresholds to that on one thread, but
    with worker threads the arrays kept coming back as new pages from the system: 2,400–
    3,100 page faults and 7–37 ms of system time per warm demo solve on two threads (fewer
    than 60 on one). With the thresholds fixed at the values glibc's dynamic rule
    reaches at most (``M_MMAP_THRESHOLD`` 32 MiB, ``M_TRIM_THRESHOLD`` 64 MiB), under 100.
    Arrays from 32 MiB up are still mapped and unmapped one by one, so a large fleet's
    memory is returned as before. glibc only: elsewhere nothing changes.
    """
    if platform.libc_ver()[0] == "glibc":
        libc = ctypes.CDLL(None)
        libc.mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD)
        libc.mallopt(_M_TRIM_THRESHOLD, 2 * MMAP_THRESHOLD)


@functools.cache
def _pool(threads: int) -> ThreadPoolExecutor:
    """The process's worker threads (made on first need, one pool per count).

    Their first start also fixes glibc's memory thresholds (:func:`keep_freed_memory`).
    """
    keep_freed_memory()
    return ThreadPoolExecutor(threads, thread_name_prefix="auvplan-kernels")


# A forked child has none of its parent's threads: it makes its own pools.
os.register_at_fork(after_in_child=_pool.cache_clear)


def map_threads(function: Callable[[_T], _R], items: Sequence[_T], threads: int) -> list[_R]:
    """``[function(item) for item in items]``, on ``threads`` threads when more than one.

    The calling thread is one of them: it computes the first item while ``threads − 1``
    workers take the others (no hand-off to wait for on its own share).
    """
    if threads == 1 or len(items) == 1:
        return [function(item) for item in items]
    pool = _pool(threads - 1)
    others = [pool.submit(function, item) for item in items[1:]]
    first = function(items[0])
    return [first, *(future.result() for future in others)]
