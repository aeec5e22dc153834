"""The disk cache of generated kernel modules: written once, shared by processes, safe.

Fresh processes (``subprocess`` with the worktree's ``src`` on ``PYTHONPATH``) show what a
later mission sees: a cached module is neither generated nor compiled again (numba loads the
machine code of every kernel). Every other test has its own cache folder.
"""

from __future__ import annotations

import importlib
import json
import logging
import os
import shutil
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

import casadi as ca
import numpy as np
import pytest

import auvplan
from auvplan.optimization import BlockKernels, _kernel_cache, block_kernels
from auvplan.optimization._kernel_cache import cache_root, kernel_path, load_kernel_module
from auvplan.optimization._numba_codegen import UnsupportedOperation

from ._kernel_models import pendulum

kernel_module = importlib.import_module("auvplan.optimization.block_kernels")
SLOW = pytest.mark.slow

#: A fresh process: the pendulum kernels (``g = argv[2]``) from the cache ``argv[1]`` at the
#: point ``argv[3]`` (JSON); reports whether the module was generated or compiled, and results.
LATER_PROCESS = """
import importlib, json, sys
from pathlib import Path
import numpy as np
sys.path.insert(0, {helpers!r})
from _kernel_models import pendulum
kernel_module = importlib.import_module("auvplan.optimization.block_kernels")
report = {{"generated": 0, "is_new": []}}
load = kernel_module.load_kernel_module
def counting_load(key, make_source, cache_dir=None):
    def source():
        report["generated"] += 1
        return make_source()
    module, is_new = load(key, source, cache_dir)
    report["is_new"].append(is_new)
    return module, is_new
kernel_module.load_kernel_module = counting_load
kernels = kernel_module.block_kernels(*pendulum(float(sys.argv[2])), Path(sys.argv[1]))
dispatchers = [getattr(kernels.module, name) for name in
               ("value_batch", "forward_batch", "reverse_batch", "closed_loop_batch")]
report["compiled"] = sum(d.stats.cache_misses.total() for d in dispatchers)
report["loaded"] = sum(d.stats.cache_hits.total() for d in dispatchers)
report["file"] = kernels.module.__file__
x, u, p, w, costate = (np.array(a) for a in json.loads(sys.argv[3]))
report["step"] = kernels.step(x, u, p, w, 0.1, 2)[0].tolist()
report["hessian"] = kernels.hessian(x, u, p, w, 0.1, 2, costate).tolist()
print(json.dumps(report))
"""
#: One of several processes loading the same small module into the empty cache ``argv[1]``
#: at the same moment: each announces itself (``ready-<argv[2]>`` beside the cache), waits
#: for ``go``, then generates the source slowly, so that every process finds it missing.
RACING_PROCESS = """
import json, sys, time
from pathlib import Path
from auvplan.optimization._kernel_cache import load_kernel_module, mark_compiled
cache = Path(sys.argv[1])
SOURCE = "import numba\\n@numba.njit(cache=True)\\ndef triple(a):\\n    return 3.0 * a + 0.25\\n"
generated = []
def slow_source():
    generated.append(True)
    time.sleep(1.0)
    return SOURCE
(cache.parent / ("ready-" + sys.argv[2])).touch()
while not (cache.parent / "go").exists():
    time.sleep(0.01)
module, is_new = load_kernel_module("racing module", slow_source, cache)
value = module.triple(1.5)
mark_compiled(module)
print(json.dumps({"is_new": is_new, "generated": bool(generated), "value": value,
                  "file": module.__file__}))
"""


def _start(script: str, *arguments: str) -> subprocess.Popen[str]:
    """A fresh Python process running ``script`` with the worktree's sources."""
    env = {**os.environ, "PYTHONPATH": str(Path(auvplan.__file__).parents[1])}
    return subprocess.Popen(
        [sys.executable, "-c", script, *arguments],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )


def _report(process: subprocess.Popen[str]) -> dict[str, Any]:
    """The JSON report a process prints last (it must succeed)."""
    stdout, stderr = process.communicate(timeout=300)
    assert process.returncode == 0, stderr
    report: dict[str, Any] = json.loads(stdout.strip().splitlines()[-1])
    return report


def _files(cache: Path, stem: str) -> dict[str, int]:
    """The files of module ``stem`` (with numba's) and their modification times [ns]."""
    return {
        str(path.relative_to(cache)): path.stat().st_mtime_ns
        for path in cache.rglob(f"{stem}*")
        if path.is_file()
    }


def test_a_later_process_loads_the_module_without_generating_or_compiling(
    kernel_cache: Path,
) -> None:
    # a model of this test only: no other test (worker) writes its files meanwhile
    kernels = block_kernels(*pendulum(8.0), kernel_cache)
    module = Path(str(kernels.module.__file__))
    assert module.with_suffix(".ready").exists()
    written = _files(kernel_cache, module.stem)
    assert any(name.endswith(".nbc") for name in written)  # numba's machine code beside it
    x, u = np.array([[0.3, -0.2], [1.0, 0.5]]), np.array([[0.4], [-0.1]])
    p, w = np.zeros((2, 1)), np.array([[1.0, 0.5], [2.0, 0.1]])
    costate = np.array([[1.0, -2.0], [0.5, 0.3]])
    point = json.dumps([a.tolist() for a in (x, u, p, w, costate)])

    script = LATER_PROCESS.format(helpers=str(Path(__file__).parent))
    later = _report(_start(script, str(kernel_cache), "8.0", point))
    assert later["file"] == str(module)
    assert later["is_new"] == [False]
    assert later["generated"] == 0  # the source is not generated again
    assert later["compiled"] == 0  # nor compiled: every kernel's machine code is loaded
    assert later["loaded"] == 4
    assert _files(kernel_cache, module.stem) == written  # nothing rewritten
    np.testing.assert_array_equal(later["step"], kernels.step(x, u, p, w, 0.1, 2)[0])
    np.testing.assert_array_equal(later["hessian"], kernels.hessian(x, u, p, w, 0.1, 2, costate))


def test_processes_racing_on_an_empty_cache_leave_one_intact_module(tmp_path: Path) -> None:
    cache = tmp_path / "kernels"
    processes = [_start(RACING_PROCESS, str(cache), str(i)) for i in range(2)]
    deadline = time.monotonic() + 120.0
    while not all((tmp_path / f"ready-{i}").exists() for i in range(2)):
        assert time.monotonic() < deadline, "the racing processes did not start"
        assert all(process.poll() is None for process in processes), "a process failed"
        time.sleep(0.02)
    (tmp_path / "go").touch()
    reports = [_report(process) for process in processes]

    assert all(report["is_new"] and report["generated"] for report in reports)  # a real race
    assert {report["value"] for report in reports} == {4.75}
    modules = list(cache.glob("k_*.py"))
    assert len(modules) == 1
    assert {report["file"] for report in reports} == {str(modules[0])}
    assert modules[0].with_suffix(".ready").exists()
    assert not list(cache.glob("*.tmp"))  # every temporary file was renamed into place
    assert "def triple(a):" in modules[0].read_text(encoding="utf-8")
    later = _report(_start(RACING_PROCESS, str(cache), "later"))
    assert later == {**reports[0], "is_new": False, "generated": False}


@pytest.fixture
def without_warm_up(monkeypatch: pytest.MonkeyPatch) -> None:
    """Skip compiling every kernel (these tests look at the files and one kernel)."""
    monkeypatch.setattr(kernel_module, "_warm_up", lambda kernels: None)


def _rate(kernels: BlockKernels, x: np.ndarray, u: np.ndarray) -> np.ndarray:
    """``f`` of the pendulum kernels at one point (compiles the ``value`` kernel only)."""
    rate, cost = np.empty((1, 2)), np.empty((1, 1))
    kernels.module.value_batch(x[None], u[None], np.zeros((1, 1)), np.ones((1, 2)), rate, cost)
    return rate[0]


def _pendulum_rate(gravity: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
    return np.asarray(pendulum(gravity)[0](x, u, 0.0)).ravel()


@pytest.mark.usefixtures("without_warm_up")
def test_a_changed_model_gets_its_own_module(tmp_path: Path) -> None:
    x, u = np.array([0.4, -0.3]), np.array([0.2])
    weak, strong = (block_kernels(*pendulum(g), tmp_path) for g in (3.0, 5.0))
    assert weak.module.__file__ != strong.module.__file__
    assert len(list(tmp_path.glob("k_*.py"))) == 2
    for kernels, gravity in ((weak, 3.0), (strong, 5.0)):
        np.testing.assert_allclose(_rate(kernels, x, u), _pendulum_rate(gravity, x, u), 1e-14)
    assert block_kernels(*pendulum(3.0), tmp_path) is weak  # built once per process


def _expect_fallback(
    cache: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """``cache`` cannot be written: the module goes to the (isolated) temporary folder."""
    temporary = tmp_path / "tmp"
    temporary.mkdir()
    monkeypatch.setattr("tempfile.tempdir", str(temporary))
    with caplog.at_level(logging.WARNING, logger="auvplan.optimization._kernel_cache"):
        kernels = block_kernels(*pendulum(4.0), cache)
    assert f"kernel cache {cache} is not writable" in caplog.text
    fallback = temporary / f"auvplan-kernels-{os.getuid()}"
    assert Path(str(kernels.module.__file__)).parent == fallback
    assert len(list(fallback.glob("k_*.py"))) == 1
    x, u = np.array([0.1, 0.2]), np.array([-0.3])
    np.testing.assert_allclose(_rate(kernels, x, u), _pendulum_rate(4.0, x, u), 1e-14)


@pytest.mark.usefixtures("without_warm_up")
@pytest.mark.skipif(os.geteuid() == 0, reason="root ignores directory permissions")
def test_an_unwritable_cache_falls_back_to_the_temporary_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        _expect_fallback(locked, tmp_path, monkeypatch, caplog)
        assert not list(locked.iterdir())
    finally:
        locked.chmod(0o700)


@pytest.mark.usefixtures("without_warm_up")
def test_a_cache_that_cannot_be_created_falls_back_to_the_temporary_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    blocker = tmp_path / "file"  # (works as root too, unlike permissions)
    blocker.write_text("not a folder", encoding="utf-8")
    _expect_fallback(blocker / "kernels", tmp_path, monkeypatch, caplog)


def test_an_untranslatable_model_leaves_nothing_in_the_cache(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    x, u, p, w = ca.SX.sym("x", 1), ca.SX.sym("u", 1), ca.SX.sym("p", 0), ca.SX.sym("w", 0)
    dynamics = ca.Function("f", [x, u, p], [ca.erfinv(0.5 * ca.tanh(x)) + u])
    cost = ca.Function("l", [x, u, p, w], [x**2 + u**2])
    with pytest.raises(UnsupportedOperation, match="not translated"):
        block_kernels(dynamics, cost, tmp_path / "untranslated")
    monkeypatch.setattr(kernel_module, "MAX_KERNEL_INSTRUCTIONS", 10)
    with pytest.raises(UnsupportedOperation, match="instructions"):
        block_kernels(*pendulum(6.0), tmp_path / "too large")
    assert not [path for path in tmp_path.rglob("*") if path.is_file()]


def test_cache_root_and_module_names(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("AUVPLAN_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache_root() == tmp_path / "xdg" / "auvplan"
    assert kernel_path("key").parent == tmp_path / "xdg" / "auvplan" / "kernels"
    monkeypatch.setenv("AUVPLAN_CACHE_DIR", str(tmp_path / "explicit"))
    assert kernel_path("key").parent == tmp_path / "explicit" / "kernels"
    assert kernel_path("key", tmp_path / "mine").parent == tmp_path / "mine"
    assert kernel_path("key") == kernel_path("key") != kernel_path("another key")


#: How a cache file is damaged: its first half (a full disk), bytes that mean nothing, nothing.
DAMAGES: dict[str, Callable[[bytes], bytes]] = {
    "truncated": lambda content: content[: len(content) // 2],
    "garbage": lambda content: np.random.default_rng(28).bytes(max(len(content), 64)),
    "empty": lambda content: b"",
}
TRIPLE = "import numba\n@numba.njit(cache=True)\ndef triple(a):\n    return 3.0 * a + 0.25\n"


@pytest.mark.parametrize("damage", DAMAGES)
def test_a_damaged_module_is_generated_again_with_one_warning(
    damage: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    generated: list[bool] = []

    def source() -> str:
        generated.append(True)
        return TRIPLE

    def load() -> ModuleType:
        monkeypatch.setattr(_kernel_cache, "_LOADED", {})  # as a later process
        return load_kernel_module("tripling", source, tmp_path)[0]

    path = Path(str(load().__file__))
    path.write_bytes(DAMAGES[damage](path.read_bytes()))
    with caplog.at_level(logging.WARNING, logger="auvplan.optimization._kernel_cache"):
        module = load()
        assert [record.getMessage() for record in caplog.records] == [
            f"kernel cache file {path} is damaged: generated again"
        ]
        caplog.clear()
        assert load().triple is not None  # the rebuilt module is whole: no warning
    assert module.triple.py_func(1.5) == 4.75
    assert caplog.records == []
    assert len(generated) == 2
    assert list(tmp_path.glob("k_*")) == [path]
    assert not list(tmp_path.glob("*.tmp"))  # the new module was renamed into place


#: Cache files of the pendulum kernel ``value_batch`` (a kernel called from Python).
KERNEL_FILES: dict[str, Callable[[Path], Path]] = {
    "module": lambda module: module,
    "nbi": lambda module: _only(module.parent, f"__pycache__/{module.stem}.value_batch-*.nbi"),
    "nbc": lambda module: _only(module.parent, f"__pycache__/{module.stem}.value_batch-*.nbc"),
}
HEALING_GRAVITY = "2.5"  # a model of these tests only


def _only(folder: Path, pattern: str) -> Path:
    (path,) = folder.glob(pattern)
    return path


@pytest.fixture(scope="module")
def pendulum_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A kernel folder holding the compiled pendulum kernels (numba's files beside them)."""
    cache = tmp_path_factory.mktemp("healing") / "kernels"
    block_kernels(*pendulum(float(HEALING_GRAVITY)), cache)
    return cache


def _later_run(cache: Path, point: str) -> tuple[dict[str, Any], list[str]]:
    """A fresh process loading the pendulum kernels from ``cache``: its report and stderr."""
    script = LATER_PROCESS.format(helpers=str(Path(__file__).parent))
    process = _start(script, str(cache), HEALING_GRAVITY, point)
    stdout, stderr = process.communicate(timeout=300)
    assert process.returncode == 0, stderr  # no traceback
    return json.loads(stdout.strip().splitlines()[-1]), stderr.splitlines()


@pytest.mark.parametrize(
    ("kind", "damage"),
    [
        pytest.param(kind, damage, marks=[] if (kind, damage) == ("nbc", "truncated") else [SLOW])
        for kind in KERNEL_FILES
        for damage in DAMAGES
    ],
)
def test_a_damaged_cache_file_is_rebuilt_and_the_next_run_is_clean(
    kind: str, damage: str, pendulum_cache: Path, tmp_path: Path
) -> None:
    cache = tmp_path / "kernels"
    shutil.copytree(pendulum_cache, cache)  # (copy2 keeps the times numba compares)
    module = _only(cache, "k_*.py")
    damaged = KERNEL_FILES[kind](module)
    damaged.write_bytes(DAMAGES[damage](damaged.read_bytes()))
    point = json.dumps([[[0.3, -0.2]], [[0.4]], [[0.0]], [[1.0, 0.5]], [[1.0, -2.0]]])

    first, warnings = _later_run(cache, point)
    assert len(warnings) == 1  # one line
    assert f"{damaged} is damaged" in warnings[0]
    assert first["generated"] == (kind == "module")
    second, silence = _later_run(cache, point)
    assert silence == []
    assert (second["generated"], second["compiled"], second["loaded"]) == (0, 0, 4)
    assert second["step"] == first["step"]
    assert second["hessian"] == first["hessian"]
