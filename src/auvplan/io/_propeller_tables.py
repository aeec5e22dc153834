"""Four-quadrant propeller tables: packaged CSVs and user files of Fourier coefficients.

A propeller table is a CSV with ``#`` comment lines (the first five form the citation), a
header ``k,A_T,B_T,A_Q,B_Q`` and one row per harmonic ``k = 0..K``.
"""

from __future__ import annotations

from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.io.text import read_text
from auvplan.vehicle.params import PropellerParams

PROPELLER_COLUMNS: Final = ("k", "A_T", "B_T", "A_Q", "B_Q")

#: Largest magnitude of a Fourier coefficient of C_T* or C_Q* (published series stay below 2).
_MAX_PROPELLER_COEFFICIENT: Final = 10.0


def data_dir(kind: str) -> Traversable:
    """The packaged data folder ``auvplan/data/<kind>``."""
    return resources.files("auvplan").joinpath("data", kind)


def packaged_propeller_tables() -> tuple[str, ...]:
    """Names of the propeller tables shipped with auvplan.

    Examples
    --------
    >>> packaged_propeller_tables()
    ('wageningen_b4-70_pd1.4',)
    """
    return tuple(
        sorted(
            entry.name.removesuffix(".csv")
            for entry in data_dir("propellers").iterdir()
            if entry.name.endswith(".csv")
        )
    )


def _parse_propeller_table(text: str, origin: str) -> tuple[FloatArray, FloatArray]:
    rows = [
        line.strip()
        for line in text.splitlines()
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not rows or tuple(c.strip() for c in rows[0].split(",")) != PROPELLER_COLUMNS:
        raise DataFormatError(
            f"propeller table {origin}: header must be {','.join(PROPELLER_COLUMNS)}"
        )
    try:
        table = np.array([[float(v) for v in row.split(",")] for row in rows[1:]], dtype=float)
    except ValueError as error:
        raise DataFormatError(f"propeller table {origin}: {error}") from None
    if table.ndim != 2 or table.shape[1] != len(PROPELLER_COLUMNS) or table.shape[0] < 2:
        raise DataFormatError(f"propeller table {origin}: needs rows k,A_T,B_T,A_Q,B_Q for k=0..K")
    if not np.array_equal(table[:, 0], np.arange(table.shape[0])):
        raise DataFormatError(f"propeller table {origin}: k must run 0, 1, 2, ... without gaps")
    if not np.all(np.isfinite(table)):
        raise DataFormatError(f"propeller table {origin}: non-finite coefficient")
    if np.max(np.abs(table[:, 1:])) > _MAX_PROPELLER_COEFFICIENT:
        raise DataFormatError(
            f"propeller table {origin}: coefficient {np.max(np.abs(table[:, 1:])):g} beyond "
            f"±{_MAX_PROPELLER_COEFFICIENT:g} (C_T*, C_Q* are of order 1)"
        )
    return table[:, 0], table[:, 1:]


def propeller_table_file(table: str | Path, base_dir: Path | None = None) -> Path | None:
    """The CSV file a vehicle file's ``table`` names (``None``: a packaged table).

    A relative path is taken from ``base_dir`` (the vehicle file's folder), when given.

    Examples
    --------
    >>> propeller_table_file("wageningen_b4-70_pd1.4") is None
    True
    >>> propeller_table_file("props/mine.csv", Path("boats"))
    PosixPath('boats/props/mine.csv')
    """
    if str(table) in packaged_propeller_tables():
        return None
    path = Path(table)
    return path if path.is_absolute() or base_dir is None else base_dir / path


def load_propeller_table(
    table: str | Path,
    *,
    diameter: float,
    c_T: float = 1.0,
    c_Q: float = 1.0,
    order: int | None = None,
    base_dir: Path | None = None,
) -> PropellerParams:
    """Read a four-quadrant propeller table (packaged name or CSV path).

    Parameters
    ----------
    table : str or Path
        A packaged table name (see :func:`packaged_propeller_tables`) or a CSV path.
    diameter : float
        Propeller diameter [m].
    c_T, c_Q : float
        Thrust and torque correction factors [-].
    order : int, optional
        Harmonics used by default (``None``: all).
    base_dir : Path, optional
        Directory that relative paths are resolved against.

    Returns
    -------
    PropellerParams

    Raises
    ------
    InputError
        If the table is neither packaged nor an existing file.
    DataFormatError
        If the file does not have the expected layout.

    Examples
    --------
    >>> load_propeller_table("wageningen_b4-70_pd1.4", diameter=0.057).max_order
    30
    """
    name = str(table)
    path = propeller_table_file(table, base_dir)
    if path is None:
        text = read_text(data_dir("propellers").joinpath(f"{name}.csv"), what="propeller table")
        source = f"packaged table {name}"
    else:
        if not path.is_file():
            raise InputError(
                f"propeller table {name!r} is neither packaged "
                f"({', '.join(packaged_propeller_tables())}) nor an existing file"
            )
        text = read_text(path, what="propeller table")
        name = path.stem
        source = str(path)
    _, coefficients = _parse_propeller_table(text, name)
    comments = [line[1:].strip() for line in text.splitlines() if line.startswith("#")]
    citation = " ".join(comments[:5]) if comments else source
    return PropellerParams(
        name=name,
        source=citation,
        diameter=diameter,
        c_T=c_T,
        c_Q=c_Q,
        A_T=coefficients[:, 0],
        B_T=coefficients[:, 1],
        A_Q=coefficients[:, 2],
        B_Q=coefficients[:, 3],
        order=order,
    )


__all__ = [
    "PROPELLER_COLUMNS",
    "data_dir",
    "load_propeller_table",
    "packaged_propeller_tables",
    "propeller_table_file",
]
