"""matplotlib's notices while a figure is drawn, logged at debug level instead of printed.

Drawing a figure, matplotlib warns (:func:`warnings.warn`) of glyphs its fonts lack (a vehicle
named in CJK characters or emoji is drawn with boxes in their place) and of a constrained
layout it could not apply (axes too small for their decorations), and its mathtext logs the
glyphs it substitutes (logger ``matplotlib.mathtext``). None of them changes a number of the
run, yet they were tens of lines on the console of every such run (``-q`` promises one line
or nothing). :func:`notices_as_debug` collects them while matplotlib draws and logs each
distinct one once at debug level (``auvplan -v`` shows them).
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["notices_as_debug"]

logger = logging.getLogger(__name__)


@contextmanager
def notices_as_debug() -> Iterator[None]:
    """Log matplotlib's warnings and warning log records of the block at debug level.

    Only matplotlib's drawing should run in the block: every warning raised in it is taken
    for one of matplotlib's.
    """
    notices: list[str] = []

    class Collector(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            notices.append(record.getMessage())

    source = logging.getLogger("matplotlib")
    handler, propagate = Collector(logging.WARNING), source.propagate
    source.addHandler(handler)
    source.propagate = False
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            yield
    finally:
        source.removeHandler(handler)
        source.propagate = propagate
    for notice in dict.fromkeys([*(str(warning.message) for warning in caught), *notices]):
        logger.debug("matplotlib: %s", notice)
