"""Writing a file: a full disk, a too-large file or a read-only file system is a user error.

Every writer of an output file writes inside :func:`writing`, which turns the file-system
faults a user must fix (:data:`FAULTS`: no space left, quota exceeded, file too large,
read-only file system) into one :class:`~auvplan.errors.WriteError` naming the file and the
cause. The NetCDF library reports a failed write as ``RuntimeError("NetCDF: HDF error")``
with no cause; the cause is then read from the file system (read-only, or less than
:data:`LOW_SPACE_BYTES` free) or the process's file-size limit (``RLIMIT_FSIZE``) when the
file reached it. A file written into a staging folder of
:func:`auvplan.io.output.staged_output_dir` (or :func:`~auvplan.io.output.staged_output_file`)
is named by the path the user asked for: the staging folder is deleted with the failure.
"""

from __future__ import annotations

import errno
import os
import re
import resource
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Final

from auvplan.errors import WriteError

__all__ = ["FAULTS", "LOW_SPACE_BYTES", "shown_path", "writing"]

#: ``errno`` codes of a write the user must make room or permission for.
FAULTS: Final = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS})
#: Free space [B] below which a failed NetCDF write is put down to a full disk.
LOW_SPACE_BYTES: Final = 1 << 20
#: A staging name of :mod:`auvplan.io.output`: ``.NAME.<8 random characters>.partial`` (a
#: folder) or ``.STEM.<8 random characters>.partial.SUFFIX`` (a file), as made by
#: :func:`tempfile.mkdtemp` / :func:`tempfile.mkstemp`.
_STAGING: Final = re.compile(r"\.(?P<name>.+)\.[a-z0-9_]{8}\.partial(?P<suffix>(\.[^.]+)?)")


@contextmanager
def writing(path: Path) -> Iterator[Path]:
    """Write ``path`` in the block; a file-system fault becomes a WriteError naming it.

    Parameters
    ----------
    path : Path
        The file the block writes.

    Yields
    ------
    Path
        ``path``.

    Raises
    ------
    WriteError
        If the block raises an OSError of :data:`FAULTS`, or the NetCDF library's
        ``RuntimeError("NetCDF: ...")``; the message is ``cannot write FILE: CAUSE``.

    Examples
    --------
    >>> with writing(Path("/out/.run.abcd1234.partial/maps.nc")):
    ...     raise OSError(errno.ENOSPC, "No space left on device")
    Traceback (most recent call last):
    ...
    auvplan.errors.WriteError: cannot write /out/run/maps.nc: No space left on device
    """
    try:
        yield path
    except OSError as error:
        if error.errno not in FAULTS:
            raise
        raise WriteError(f"cannot write {shown_path(path)}: {error.strerror}") from error
    except RuntimeError as error:
        if not str(error).startswith("NetCDF:"):
            raise
        cause = _netcdf_cause(path, error)
        raise WriteError(f"cannot write {shown_path(path)}: {cause}") from error


def shown_path(path: Path) -> Path:
    """``path`` with every staging folder or file name of :mod:`auvplan.io.output` undone.

    Examples
    --------
    >>> shown_path(Path("out/.run1.x7_k2p9q.partial/export/plan.gpx")).as_posix()
    'out/run1/export/plan.gpx'
    >>> shown_path(Path("figures/.paths.abcd1234.partial.png")).as_posix()
    'figures/paths.png'
    """
    parts = [
        match["name"] + match["suffix"] if (match := _STAGING.fullmatch(part)) else part
        for part in path.parts
    ]
    return Path(*parts)


def _netcdf_cause(path: Path, error: RuntimeError) -> str:
    """The cause of the NetCDF library's ``error`` writing ``path``, read from its file system."""
    try:
        stats = os.statvfs(path.parent)
    except OSError:
        return str(error)
    if stats.f_flag & os.ST_RDONLY:
        return f"{os.strerror(errno.EROFS)} ({error})"
    if stats.f_bavail * stats.f_frsize < LOW_SPACE_BYTES:
        return f"{os.strerror(errno.ENOSPC)} ({error})"
    limit = resource.getrlimit(resource.RLIMIT_FSIZE)[0]  # the process's largest file [B]
    size = path.stat().st_size if path.exists() else 0
    if limit != resource.RLIM_INFINITY and size + LOW_SPACE_BYTES >= limit:
        return f"{os.strerror(errno.EFBIG)} ({error})"
    return str(error)
