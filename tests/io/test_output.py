"""Output folders are replaced as a whole or not at all; nothing is ever left half-written."""

from __future__ import annotations

import os
import shutil
import signal
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from auvplan.errors import InputError
from auvplan.io import output
from auvplan.io.output import (
    check_output_dir,
    link_entries,
    staged_output_dir,
    staged_output_file,
)


def _tree(root: Path) -> dict[str, bytes | None]:
    """Every entry below ``root``: relative path -> file content (None for folders, links)."""
    return {
        str(path.relative_to(root)): (
            path.read_bytes() if path.is_file() and not path.is_symlink() else None
        )
        for path in sorted(root.rglob("*"))
    }


@pytest.fixture
def previous(tmp_path: Path) -> Path:
    """An output folder from an earlier run plus the user's own notes, sub-folder and link."""
    target = tmp_path / "out"
    (target / "figures").mkdir(parents=True)
    (target / "maps.nc").write_bytes(b"old maps")
    (target / "figures" / "old.png").write_bytes(b"old figure")
    (target / "notes.txt").write_text("mine")
    (target / "link").symlink_to("notes.txt")
    return target


def test_a_new_folder_gets_exactly_the_staged_files(tmp_path: Path) -> None:
    target = tmp_path / "a" / "b" / "out"
    with staged_output_dir(target) as staging:
        assert staging.parent == target.parent
        assert staging.name.startswith(".out.")
        assert staging.name.endswith(".partial")
        (staging / "maps.nc").write_bytes(b"new")
    assert sorted(p.name for p in target.iterdir()) == ["maps.nc"]
    assert sorted(p.name for p in target.parent.iterdir()) == ["out"]
    umask = os.umask(0)
    os.umask(umask)
    assert target.stat().st_mode & 0o777 == 0o777 & ~umask


def test_success_replaces_written_files_and_keeps_the_others(previous: Path) -> None:
    previous.chmod(0o750)
    with staged_output_dir(previous) as staging:
        (staging / "maps.nc").write_bytes(b"new maps")
        (staging / "figures").mkdir()
        (staging / "figures" / "new.png").write_bytes(b"new figure")
    assert _tree(previous.parent) == {
        "out": None,
        "out/figures": None,
        "out/figures/new.png": b"new figure",
        "out/figures/old.png": b"old figure",
        "out/link": None,
        "out/maps.nc": b"new maps",
        "out/notes.txt": b"mine",
    }
    assert (previous / "link").readlink() == Path("notes.txt")
    assert previous.stat().st_mode & 0o777 == 0o750


def _write(target: Path, files: dict[str, bytes | None], *, then: Callable[[], None]) -> None:
    """Stage ``files`` (None: a folder) for ``target``, then call ``then`` inside the block."""
    with staged_output_dir(target) as staging:
        for name, content in files.items():
            if content is None:
                (staging / name).mkdir()
            else:
                (staging / name).write_bytes(content)
        then()


def _boom() -> None:
    raise RuntimeError("boom")


def _nothing() -> None:
    pass


def test_a_failure_changes_nothing_and_leaves_nothing(previous: Path) -> None:
    before = _tree(previous.parent)
    with pytest.raises(RuntimeError, match="boom"):
        _write(previous, {"maps.nc": b"half"}, then=_boom)
    assert _tree(previous.parent) == before


def test_parent_folders_created_for_a_failed_run_are_removed(tmp_path: Path) -> None:
    with pytest.raises(RuntimeError), staged_output_dir(tmp_path / "x" / "y" / "out"):
        raise RuntimeError
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("make", "target", "message"),
    [
        (lambda tmp: (tmp / "mission.toml").write_text("x"), "mission.toml", "is not a folder"),
        (lambda tmp: (tmp / "file").write_text("x"), "file/sub", "file is not a folder"),
        (lambda tmp: None, ".", "is the current folder or contains it"),
        (lambda tmp: None, "..", "is the current folder or contains it"),
    ],
    ids=["existing-file", "below-a-file", "current-folder", "parent-folder"],
)
def test_bad_targets_are_refused_before_the_block_runs(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    make: object,
    target: str,
    message: str,
) -> None:
    monkeypatch.chdir(tmp_path)
    make(tmp_path)  # type: ignore[operator]
    before = _tree(tmp_path)
    with pytest.raises(InputError, match=message), staged_output_dir(Path(target)):
        pytest.fail("the block must not run")
    assert _tree(tmp_path) == before


@pytest.mark.parametrize(
    ("existing", "written"),
    [("folder", "file"), ("file", "folder")],
)
def test_a_file_folder_clash_fails_with_nothing_changed(
    previous: Path, existing: str, written: str
) -> None:
    """The issue's case: a folder named ``paths.geojson`` where the run writes that file."""
    clash = previous / "paths.geojson"
    if existing == "folder":
        clash.mkdir()
        (clash / "inside").write_text("keep")
    else:
        clash.write_text("keep")
    before = _tree(previous.parent)
    files = {"maps.nc": b"new maps", "paths.geojson": b"{}" if written == "file" else None}
    with pytest.raises(InputError, match=f"paths.geojson is a {existing} but the run writes"):
        _write(previous, files, then=_nothing)
    assert _tree(previous.parent) == before


@pytest.fixture
def no_exchange(monkeypatch: pytest.MonkeyPatch) -> None:
    """A system without an atomic exchange of two names: the swap takes two renames."""
    monkeypatch.setattr(output, "_exchange", lambda first, second: False)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="renameat2 is Linux's")
def test_the_swap_is_one_atomic_exchange_on_linux(
    previous: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The new folder takes the name in the same step the old one leaves it."""
    deleted: dict[str, bytes] = {}
    original = shutil.rmtree

    def inspect_then_delete(path: Path, **options: bool) -> None:
        deleted.update(_tree(Path(path)))
        deleted["target maps.nc"] = (previous / "maps.nc").read_bytes()
        original(path, **options)

    monkeypatch.setattr(output.shutil, "rmtree", inspect_then_delete)
    with staged_output_dir(previous) as staging:
        (staging / "maps.nc").write_bytes(b"new maps")
    assert deleted["maps.nc"] == b"old maps"  # the old folder, under the staging name
    assert deleted["target maps.nc"] == b"new maps"
    assert [name for name in _tree(previous.parent) if name.startswith(".")] == []


def test_a_failed_exchange_leaves_the_old_folder(
    previous: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    before = _tree(previous.parent)

    def failing_exchange(first: Path, second: Path) -> bool:
        raise OSError(5, "Input/output error", str(second))

    monkeypatch.setattr(output, "_exchange", failing_exchange)
    with pytest.raises(OSError, match="Input/output"), staged_output_dir(previous) as staging:
        (staging / "maps.nc").write_bytes(b"new maps")
    assert _tree(previous.parent) == before


@pytest.mark.usefixtures("no_exchange")
def test_a_failed_swap_restores_the_old_folder(
    previous: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Fault injection: renaming the staging folder into place fails after the old one moved."""
    before = _tree(previous.parent)
    original = Path.replace

    def failing_replace(self: Path, target: str | os.PathLike[str]) -> Path:
        if self.name.endswith(".partial"):
            raise PermissionError(13, "Permission denied", str(target))
        return original(self, target)

    monkeypatch.setattr(Path, "replace", failing_replace)
    with pytest.raises(PermissionError), staged_output_dir(previous) as staging:
        (staging / "maps.nc").write_bytes(b"new maps")
    assert _tree(previous.parent) == before


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write in read-only folders")
def test_an_unwritable_parent_is_refused(tmp_path: Path) -> None:
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    try:
        with pytest.raises(InputError, match="no permission to write in"):
            check_output_dir(locked / "out")
    finally:
        locked.chmod(0o755)


@pytest.fixture
def sigterm_raises() -> Iterator[None]:
    """SIGTERM raises SystemExit(143) (what the command line installs, in miniature)."""

    def terminate(signum: int, _frame: object) -> None:
        raise SystemExit(128 + signum)

    previous = signal.signal(signal.SIGTERM, terminate)
    yield
    signal.signal(signal.SIGTERM, previous)


@pytest.mark.usefixtures("sigterm_raises")
def test_sigterm_while_writing_cleans_up(previous: Path) -> None:
    before = _tree(previous.parent)
    with pytest.raises(SystemExit, match="143"):
        _write(previous, {"maps.nc": b"half"}, then=lambda: os.kill(os.getpid(), signal.SIGTERM))
    assert _tree(previous.parent) == before


@pytest.mark.usefixtures("sigterm_raises", "no_exchange")
def test_a_signal_during_the_swap_waits_until_it_is_complete(
    previous: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """SIGTERM arriving between the two renames is delivered only after the swap."""
    original = Path.replace

    def replace_then_signal(self: Path, target: str | os.PathLike[str]) -> Path:
        moved = original(self, target)
        if Path(target).name.endswith(".old"):  # the old folder is aside, the new not yet in
            os.kill(os.getpid(), signal.SIGTERM)
        return moved

    monkeypatch.setattr(Path, "replace", replace_then_signal)
    with pytest.raises(SystemExit), staged_output_dir(previous) as staging:
        (staging / "maps.nc").write_bytes(b"new maps")
    tree = _tree(previous.parent)
    assert tree["out/maps.nc"] == b"new maps"
    assert tree["out/notes.txt"] == b"mine"
    assert [name for name in tree if name.startswith(".")] == []


def test_staged_output_file_is_all_or_nothing(tmp_path: Path) -> None:
    target = tmp_path / "figure.png"

    def write_half() -> None:
        with staged_output_file(target) as staging:
            staging.write_bytes(b"half")
            raise RuntimeError

    with pytest.raises(RuntimeError):
        write_half()
    assert list(tmp_path.iterdir()) == []
    with staged_output_file(target) as staging:
        assert staging.suffix == ".png"
        staging.write_bytes(b"png")
    assert [p.name for p in tmp_path.iterdir()] == ["figure.png"]
    assert target.read_bytes() == b"png"
    with pytest.raises(InputError, match="is a folder, not a file name"):
        output.check_output_file(tmp_path)


def test_link_entries_hard_links_all_but_skipped_and_hidden(tmp_path: Path) -> None:
    source, destination = tmp_path / "source", tmp_path / "destination"
    (source / "figures").mkdir(parents=True)
    (source / "plan.csv").write_text("t,x\n0,1\n")
    (source / "figures" / "map.png").write_bytes(b"png")
    (source / "navigation.json").write_text("{}")
    (source / ".plan.abc.partial.csv").write_text("half")
    (source / "latest").symlink_to("plan.csv")
    destination.mkdir()
    link_entries(source, destination, skip={"navigation.json"})
    assert _tree(destination) == {
        "figures": None, "figures/map.png": b"png", "latest": None, "plan.csv": b"t,x\n0,1\n",
    }  # fmt: skip
    assert (destination / "plan.csv").samefile(source / "plan.csv")
    assert (destination / "figures" / "map.png").samefile(source / "figures" / "map.png")
    assert (destination / "latest").readlink() == Path("plan.csv")
    with staged_output_file(source / "plan.csv") as staging:  # a writer replaces, not edits
        staging.write_text("t,x\n0,2\n")
    assert (destination / "plan.csv").read_text() == "t,x\n0,1\n"
