"""Writing output directories all-or-nothing."""

from __future__ import annotations

import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


@contextmanager
def staged_output_dir(target: Path) -> Iterator[Path]:
    """Stage files in a temporary sibling directory and move them into ``target`` on success.

    Everything is written to the yielded staging directory. If the block raises, the staging
    directory is deleted and ``target`` is left exactly as it was (not even created), so a
    failed run never leaves half-written output. On success each staged file replaces the file
    of the same name in ``target`` (other files there are kept).

    Parameters
    ----------
    target : Path
        The output directory the user asked for.

    Yields
    ------
    Path
        The staging directory to write into.
    """
    target = Path(target)
    parent = target.parent if str(target.parent) else Path()
    parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".partial", dir=parent))
    try:
        yield staging
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    target.mkdir(parents=True, exist_ok=True)
    for entry in sorted(staging.rglob("*")):
        destination = target / entry.relative_to(staging)
        if entry.is_dir():
            destination.mkdir(parents=True, exist_ok=True)
        else:
            entry.replace(destination)
    shutil.rmtree(staging, ignore_errors=True)
