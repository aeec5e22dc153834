"""Worker threads for the optimiser's batched kernels: points or stages split into pieces.

The numba kernels release the GIL (``nogil``), so pieces of a batch evaluated on threads run
side by side. Every point (stage) is computed by the same arithmetic whichever piece it falls
in: results do not depend on the number of threads.
"""

from __future__ import annotations

import functools
import os
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


@functools.cache
def _pool(threads: int) -> ThreadPoolExecutor:
    """The process's worker threads (made on first need, one pool per count)."""
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
