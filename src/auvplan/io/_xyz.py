"""XYZ point clouds: text columns ``lon lat z`` or ``east north z``, read defensively.

A survey may carry a few stray position fixes (a GNSS glitch logged as ``0 0 z``) far from the
soundings; gridding the whole cloud would then span the distance to the glitch. Such fixes are
dropped with a logged warning (:func:`drop_stray_fixes`). Regular lattices (gridded exports,
possibly with holes) are read as that grid exactly; other clouds are kept as points and gridded
after the conversion to the local frame.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Final, Literal

import numpy as np
from pyproj import CRS

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError
from auvplan.io._raster import Raster, first_line, looks_geographic
from auvplan.terrain.projection import GEOGRAPHIC_CRS

logger = logging.getLogger(__name__)

XyzCoordinates = Literal["auto", "geographic", "metric"]

#: A position is a stray fix when it lies farther than this many robust standard deviations
#: (1.4826 x the median absolute deviation) from the median, along either coordinate ...
STRAY_FIX_SIGMAS: Final = 10.0
#: ... and such positions are at most this fraction of the soundings (else they are kept: a
#: survey of several separate areas is not an outlier).
STRAY_FIX_MAX_FRACTION: Final = 0.01


def read_xyz(path: Path, coordinates: XyzCoordinates) -> Raster:
    """Read an XYZ text file into a lattice raster or a one-row raster of scattered points."""
    try:
        text = path.read_text(encoding="utf-8", errors="strict")
    except UnicodeDecodeError as error:
        raise DataFormatError(f"unreadable XYZ text ({first_line(error)})") from None
    table = _numeric_table(text)
    if table.shape[0] < 4:
        raise DataFormatError(f"XYZ file has {table.shape[0]} points, need at least 4")
    first, second, z = drop_stray_fixes(table[:, 0], table[:, 1], table[:, 2], path)
    if coordinates == "auto":
        is_geographic = looks_geographic(second, first)
    else:
        is_geographic = coordinates == "geographic"
    crs = CRS(GEOGRAPHIC_CRS) if is_geographic else None
    lattice = _as_lattice(first, second, z)
    if lattice is not None:
        values, east_axis, north_axis = lattice
        return Raster(values, north_axis, east_axis, crs, None)
    # Scattered points: keep them as a one-row "raster" of points, gridded after conversion.
    return Raster(z[None, :], second, first, crs, None, attributes={"scattered": "yes"})


def drop_stray_fixes(
    first: FloatArray, second: FloatArray, z: FloatArray, path: Path
) -> tuple[FloatArray, FloatArray, FloatArray]:
    r"""Drop the few points whose position lies far outside the bulk of the survey.

    Parameters
    ----------
    first, second : ndarray of shape (n_points,)
        The two position columns (any unit: the rule is scale-free).
    z : ndarray of shape (n_points,)
        The values, dropped together with their positions.
    path : Path
        The file, named in the warning.

    Returns
    -------
    tuple of ndarray
        ``(first, second, z)`` without the stray fixes.

    Notes
    -----
    Along each coordinate :math:`c`, with median :math:`\tilde c` and robust standard deviation
    :math:`\hat\sigma = 1.4826\,\mathrm{median}|c - \tilde c|`, a point is stray when
    :math:`|c - \tilde c| > 10\,\hat\sigma` (a uniform survey of width :math:`L` has
    :math:`\hat\sigma = 0.37 L` and no point beyond :math:`1.35\,\hat\sigma`). The stray points
    are dropped only when they are at most 1 % of the soundings: a larger far group is a part
    of the survey, and gridding then refuses an absurd grid size instead.
    """
    is_stray = np.zeros(first.size, dtype=bool)
    for coordinate in (first, second):
        deviation = np.abs(coordinate - np.median(coordinate))
        sigma = 1.4826 * float(np.median(deviation))
        if sigma > 0.0:
            is_stray |= deviation > STRAY_FIX_SIGMAS * sigma
    n_stray = int(is_stray.sum())
    if n_stray == 0 or n_stray > max(1, STRAY_FIX_MAX_FRACTION * first.size):
        return first, second, z
    logger.warning(
        "bathymetry %s: dropped %d of %d soundings whose position lies more than %g robust "
        "standard deviations from the median position (stray fixes)",
        path,
        n_stray,
        first.size,
        STRAY_FIX_SIGMAS,
    )
    keep = ~is_stray
    return first[keep], second[keep], z[keep]


def _numeric_table(text: str) -> FloatArray:
    """The first three columns of the data lines of an XYZ text, as floats.

    Lines before the first data line may be headers; after it, every line that is not blank
    or a ``#`` comment must hold at least three numbers. A line cut short or garbled (an
    interrupted download, a corrupted copy) is a DataFormatError naming it, not a line
    silently skipped.
    """
    rows: list[list[float]] = []
    for number, line in enumerate(text.splitlines(), start=1):
        words = line.split("#", 1)[0].replace(",", " ").split()
        if not words:
            continue
        try:
            values = [float(word) for word in words]
        except ValueError:
            if not rows:
                continue  # a header line
            raise DataFormatError(
                f"line {number} is not numeric ({line.strip()[:40]!r}): the data lines before "
                "it are numbers; a corrupted copy?"
            ) from None
        if len(values) < 3:
            raise DataFormatError(
                f"line {number} has {len(values)} column{'s' if len(values) > 1 else ''}, "
                "need 3 (lon lat z or east north z): cut short by an interrupted download or "
                "copy? fetch the file again"
            )
        rows.append(values[:3])
    return np.array(rows, dtype=np.float64).reshape(-1, 3)


def _as_lattice(
    east: FloatArray, north: FloatArray, z: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray] | None:
    """``(values, east_axis, north_axis)`` if the points lie on a regular lattice, else None."""
    axes = []
    for coordinate in (east, north):
        unique = np.unique(coordinate)
        if unique.size < 2:
            return None
        steps = np.diff(unique)
        step = float(np.median(steps))
        if np.max(np.abs(steps - step)) > 0.05 * step:
            return None
        axes.append(unique[0] + step * np.arange(unique.size))
    east_axis, north_axis = axes
    if east_axis.size * north_axis.size > 4 * z.size:
        return None  # too sparse to be a gridded export
    col = np.rint((east - east_axis[0]) / (east_axis[1] - east_axis[0])).astype(np.int64)
    row = np.rint((north - north_axis[0]) / (north_axis[1] - north_axis[0])).astype(np.int64)
    values = np.full((north_axis.size, east_axis.size), np.nan)
    values[row, col] = z
    return values, east_axis, north_axis
