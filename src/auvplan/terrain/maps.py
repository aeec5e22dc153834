r"""Terrain-information maps of the paper's Sec. III-A (eqs. 13–15).

From a bathymetric grid :math:`M_B` to the cost map the A* pre-planner searches:

1. information map (eq. 13) :math:`M_I = (|\nabla M_B| / \max |\nabla M_B|)^s`,
2. excitation map (eq. 14) :math:`M_E`: block mean of :math:`M_I` over
   :math:`r_n \times r_e` cells,
3. cost map :math:`M_C = \cos(\tfrac{\pi}{2} M_E)` and the shifted cost (eq. 15)
   :math:`\tilde M_C = \omega + w M_C`.

NaN cells (land, no data) stay NaN in every map: they are no-go cells downstream.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.terrain.grid import BathymetryGrid, GridGeometry

#: Range of the information exponent s (eq. 13): beyond it M_I is all 0 or all 1 in practice.
MIN_EXPONENT: Final = 0.01
MAX_EXPONENT: Final = 100.0
#: Upper bound of the cost shift omega and the cost weight w (eq. 15).
MAX_COST_TERM: Final = 1e6


@dataclass(frozen=True)
class MapParameters:
    r"""Parameters of the terrain-information maps (paper eqs. 13–15).

    Parameters
    ----------
    exponent : float
        Exponent :math:`s` of the information map (eq. 13), in [0.01, 100]; 1 in the paper.
    block : tuple of int
        Block size :math:`(r_n, r_e)` in cells (north, east) of the excitation map (eq. 14),
        both >= 1.
    omega : float
        Shift :math:`\omega` of the cost map (eq. 15), in (0, 1e6]. The paper's Euclidean A*
        heuristic needs :math:`\omega \ge \sqrt 2` to be admissible; that is a property of
        that heuristic, not of the map, so smaller positive values are accepted here. Paper
        figure: 10.
    weight : float
        Weight :math:`w` of the cost map in the shifted cost (eq. 15), in [0, 1e6]; 10 in the
        paper. The bounds on :math:`\omega` and :math:`w` keep path costs (sums of
        :math:`\omega + w M_C` over up to millions of cells) far from overflow.

    Raises
    ------
    InputError
        If a value is out of range.

    Examples
    --------
    >>> MapParameters(block=(3, 2)).block
    (3, 2)
    """

    exponent: float = 1.0
    block: tuple[int, int] = (2, 2)
    omega: float = 10.0
    weight: float = 10.0

    def __post_init__(self) -> None:
        if not MIN_EXPONENT <= self.exponent <= MAX_EXPONENT:
            raise InputError(
                f"information exponent s must be in [{MIN_EXPONENT:g}, {MAX_EXPONENT:g}], "
                f"got {self.exponent}"
            )
        if (
            len(self.block) != 2
            or any(int(b) != b or b < 1 for b in self.block)
            or any(isinstance(b, bool) for b in self.block)
        ):
            raise InputError(f"block must be two integers >= 1 (r_n, r_e), got {self.block}")
        if not 0.0 < self.omega <= MAX_COST_TERM:
            raise InputError(
                f"cost shift omega must be in (0, {MAX_COST_TERM:g}], got {self.omega}"
            )
        if not 0.0 <= self.weight <= MAX_COST_TERM:
            raise InputError(f"cost weight w must be in [0, {MAX_COST_TERM:g}], got {self.weight}")


@dataclass(frozen=True)
class TerrainMaps:
    r"""The four maps of the paper's Fig. 5 plus the shifted cost, with their grids.

    Parameters
    ----------
    bathymetry : BathymetryGrid
        The input grid (depth [m], positive down, on the fine grid).
    information : ndarray of shape (n_rows, n_cols)
        Information map :math:`M_I` in [0, 1] on the fine grid (eq. 13); NaN on no-go cells.
    excitation : ndarray of shape (n_block_rows, n_block_cols)
        Excitation map :math:`M_E` in [0, 1] on the coarse grid (eq. 14).
    cost : ndarray of shape (n_block_rows, n_block_cols)
        Cost map :math:`M_C = \cos(\pi/2\, M_E)` in [0, 1].
    shifted_cost : ndarray of shape (n_block_rows, n_block_cols)
        :math:`\omega + w M_C` (eq. 15), what the A* pre-planner searches.
    cost_geometry : GridGeometry
        Geometry of the coarse grid, ``bathymetry.geometry.coarsen(*parameters.block)``.
    parameters : MapParameters
        The parameters used.
    """

    bathymetry: BathymetryGrid
    information: FloatArray
    excitation: FloatArray
    cost: FloatArray
    shifted_cost: FloatArray
    cost_geometry: GridGeometry
    parameters: MapParameters


def compute_gradient_magnitude(grid: BathymetryGrid) -> FloatArray:
    r"""Magnitude of the depth gradient [m/m] on the true north and east spacings.

    Parameters
    ----------
    grid : BathymetryGrid
        Depth [m] of shape ``(n_rows, n_cols)``, at least 2 x 2, NaN for no-go cells.

    Returns
    -------
    ndarray of shape (n_rows, n_cols)
        :math:`\sqrt{(\partial d/\partial n)^2 + (\partial d/\partial e)^2}` [m/m].

    Notes
    -----
    Along each axis the derivative at a finite cell is the central difference
    :math:`(d_{i+1} - d_{i-1}) / (2\Delta)` when both neighbours are finite, the one-sided
    difference :math:`\pm(d_{i\pm1} - d_i)/\Delta` when only one is (this includes the map
    border), and NaN when neither is. NaN cells stay NaN. So the gradient never reaches across
    a no-go cell, and a cell is NaN only if it, or its whole neighbourhood along an axis, is.
    """
    depth = np.asarray(grid.depth, dtype=np.float64)
    if depth.shape[0] < 2 or depth.shape[1] < 2:
        raise InputError(f"the gradient needs a grid of at least 2 x 2 cells, got {depth.shape}")
    d_north = _axis_derivative(depth, grid.geometry.spacing_north, axis=0)
    d_east = _axis_derivative(depth, grid.geometry.spacing_east, axis=1)
    return np.asarray(np.hypot(d_north, d_east))


def _axis_derivative(depth: FloatArray, spacing: float, *, axis: int) -> FloatArray:
    """Derivative along ``axis`` with the NaN-aware stencil of compute_gradient_magnitude.

    The central difference is the mean of the backward and forward differences, so the
    derivative is the mean of whichever of the two is finite (NaN if neither is).
    """
    values = np.moveaxis(depth, axis, 0)
    step = np.diff(values, axis=0) / spacing  # step[i] = (d[i+1] - d[i]) / spacing
    has_step = np.isfinite(step)
    step[~has_step] = 0.0
    total = np.zeros_like(values)
    count = np.zeros(values.shape, dtype=np.float64)
    total[1:] += step  # backward difference at i = step[i-1]
    total[:-1] += step  # forward difference at i = step[i]
    count[1:] += has_step
    count[:-1] += has_step
    with np.errstate(invalid="ignore", divide="ignore"):
        derivative = total / count  # 0 / 0 -> NaN: no finite neighbour along this axis
    return np.asarray(np.moveaxis(derivative, 0, axis))


def compute_information_map(grid: BathymetryGrid, *, exponent: float = 1.0) -> FloatArray:
    r"""Information map (paper eq. 13): the normalised gradient magnitude to the power ``s``.

    Parameters
    ----------
    grid : BathymetryGrid
        Depth [m] of shape ``(n_rows, n_cols)`` (at least 2 x 2); NaN for no-go cells.
    exponent : float
        Exponent :math:`s > 0`.

    Returns
    -------
    ndarray of shape (n_rows, n_cols)
        :math:`M_I = (|\nabla M_B| / \max |\nabla M_B|)^s` in [0, 1], dimensionless; NaN where
        the gradient is NaN (see :func:`compute_gradient_magnitude`). A flat grid (maximum
        gradient 0) carries no information: :math:`M_I = 0`.

    Raises
    ------
    InputError
        If ``exponent <= 0``, the grid is smaller than 2 x 2, or no cell has a finite gradient.

    Notes
    -----
    The gradient is in metres per metre on the true spacings, which differ between north
    and east on grids projected from lat/lon. High :math:`M_I` means good terrain-based
    navigation: the Cramér–Rao bound of a depth fix falls as the gradient grows.

    Examples
    --------
    >>> depth = np.array([[0.0, 1.0, 2.0], [0.0, 2.0, 4.0]])
    >>> grid = BathymetryGrid(depth, GridGeometry(2, 3, 1.0, 1.0))
    >>> compute_information_map(grid).round(3)
    array([[0.354, 0.5  , 0.791],
           [0.707, 0.791, 1.   ]])
    """
    if not (np.isfinite(exponent) and exponent > 0.0):
        raise InputError(f"information exponent s must be > 0, got {exponent}")
    magnitude = compute_gradient_magnitude(grid)
    finite = np.isfinite(magnitude)
    if not finite.any():
        raise InputError(f"no cell of {grid.name or 'the grid'} has a finite depth gradient")
    largest = float(magnitude[finite].max())
    if largest == 0.0:
        return np.where(finite, 0.0, np.nan)
    information = magnitude / largest
    return information if exponent == 1.0 else np.asarray(information**exponent)


def compute_excitation_map(information: FloatArray, block: tuple[int, int]) -> FloatArray:
    """Excitation map (paper eq. 14): the mean of ``information`` over blocks of cells.

    Parameters
    ----------
    information : ndarray of shape (n_rows, n_cols)
        Information map :math:`M_I` (dimensionless).
    block : tuple of int
        ``(r_n, r_e)``: block size in cells along north and east, both >= 1.

    Returns
    -------
    ndarray of shape (n_rows // r_n, n_cols // r_e)
        Block means. A block containing any NaN cell is NaN (no-go; conservative). Remainder
        rows (north) and columns (east) that do not fill a block are dropped, as in
        :meth:`GridGeometry.coarsen`.

    Raises
    ------
    InputError
        If a block size is < 1 or larger than the map.

    Examples
    --------
    >>> compute_excitation_map(np.arange(12.0).reshape(3, 4), (2, 2))
    array([[2.5, 4.5]])
    """
    r_north, r_east = (int(b) for b in block)
    n_rows, n_cols = information.shape
    if r_north < 1 or r_east < 1:
        raise InputError(f"block size must be >= 1 cell, got {r_north} x {r_east}")
    n_blocks_north, n_blocks_east = n_rows // r_north, n_cols // r_east
    if n_blocks_north < 1 or n_blocks_east < 1:
        raise InputError(f"block {r_north} x {r_east} is larger than the map {n_rows} x {n_cols}")
    trimmed = np.asarray(information, dtype=np.float64)[
        : n_blocks_north * r_north, : n_blocks_east * r_east
    ]
    blocks = trimmed.reshape(n_blocks_north, r_north, n_blocks_east, r_east)
    return np.asarray(blocks.mean(axis=(1, 3)))


def compute_cost_map(excitation: FloatArray) -> FloatArray:
    r"""Cost map :math:`M_C = \cos(\tfrac{\pi}{2} M_E)` (paper Sec. III-A).

    Parameters
    ----------
    excitation : ndarray of shape (n_rows, n_cols)
        Excitation map in [0, 1].

    Returns
    -------
    ndarray of shape (n_rows, n_cols)
        Cost in [0, 1]: 1 over featureless terrain, falling to 0 over the richest; NaN stays NaN.

    Examples
    --------
    >>> compute_cost_map(np.array([0.0, 0.5, 1.0])).round(4)
    array([1.    , 0.7071, 0.    ])
    """
    return np.asarray(np.cos(0.5 * np.pi * np.asarray(excitation, dtype=np.float64)))


def compute_shifted_cost(cost: FloatArray, *, omega: float, weight: float) -> FloatArray:
    r"""Admissibility shift (paper eq. 15): :math:`\tilde M_C = \omega + w M_C`.

    Parameters
    ----------
    cost : ndarray of shape (n_rows, n_cols)
        Cost map :math:`M_C` in [0, 1].
    omega : float
        Shift :math:`\omega > 0`.
    weight : float
        Weight :math:`w \ge 0`.

    Returns
    -------
    ndarray of shape (n_rows, n_cols)
        Shifted cost in :math:`[\omega, \omega + w]`; NaN stays NaN.

    Examples
    --------
    >>> compute_shifted_cost(np.array([0.0, 1.0]), omega=10.0, weight=10.0)
    array([10., 20.])
    """
    return np.asarray(omega + weight * np.asarray(cost, dtype=np.float64))


def compute_terrain_maps(
    grid: BathymetryGrid, parameters: MapParameters | None = None
) -> TerrainMaps:
    """All terrain maps of the paper's Fig. 5 for one bathymetric grid (eqs. 13–15).

    Parameters
    ----------
    grid : BathymetryGrid
        Depth [m], positive down, at least 2 x 2 and at least one block; NaN = no-go.
    parameters : MapParameters, optional
        Exponent, block size, shift and weight; the paper's values by default.

    Returns
    -------
    TerrainMaps
        Information map on the fine grid; excitation, cost and shifted cost on the coarse grid
        ``grid.geometry.coarsen(*parameters.block)``.

    Raises
    ------
    InputError
        If the grid is too small for the gradient or the block, or has no finite gradient.

    Examples
    --------
    >>> from auvplan.terrain.synthetic import synthetic_bank
    >>> maps = compute_terrain_maps(synthetic_bank())
    >>> maps.shifted_cost.shape, maps.cost_geometry.spacing_east
    ((50, 100), 8.0)
    """
    parameters = MapParameters() if parameters is None else parameters
    cost_geometry = grid.geometry.coarsen(*parameters.block)
    information = compute_information_map(grid, exponent=parameters.exponent)
    excitation = compute_excitation_map(information, parameters.block)
    cost = compute_cost_map(excitation)
    shifted = compute_shifted_cost(cost, omega=parameters.omega, weight=parameters.weight)
    return TerrainMaps(grid, information, excitation, cost, shifted, cost_geometry, parameters)
