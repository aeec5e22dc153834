"""numba's on-disk cache made self-healing: a damaged cache file is discarded and rebuilt.

numba (``cache=True``) keeps each compiled kernel in two files: an index ``<name>.nbi`` and
the machine code ``<name>.<n>.nbc``. They live in the ``__pycache__`` folder beside the
kernel's source (``src/auvplan/<package>/__pycache__`` for auvplan's own kernels,
``<cache>/kernels/__pycache__`` for the generated ones of
:mod:`auvplan.optimization._kernel_cache`), or under ``$NUMBA_CACHE_DIR`` when it is set.
numba 0.68 raises when such a file is truncated, garbage or empty (an ``EOFError`` or an
``UnpicklingError`` from the first call of the kernel), and every later run raises the same
way (numba issue 10434; the fix in pull request 10656 is not released).

Importing this module replaces numba's ``IndexDataCacheFile`` with :class:`HealingCacheFile`,
which treats a file that cannot be read back as missing: it logs one warning naming the
file, deletes it, and numba compiles the kernel again and writes a new file. A kernel the
file system refuses to save (full disk, read-only, file too large) stays unsaved, with one
warning per cache folder, instead of failing the run (numba raises the ``OSError``). The package of
every auvplan kernel module imports this module before defining its kernels (numba creates a
kernel's cache file object when it decorates the kernel). Files numba can read are
untouched, so a healthy cache behaves exactly as before.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

from numba.core import caching

__all__ = ["HealingCacheFile"]

logger = logging.getLogger(__name__)
#: Cache folders where saving a kernel failed (warned once).
_UNSAVED: set[Path] = set()


class HealingCacheFile(caching.IndexDataCacheFile):
    """numba's index and data files of one kernel; a damaged one is discarded (module notes)."""

    def _load_index(self) -> dict[Any, str]:
        """The index (signature → data file name); empty when the index is missing or damaged."""
        try:
            overloads: dict[Any, str] = super()._load_index()  # type: ignore[no-untyped-call]
        except OSError:
            raise  # unreadable (permissions...): not a damaged file, numba's own handling
        except Exception as error:  # noqa: BLE001 (garbage unpickles to almost any error)
            _discard(Path(self._index_path), error)
            return {}
        return overloads

    def _load_data(self, name: str) -> Any:
        """The cached compile result in data file ``name``; None when it is damaged."""
        try:
            return super()._load_data(name)  # type: ignore[no-untyped-call]
        except OSError:
            raise  # a missing data file is a cache miss in numba's ``load``
        except Exception as error:  # noqa: BLE001 (garbage unpickles to almost any error)
            _discard(Path(self._data_path(name)), error)  # type: ignore[no-untyped-call]
            return None

    def save(self, key: Any, data: Any) -> None:
        """Save a compiled kernel; one the file system refuses (full, read-only) stays unsaved."""
        try:
            super().save(key, data)  # type: ignore[no-untyped-call]
        except OSError as error:  # (numba deletes its temporary file)
            folder = Path(self._cache_path)
            if folder not in _UNSAVED:  # one line per folder, not one per kernel
                _UNSAVED.add(folder)
                logger.warning(
                    "numba cache %s: %s; kernels are compiled again by the next run",
                    folder,
                    error.strerror or error,
                )


def _discard(path: Path, error: Exception) -> None:
    """Delete the damaged cache file ``path`` with one warning naming it and ``error``."""
    logger.warning(
        "numba cache file %s is damaged (%s: %s): discarded, its kernel is compiled again",
        path,
        type(error).__name__,
        error,
    )
    path.unlink(missing_ok=True)


caching.IndexDataCacheFile = HealingCacheFile  # type: ignore[misc]
