r"""Regular grids in the local north/east frame: the one owner of index <-> world mapping.

Conventions (SPEC §0): north/east in metres from the map origin, depth positive down.
Row 0 is the southern edge, column 0 the western edge. Cell ``(row, col)`` has its centre at

.. math::

    north = origin_{north} + row \cdot \\Delta_{north}, \\qquad
    east = origin_{east} + col \cdot \\Delta_{east}.

The local frame's origin (north = east = 0) is the centre of the south-west cell of the
(windowed) bathymetry grid. No other module does index arithmetic.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from auvplan._typing import FloatArray, IntArray
from auvplan.errors import InputError
from auvplan.terrain.projection import LocalProjection


@dataclass(frozen=True)
class GridGeometry:
    """Geometry of a regular north/east grid.

    Parameters
    ----------
    n_rows, n_cols : int
        Number of rows (along north) and columns (along east).
    spacing_north, spacing_east : float
        Cell spacing [m], both > 0 (they differ on grids projected from lat/lon).
    origin_north, origin_east : float
        World coordinates [m] of the centre of cell ``(0, 0)``.

    Examples
    --------
    >>> g = GridGeometry(3, 4, 10.0, 5.0)
    >>> g.to_world(np.array([2]), np.array([1]))
    (array([20.]), array([5.]))
    >>> g.to_index(np.array([19.0]), np.array([6.0]))
    (array([2]), array([1]))
    """

    n_rows: int
    n_cols: int
    spacing_north: float
    spacing_east: float
    origin_north: float = 0.0
    origin_east: float = 0.0

    def __post_init__(self) -> None:
        if self.n_rows < 1 or self.n_cols < 1:
            raise InputError(f"grid shape must be positive, got {self.n_rows} x {self.n_cols}")
        if not (self.spacing_north > 0.0 and self.spacing_east > 0.0):
            raise InputError(
                f"grid spacing must be positive, got {self.spacing_north} x {self.spacing_east} m"
            )

    @property
    def shape(self) -> tuple[int, int]:
        """``(n_rows, n_cols)``."""
        return (self.n_rows, self.n_cols)

    @property
    def north(self) -> FloatArray:
        """Cell-centre north coordinates [m], shape ``(n_rows,)``."""
        return self.origin_north + self.spacing_north * np.arange(self.n_rows, dtype=np.float64)

    @property
    def east(self) -> FloatArray:
        """Cell-centre east coordinates [m], shape ``(n_cols,)``."""
        return self.origin_east + self.spacing_east * np.arange(self.n_cols, dtype=np.float64)

    @property
    def north_bounds(self) -> tuple[float, float]:
        """South and north edges of the grid [m] (cell edges, not centres)."""
        half = 0.5 * self.spacing_north
        return (
            self.origin_north - half,
            self.origin_north + (self.n_rows - 0.5) * self.spacing_north,
        )

    @property
    def east_bounds(self) -> tuple[float, float]:
        """West and east edges of the grid [m] (cell edges, not centres)."""
        half = 0.5 * self.spacing_east
        return (self.origin_east - half, self.origin_east + (self.n_cols - 0.5) * self.spacing_east)

    def to_world(
        self, row: IntArray | FloatArray, col: IntArray | FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """Cell indices (integer or fractional) to world ``(north, east)`` [m]."""
        north = self.origin_north + self.spacing_north * np.asarray(row, dtype=np.float64)
        east = self.origin_east + self.spacing_east * np.asarray(col, dtype=np.float64)
        return north, east

    def to_fractional_index(
        self, north: FloatArray, east: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """World ``(north, east)`` [m] to fractional ``(row, col)``; cell centres are integers."""
        row = (np.asarray(north, dtype=np.float64) - self.origin_north) / self.spacing_north
        col = (np.asarray(east, dtype=np.float64) - self.origin_east) / self.spacing_east
        return row, col

    def to_index(self, north: FloatArray, east: FloatArray) -> tuple[IntArray, IntArray]:
        """World ``(north, east)`` [m] to the index of the containing cell.

        A point outside the grid gets an out-of-range index: ``-1`` or ``n`` along the axis
        where it is outside (NaN gives ``-1``), so that far-away points (1e300 m) cast safely.
        """
        row, col = self.to_fractional_index(north, east)
        return _cell_index(row, self.n_rows), _cell_index(col, self.n_cols)

    def contains(self, north: FloatArray, east: FloatArray) -> FloatArray:
        """Boolean array, true where the point lies inside the grid's cells."""
        row, col = self.to_index(north, east)
        return np.asarray((row >= 0) & (row < self.n_rows) & (col >= 0) & (col < self.n_cols))

    def crop(self, rows: slice, cols: slice) -> GridGeometry:
        """Geometry of the sub-grid ``[rows, cols]`` (unit-step slices), same world frame."""
        r0, r1, _ = rows.indices(self.n_rows)
        c0, c1, _ = cols.indices(self.n_cols)
        north0, east0 = self.to_world(np.array(r0), np.array(c0))
        return GridGeometry(
            r1 - r0, c1 - c0, self.spacing_north, self.spacing_east, float(north0), float(east0)
        )

    def coarsen(self, r_north: int, r_east: int) -> GridGeometry:
        """Geometry of the block grid of ``r_north x r_east`` cells (remainders dropped).

        Block ``(i, j)`` covers fine rows ``i r_n … (i+1) r_n − 1``; its centre is the mean of
        those cell centres.
        """
        if r_north < 1 or r_east < 1:
            raise InputError(f"block size must be >= 1 cell, got {r_north} x {r_east}")
        n_rows, n_cols = self.n_rows // r_north, self.n_cols // r_east
        if n_rows < 1 or n_cols < 1:
            raise InputError(
                f"block {r_north} x {r_east} is larger than the grid {self.n_rows} x {self.n_cols}"
            )
        return GridGeometry(
            n_rows,
            n_cols,
            self.spacing_north * r_north,
            self.spacing_east * r_east,
            self.origin_north + 0.5 * (r_north - 1) * self.spacing_north,
            self.origin_east + 0.5 * (r_east - 1) * self.spacing_east,
        )


@dataclass(frozen=True)
class BathymetryGrid:
    """A bathymetric grid in the local frame.

    Parameters
    ----------
    depth : ndarray of shape (n_rows, n_cols)
        Depth [m], positive down. NaN marks land / no data (no-go cells).
    geometry : GridGeometry
        Cell geometry; ``geometry.shape == depth.shape``.
    projection : LocalProjection or None
        The local frame, linking north/east to lat/lon (``projection.crs`` is it as a
        :class:`pyproj.CRS`), when the source had a CRS (geographic or projected); ``None``
        for purely local grids (synthetic, metric files without a CRS).
    depth_std : ndarray of shape (n_rows, n_cols) or None
        Optional per-cell standard deviation of the depth [m].
    name : str
        Human-readable source name (file name, ``"synthetic bank (seed 7)"``).
    """

    depth: FloatArray
    geometry: GridGeometry
    projection: LocalProjection | None = None
    depth_std: FloatArray | None = None
    name: str = ""
    attributes: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.depth.ndim != 2 or self.depth.shape != self.geometry.shape:
            raise InputError(
                f"depth shape {self.depth.shape} does not match grid shape {self.geometry.shape}"
            )
        if self.depth_std is not None and self.depth_std.shape != self.depth.shape:
            raise InputError(
                f"depth_std shape {self.depth_std.shape} does not match depth {self.depth.shape}"
            )

    def window(
        self, north: tuple[float, float] | None = None, east: tuple[float, float] | None = None
    ) -> BathymetryGrid:
        """Crop to the cells whose centres lie in ``north`` x ``east`` [m] (inclusive).

        The result is re-originated so that its south-west cell centre is ``(0, 0)``; its
        projection is shifted accordingly, so geographic poses keep mapping to the same cells.
        """
        g = self.geometry
        rows = _index_range(g.north, north, "north")
        cols = _index_range(g.east, east, "east")
        sub = g.crop(rows, cols)
        shifted = GridGeometry(sub.n_rows, sub.n_cols, sub.spacing_north, sub.spacing_east)
        projection = (
            None
            if self.projection is None
            else self.projection.shifted(sub.origin_north, sub.origin_east)
        )
        std = None if self.depth_std is None else self.depth_std[rows, cols].copy()
        return BathymetryGrid(
            self.depth[rows, cols].copy(),
            shifted,
            projection,
            std,
            self.name,
            dict(self.attributes),
        )


def _cell_index(fractional: FloatArray, n_cells: int) -> IntArray:
    """``floor(fractional + 0.5)`` clipped to ``[-1, n_cells]`` (NaN -> -1), as int64."""
    index = np.clip(np.floor(fractional + 0.5), -1.0, float(n_cells))
    return np.where(np.isnan(index), -1.0, index).astype(np.int64)


def _index_range(centres: FloatArray, bounds: tuple[float, float] | None, axis: str) -> slice:
    if bounds is None:
        return slice(0, centres.size)
    low, high = float(min(bounds)), float(max(bounds))
    inside = np.flatnonzero((centres >= low) & (centres <= high))
    if inside.size < 2:
        raise InputError(
            f"window {axis} = [{low:g}, {high:g}] m keeps fewer than 2 cells of the grid "
            f"({centres[0]:g} … {centres[-1]:g} m)"
        )
    return slice(int(inside[0]), int(inside[-1]) + 1)
