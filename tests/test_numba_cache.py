"""numba's cache files heal: every auvplan kernel's damaged ``.nbi``/``.nbc`` is rebuilt.

The damage matrix on real kernel files (truncated, garbage, empty, in fresh processes) is in
``tests/optimization/test_kernel_cache.py``; here: every compiled kernel of the package gets
the healing cache file, and a damaged index or data file is a cache miss with one warning.
"""

from __future__ import annotations

import errno
import importlib
import logging
import os
import pickle
from pathlib import Path
from typing import Any

import pytest
from numba.core import caching
from numba.core.dispatcher import Dispatcher

import auvplan
from auvplan import _numba_cache
from auvplan._numba_cache import HealingCacheFile

SOURCE_ROOT = Path(auvplan.__file__).parent


def _kernel_modules() -> list[str]:
    """The modules of the package that define ``cache=True`` numba kernels."""
    return sorted(
        ".".join(path.relative_to(SOURCE_ROOT.parent).with_suffix("").parts)
        for path in SOURCE_ROOT.rglob("*.py")
        if "njit(cache=True" in path.read_text(encoding="utf-8")
    )


def test_every_cached_kernel_of_the_package_heals() -> None:
    modules = _kernel_modules()
    assert len(modules) >= 10
    n_kernels = 0
    for name in modules:
        for value in vars(importlib.import_module(name)).values():
            cache = getattr(value, "_cache", None) if isinstance(value, Dispatcher) else None
            if cache is not None:
                assert isinstance(cache._cache_file, HealingCacheFile), (name, value)
                n_kernels += 1
    assert n_kernels >= 40


@pytest.mark.parametrize("content", [b"", b"\x80\x05\x95garbage", pickle.dumps("0.0")[:3]])
def test_a_damaged_index_or_data_file_is_a_miss_with_one_warning(
    tmp_path: Path, content: bytes, caplog: pytest.LogCaptureFixture
) -> None:
    cache_file: Any = caching.IndexDataCacheFile(tmp_path, "kernel-1.py311", "stamp")
    assert type(cache_file) is HealingCacheFile
    cache_file.save("signature", ("machine", "code"))
    assert cache_file.load("signature") == ("machine", "code")
    data = tmp_path / "kernel-1.py311.1.nbc"
    index = tmp_path / "kernel-1.py311.nbi"
    with caplog.at_level(logging.WARNING, logger="auvplan._numba_cache"):
        data.write_bytes(content)
        assert cache_file.load("signature") is None  # compiled again
        assert not data.exists()
        cache_file.save("signature", ("new", "code"))
        index.write_bytes(content)
        assert cache_file.load("signature") is None
        assert not index.exists()
        cache_file.save("signature", ("newer", "code"))
    assert cache_file.load("signature") == ("newer", "code")
    assert [record.getMessage().split(" is damaged")[0] for record in caplog.records] == [
        f"numba cache file {data}",
        f"numba cache file {index}",
    ]


def test_a_kernel_the_file_system_refuses_stays_unsaved_with_one_warning(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    def full_disk(self: HealingCacheFile, name: str, data: object) -> None:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(HealingCacheFile, "_save_data", full_disk)
    monkeypatch.setattr(_numba_cache, "_UNSAVED", set())
    cache_file: Any = caching.IndexDataCacheFile(tmp_path, "kernel-1.py311", "stamp")
    with caplog.at_level(logging.WARNING, logger="auvplan._numba_cache"):
        for key in ("one signature", "another signature"):
            cache_file.save(key, ("machine", "code"))  # (numba raised: the run failed)
            assert cache_file.load(key) is None  # compiled again by the next run
    expected = f"numba cache {tmp_path}: No space left on device; kernels are compiled again"
    assert [record.getMessage() for record in caplog.records] == [f"{expected} by the next run"]
