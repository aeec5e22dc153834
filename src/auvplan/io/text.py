"""Reading text and TOML files defensively: every failure is one line naming the file."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

from auvplan.errors import DataFormatError


def read_text(path: Path, *, what: str) -> str:
    """The UTF-8 text of ``path``; ``what`` names the file's role in error messages.

    Raises
    ------
    DataFormatError
        Missing, unreadable or not UTF-8.
    """
    try:
        return Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise DataFormatError(f"{what} not found: {path}") from None
    except UnicodeDecodeError as error:
        raise DataFormatError(
            f"{what} {path} is not UTF-8 text (byte {error.start}: {error.reason})"
        ) from None
    except OSError as error:
        raise DataFormatError(f"cannot read {what} {path}: {error.strerror}") from None


def read_toml(path: Path, *, what: str) -> dict[str, Any]:
    """The TOML document in ``path`` (see :func:`read_text`; also invalid or too-deep TOML)."""
    text = read_text(path, what=what)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise DataFormatError(f"{Path(path).name}: not valid TOML ({error})") from None
    except RecursionError:
        raise DataFormatError(f"{Path(path).name}: not valid TOML (nested too deeply)") from None


__all__ = ["read_text", "read_toml"]
