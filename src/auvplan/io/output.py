"""Writing outputs all-or-nothing: an output folder is replaced as a whole, or not at all.

:func:`staged_output_dir` stages a run's files in a hidden sibling folder
(``.NAME.XXXX.partial``) and, once every file is written, swaps it for the target folder:

1. the files and sub-folders already in the target that the run does not write are carried
   over into the staging folder (hard links, else copies), so **a successful run keeps unrelated
   files** and replaces only the files it writes;
2. the staging folder and the target trade names in one atomic step (Linux's
   ``renameat2(RENAME_EXCHANGE)``) and the old folder, now under the staging name, is deleted;
   where the system cannot exchange, the target is renamed aside (``.NAME.XXXX.old``) and the
   staging folder renamed into its place (the first rename undone if the second fails).

The target is checked before any work (:func:`check_output_dir`). Any failure, including
a stop request (SIGINT/SIGTERM, :mod:`auvplan.interrupts`), deletes the staging folder and any
parent folder the run created, so the file system is left exactly as it was. The two renames
and the deletion run in a :func:`~auvplan.interrupts.held` section, so a signal never cuts
them in half: at every instant the target holds either the complete old or the complete new
output (or, for the instant between the renames, nothing under its name).
:func:`staged_output_file` does the same for a single file (a figure).
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import logging
import os
import shutil
import tempfile
from collections.abc import Collection, Iterator
from contextlib import contextmanager
from pathlib import Path

from auvplan.errors import InputError
from auvplan.interrupts import checkpoint, held

logger = logging.getLogger(__name__)


def check_output_dir(target: Path) -> None:
    """Raise InputError unless ``target`` can become (or be replaced as) an output folder.

    Parameters
    ----------
    target : Path
        The output folder the user asked for; it need not exist.

    Raises
    ------
    InputError
        If ``target`` is an existing file, the current folder or one of its parents, lies
        below a file, or the process may not create it in, or rename it within, its parent
        folder. The message names ``target``.

    Examples
    --------
    >>> check_output_dir(Path("."))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    auvplan.errors.InputError: output folder . is the current folder or contains it: ...
    """
    destination = target.resolve()
    cwd = Path.cwd().resolve()
    if destination == cwd or destination in cwd.parents:
        raise InputError(
            f"output folder {target} is the current folder or contains it: "
            "choose a new or dedicated folder"
        )
    if destination.exists() and not destination.is_dir():
        raise InputError(f"output folder {target} exists and is not a folder")
    ancestor = destination.parent
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise InputError(f"output folder {target}: {ancestor} is not a folder")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise InputError(f"output folder {target}: no permission to write in {ancestor}")
    if destination.is_dir() and not os.access(destination, os.R_OK | os.W_OK | os.X_OK):
        raise InputError(f"output folder {target}: no permission to replace its content")


@contextmanager
def staged_output_dir(target: Path) -> Iterator[Path]:
    """Stage files in a temporary sibling folder and swap it for ``target`` on success.

    Everything is written to the yielded staging folder. If the block raises (or the swap
    fails), the staging folder and any parent folder created for it are deleted and ``target``
    is left exactly as it was (not even created). On success ``target`` holds the staged files
    plus the entries it had before that the run did not write (see the module notes).

    Parameters
    ----------
    target : Path
        The output folder the user asked for.

    Yields
    ------
    Path
        The staging folder to write into.

    Raises
    ------
    InputError
        If ``target`` cannot be an output folder (:func:`check_output_dir`), or it holds a
        folder where the run wrote a file (or the reverse); nothing is changed then.
    """
    target = Path(target)
    check_output_dir(target)
    destination = target.resolve()
    created = _make_parents(destination.parent)
    staging: Path | None = None
    try:
        staging = Path(
            tempfile.mkdtemp(
                prefix=f".{destination.name}.", suffix=".partial", dir=destination.parent
            )
        )
        staging.chmod(_mode_of(destination, 0o777))  # mkdtemp's 0o700 is for the staging only
        yield staging
        checkpoint()  # a stop requested while the files were written: before the swap
        if destination.exists():
            _carry_over(destination, staging, shown=target)
        _swap_in(staging, destination)
    except BaseException:
        with held():
            if staging is not None:
                shutil.rmtree(staging, ignore_errors=True)
            for folder in reversed(created[1:]):
                _remove_if_empty(folder)
        raise


def check_output_file(target: Path) -> None:
    """Raise InputError unless ``target`` names a file that can be written.

    Raises
    ------
    InputError
        If ``target`` has no file name or is an existing folder, or its folder does not exist.

    Examples
    --------
    >>> check_output_file(Path("."))
    Traceback (most recent call last):
    ...
    auvplan.errors.InputError: output file '.' is a folder, not a file name
    """
    if not target.name or target.name == ".." or target.is_dir():
        raise InputError(f"output file {str(target)!r} is a folder, not a file name")
    if not target.parent.is_dir():
        raise InputError(f"output file {target}: folder {target.parent} does not exist")


@contextmanager
def staged_output_file(target: Path) -> Iterator[Path]:
    """Write one file to a temporary sibling and rename it onto ``target`` on success.

    Parameters
    ----------
    target : Path
        The file to write; its folder must exist. The yielded path has the same suffix.

    Yields
    ------
    Path
        The temporary file to write.

    Raises
    ------
    InputError
        If ``target`` cannot be written (:func:`check_output_file`).
    """
    target = Path(target)
    check_output_file(target)
    handle, name = tempfile.mkstemp(
        prefix=f".{target.stem}.", suffix=f".partial{target.suffix}", dir=target.parent
    )
    os.close(handle)
    temporary = Path(name)
    try:
        temporary.chmod(_mode_of(target, 0o666))  # mkstemp's 0o600 is for the staging only
        yield temporary
        with held():
            temporary.replace(target)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise


def link_entries(source: Path, destination: Path, *, skip: Collection[str] = ()) -> None:
    """Hard-link every entry of folder ``source`` into folder ``destination``.

    Files are hard-linked (no copy on the same file system, else copied), sub-folders
    rebuilt the same way, symbolic links kept as links. Names in ``skip`` and hidden names
    (``.*``: the staging files of another writer) are left out. Writers replace files by
    renaming (:func:`staged_output_file`), never in place, so neither folder can change the
    other's files afterwards.
    """
    for entry in sorted(Path(source).iterdir()):
        if entry.name in skip or entry.name.startswith("."):
            continue
        if entry.is_dir() and not entry.is_symlink():
            shutil.copytree(
                entry, destination / entry.name, symlinks=True, copy_function=_link_or_copy
            )
        else:
            _link_or_copy(entry, destination / entry.name)


def _mode_of(existing: Path, default: int) -> int:
    """Permission bits of ``existing`` if it exists, else ``default`` less the process umask."""
    if existing.exists():
        return existing.stat().st_mode & 0o7777
    umask = os.umask(0)
    os.umask(umask)
    return default & ~umask


def _make_parents(folder: Path) -> list[Path]:
    """Create ``folder`` and its missing parents: ``[first existing, then those created]``."""
    missing = []
    while not folder.exists():
        missing.append(folder)
        folder = folder.parent
    made = [folder]
    try:
        for path in reversed(missing):
            path.mkdir()
            made.append(path)
    except BaseException:
        for path in reversed(made[1:]):
            _remove_if_empty(path)
        raise
    return made


def _remove_if_empty(folder: Path) -> None:
    with contextlib.suppress(OSError):  # not empty (someone else wrote there) or gone
        folder.rmdir()


def _carry_over(old: Path, new: Path, *, shown: Path) -> None:
    """Add to ``new`` every entry of ``old`` it lacks; refuse a file/folder clash."""
    for entry in sorted(old.iterdir()):
        counterpart = new / entry.name
        is_folder = entry.is_dir() and not entry.is_symlink()
        if counterpart.exists() or counterpart.is_symlink():
            if is_folder != counterpart.is_dir():
                kind, other = ("a folder", "a file") if is_folder else ("a file", "a folder")
                raise InputError(
                    f"output folder {shown}: {entry.relative_to(old.parent)} is {kind} but the "
                    f"run writes {other} of that name; move it away or choose another folder"
                )
            if is_folder:
                _carry_over(entry, counterpart, shown=shown)
        elif is_folder:
            shutil.copytree(entry, counterpart, symlinks=True, copy_function=_link_or_copy)
        else:
            _link_or_copy(entry, counterpart)


def _link_or_copy(source: str | Path, destination: str | Path) -> None:
    """Hard-link ``source`` (same file system: no copy), else copy it; links stay links."""
    source, destination = Path(source), Path(destination)
    if source.is_symlink():
        destination.symlink_to(source.readlink())
        return
    try:
        os.link(source, destination)
    except OSError:
        shutil.copy2(source, destination)


def _swap_in(staging: Path, destination: Path) -> None:
    """Put ``staging`` in the place of ``destination``, then delete the old folder.

    Where the kernel can (Linux ≥ 3.15: ``renameat2(RENAME_EXCHANGE)`` on local file systems)
    the two folders trade names in one atomic step, so ``destination`` names a complete folder
    at every instant, even if the process is killed outright. Elsewhere the old folder is
    renamed aside first and the staging folder renamed into its place (the first rename is
    undone if the second fails). An old folder that cannot be deleted is named in a warning.
    """
    with held():
        if not destination.exists():
            staging.replace(destination)
            return
        if _exchange(staging, destination):
            aside = staging
        else:
            aside = Path(
                tempfile.mkdtemp(
                    prefix=f".{destination.name}.", suffix=".old", dir=destination.parent
                )
            )
            try:
                destination.replace(aside)  # onto the empty folder mkdtemp made
            except BaseException:
                aside.rmdir()
                raise
            try:
                staging.replace(destination)
            except BaseException:
                aside.replace(destination)
                raise
        shutil.rmtree(aside, ignore_errors=True)
        if aside.exists():
            logger.warning("could not delete the previous output %s; delete it by hand", aside)


def _exchange(first: Path, second: Path) -> bool:
    """Swap the names of two paths atomically; False where the system cannot.

    Linux's ``renameat2(..., RENAME_EXCHANGE)`` through the C library (glibc ≥ 2.28, musl);
    ``EINVAL``/``ENOSYS``/``ENOTSUP`` (old kernels, file systems without it) mean "cannot".
    """
    renameat2 = getattr(ctypes.CDLL(None, use_errno=True), "renameat2", None)
    if renameat2 is None:
        return False
    renameat2.argtypes = (
        ctypes.c_int,
        ctypes.c_char_p,
        ctypes.c_int,
        ctypes.c_char_p,
        ctypes.c_uint,
    )
    renameat2.restype = ctypes.c_int
    at_cwd, exchange = -100, 2  # AT_FDCWD, RENAME_EXCHANGE from <fcntl.h>, <linux/fs.h>
    if renameat2(at_cwd, os.fsencode(first), at_cwd, os.fsencode(second), exchange) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.ENOTSUP):
        return False
    raise OSError(code, os.strerror(code), str(second))
