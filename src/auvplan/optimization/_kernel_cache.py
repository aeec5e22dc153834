"""Generated kernel modules, cached on disk and shared by every mission and process.

:func:`load_kernel_module` writes a generated module (:mod:`~auvplan.optimization._numba_codegen`)
to ``<cache>/kernels/k_<hash>.py``, where the hash covers a key that identifies the source
(the serialised model and the generator version), the numba and Python versions, and imports
it; a cached module is found without generating its source again. numba's own cache
(``cache=True``) keeps the machine code beside it, so the compilation (tens of seconds per
vehicle type) is paid by the first mission only; later missions and processes load it in
well under a second. A model change changes the key, hence the file: a stale kernel is
never used. Files are written to a temporary name and renamed into place, so concurrent
processes never read a partial file (numba writes its cache files the same way).

A module ends with the SHA-256 of its text (:func:`_sealed`); one whose text does not match
(truncated, garbage or empty, e.g. after a full disk or a crash) is discarded with one
warning naming it and generated again. numba's files of the module's kernels (``.nbi``,
``.nbc``) live in ``__pycache__`` beside it, or under ``$NUMBA_CACHE_DIR`` when that is set;
:mod:`auvplan._numba_cache` discards and rebuilds those the same way.
"""

from __future__ import annotations

import hashlib
import importlib.util
import logging
import os
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Final

import numba

__all__ = ["cache_root", "kernel_path", "load_kernel_module"]

logger = logging.getLogger(__name__)
_LOADED: dict[str, ModuleType] = {}
#: Version of the file layout (the seal); part of every module's name.
CACHE_FORMAT: Final = 2
#: Last line of a module: this prefix and the SHA-256 (hex) of the text before it.
SEAL_PREFIX: Final = "# auvplan kernel cache seal sha256 "


def cache_root() -> Path:
    """``$AUVPLAN_CACHE_DIR``, else ``$XDG_CACHE_HOME/auvplan`` (``~/.cache/auvplan``)."""
    explicit = os.environ.get("AUVPLAN_CACHE_DIR")
    if explicit:
        return Path(explicit)
    return Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "auvplan"


def _writable(directory: Path) -> Path:
    """``directory`` (created), or a per-user temporary folder when it cannot be written."""
    try:
        directory.mkdir(parents=True, exist_ok=True)
        if os.access(directory, os.W_OK):
            return directory
    except OSError:
        pass
    fallback = Path(tempfile.gettempdir()) / f"auvplan-kernels-{os.getuid()}"
    logger.warning("kernel cache %s is not writable: using %s", directory, fallback)
    fallback.mkdir(parents=True, exist_ok=True)
    return fallback


def kernel_path(key: str, cache_dir: Path | None = None) -> Path:
    """Where the module of ``key`` lives (the name hashes the key and the toolchain)."""
    toolchain = f"numba {numba.__version__} python {sys.version_info[:2]} format {CACHE_FORMAT}"
    text = f"{key}\n# {toolchain}"
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()[:24]
    return (cache_root() / "kernels" if cache_dir is None else cache_dir) / f"k_{digest}.py"


def load_kernel_module(
    key: str, make_source: Callable[[], str], cache_dir: Path | None = None
) -> tuple[ModuleType, bool]:
    """Import the generated module identified by ``key`` from the disk cache.

    Parameters
    ----------
    key : str
        Identifies the source completely (e.g. the serialised model and the generator
        version): equal keys must give equal sources.
    make_source : callable
        Generates the source; called only when the module is not on disk yet, or damaged.
    cache_dir : Path, optional
        Folder of the modules; default ``cache_root() / "kernels"``.

    Returns
    -------
    module : ModuleType
        The imported module (kept for the process: a second call returns the same object).
    is_new : bool
        True when the module's machine code is not cached yet (its first use compiles it).
    """
    path = kernel_path(key, cache_dir)
    loaded = _LOADED.get(str(path))
    if loaded is not None:
        return loaded, False
    directory = _writable(path.parent)
    path = directory / path.name
    is_whole = _is_sealed(path)
    if not is_whole and path.exists():
        logger.warning("kernel cache file %s is damaged: generated again", path)
        path.with_suffix(".ready").unlink(missing_ok=True)
    is_new = not path.with_suffix(".ready").exists()
    if not is_whole:  # (a damaged file is replaced, never deleted: others may be reading it)
        text = _sealed(make_source())  # first: a model it refuses leaves nothing behind
        with tempfile.NamedTemporaryFile(
            "w", dir=directory, suffix=".tmp", delete=False, encoding="utf-8"
        ) as handle:
            handle.write(text)
        Path(handle.name).replace(path)
    spec = importlib.util.spec_from_file_location(f"auvplan_kernels_{path.stem}", path)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # numba's cache re-imports it by name when loading
    spec.loader.exec_module(module)
    _LOADED[str(path)] = module
    return module, is_new


def _sealed(source: str) -> str:
    """``source`` followed by its seal line (:data:`SEAL_PREFIX` and the SHA-256 of ``source``)."""
    body = source if source.endswith("\n") else source + "\n"
    return f"{body}{SEAL_PREFIX}{hashlib.sha256(body.encode('utf-8')).hexdigest()}\n"


def _is_sealed(path: Path) -> bool:
    """Whether the module at ``path`` exists and is whole: its last line seals the rest."""
    try:
        text = path.read_bytes().decode("utf-8")
    except (FileNotFoundError, UnicodeDecodeError):
        return False
    body, newline, _ = text.removesuffix("\n").rpartition("\n")
    return _sealed(body + newline) == text


def mark_compiled(module: ModuleType) -> None:
    """Record that ``module``'s machine code is in numba's cache (after its first use)."""
    ready = Path(str(module.__file__)).with_suffix(".ready")
    if not ready.exists():
        ready.touch()
