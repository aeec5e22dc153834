"""Reading user text files defensively: one place that turns every way of failing into one line.

Vehicle files, propeller tables and mission files are text written by people. Whatever goes
wrong while reading one (missing, a folder, unreadable, not UTF-8, not TOML, nested deeper than
the parser's recursion allows, an integer literal longer than Python converts) becomes a
:class:`~auvplan.errors.DataFormatError` whose one-line message names what the file is meant to
be and where it is, e.g. ``vehicle file boat.toml: not UTF-8 text (byte 0xff at offset 9)``.
"""

from __future__ import annotations

import hashlib
import json
import tomllib
from collections.abc import Mapping
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Any

from auvplan.errors import DataFormatError
from auvplan.io.writing import writing


def read_bytes(path: Path | Traversable, *, what: str) -> bytes:
    """The bytes of a file; a missing, unreadable file or a folder is one line naming it.

    Raises
    ------
    DataFormatError
        If the file is missing, a folder or unreadable; the message names ``what`` and the
        file.
    """
    try:
        return path.read_bytes()
    except FileNotFoundError:
        raise DataFormatError(f"{what} {path}: file not found") from None
    except IsADirectoryError:
        raise DataFormatError(f"{what} {path}: is a folder, not a file") from None
    except OSError as error:
        raise DataFormatError(f"{what} {path}: cannot read ({error.strerror or error})") from None


def read_text(path: Path | Traversable, *, what: str) -> str:
    """The content of a UTF-8 text file (a leading byte-order mark is dropped).

    Parameters
    ----------
    path : Path or Traversable
        The file (a path or a packaged resource).
    what : str
        What the file is meant to be, for messages (``"vehicle file"``).

    Returns
    -------
    str
        The decoded text.

    Raises
    ------
    DataFormatError
        If the file is missing, a folder, unreadable, or not UTF-8; the message names ``what``
        and the file.

    Examples
    --------
    >>> read_text(Path("no/such/file.toml"), what="vehicle file")
    Traceback (most recent call last):
    ...
    auvplan.errors.DataFormatError: vehicle file no/such/file.toml: file not found
    """
    data = read_bytes(path, what=what)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise DataFormatError(
            f"{what} {path}: not UTF-8 text (byte 0x{data[error.start]:02x} at offset "
            f"{error.start}); save it as UTF-8"
        ) from None


def read_toml(path: Path | Traversable, *, what: str) -> dict[str, Any]:
    """The document of a TOML file, read with :func:`read_text` and parsed by :mod:`tomllib`.

    Parameters
    ----------
    path, what
        As for :func:`read_text` (e.g. ``what="mission file"``).

    Returns
    -------
    dict
        The parsed document (tables are dicts, arrays are lists).

    Raises
    ------
    DataFormatError
        If the file cannot be read as text (see :func:`read_text`), is not valid TOML, nests
        arrays or tables deeper than the parser can follow, or holds an integer with more
        digits than Python converts; the message names ``what``, the file and the cause.
    """
    text = read_text(path, what=what)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise DataFormatError(f"{what} {path}: not valid TOML ({error})") from None
    except RecursionError:
        raise DataFormatError(
            f"{what} {path}: not valid TOML (arrays or tables nested too deeply)"
        ) from None
    except ValueError as error:  # e.g. an integer literal beyond sys.get_int_max_str_digits()
        raise DataFormatError(f"{what} {path}: not valid TOML ({error})") from None


def read_json(path: Path, *, what: str) -> Any:
    """The document of a JSON file, read with :func:`read_text`.

    Raises
    ------
    DataFormatError
        If the file cannot be read as text or is not valid JSON (names ``what`` and the file).
    """
    text = read_text(path, what=what)
    try:
        return json.loads(text)
    except (ValueError, RecursionError) as error:
        raise DataFormatError(f"{what} {path}: not valid JSON ({error})") from None


def toml_text(document: Mapping[str, Any], *, header: str = "") -> str:
    """``document`` (plain TOML values: no ``None``) as TOML text (tomli-w).

    ``header`` lines come first, as ``#`` comments.

    Examples
    --------
    >>> print(toml_text({"fleet": {"horizon_s": 60.0}}, header="a mission"), end="")
    # a mission
    [fleet]
    horizon_s = 60.0
    """
    import tomli_w

    comments = "".join(f"# {line}\n" for line in header.splitlines())
    return comments + tomli_w.dumps(document)


def write_toml(document: Mapping[str, Any], path: Path, *, header: str = "") -> None:
    """Write ``document`` as a UTF-8 TOML file (:func:`toml_text`)."""
    with writing(path):
        path.write_text(toml_text(document, header=header), encoding="utf-8")


def file_sha256(path: Path | Traversable) -> str:
    """The SHA-256 digest of a file's bytes, as 64 hexadecimal digits.

    Examples
    --------
    >>> from importlib import resources
    >>> len(file_sha256(resources.files("auvplan") / "data/vehicles/medusa.toml"))
    64
    """
    digest = hashlib.sha256()
    with path.open("rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


__all__ = [
    "file_sha256",
    "read_bytes",
    "read_json",
    "read_text",
    "read_toml",
    "toml_text",
    "write_toml",
]
