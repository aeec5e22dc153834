r"""The seabed depth the navigation simulator senses and matches: a bilinear surface on the map.

Both the simulated sensors (the "true" seabed) and the filter's map use the same surface,
interpolated bilinearly between the nodes of a :class:`~auvplan.terrain.BathymetryGrid`; map
error enters as the map variance of the likelihood (:class:`~auvplan.navigation.SensorModel`).
Off the grid, and wherever an interpolation node is NaN (land, no data), there is no depth.
"""

from __future__ import annotations

import numpy as np

from auvplan._typing import FloatArray
from auvplan.navigation._kernels import sample_depth, sample_gradient
from auvplan.terrain import BathymetryGrid


def depth_at(grid: BathymetryGrid, north: FloatArray, east: FloatArray) -> FloatArray:
    """Bilinearly interpolated depth [m] at world points.

    Parameters
    ----------
    grid : BathymetryGrid
        The map.
    north, east : ndarray
        Points [m], any matching shape.

    Returns
    -------
    ndarray
        Depth [m], positive down, same shape as ``north``; NaN off the map or next to NaN.

    Examples
    --------
    >>> from auvplan.terrain import GridGeometry
    >>> grid = BathymetryGrid(np.array([[10.0, 20.0], [30.0, 40.0]]), GridGeometry(2, 2, 4.0, 2.0))
    >>> depth_at(grid, np.array([2.0, 9.0]), np.array([1.0, 1.0]))
    array([25., nan])
    """
    north, east = np.broadcast_arrays(np.asarray(north, float), np.asarray(east, float))
    row, col = grid.geometry.to_fractional_index(north, east)
    return sample_depth(grid.depth, row.ravel(), col.ravel()).reshape(north.shape)


def depth_gradient_at(grid: BathymetryGrid, north: FloatArray, east: FloatArray) -> FloatArray:
    r"""Gradient :math:`\nabla h = (\partial h / \partial n, \partial h / \partial e)` [m/m].

    Parameters
    ----------
    grid : BathymetryGrid
        The map.
    north, east : ndarray
        Points [m], any matching shape ``S``.

    Returns
    -------
    ndarray of shape S + (2,)
        Gradient of the bilinear surface of :func:`depth_at` (constant along each axis within
        a cell, so the derivative across a cell edge is one-sided); NaN off the map.

    Examples
    --------
    >>> from auvplan.terrain import GridGeometry
    >>> grid = BathymetryGrid(np.array([[10.0, 20.0], [30.0, 40.0]]), GridGeometry(2, 2, 4.0, 2.0))
    >>> depth_gradient_at(grid, np.array([2.0]), np.array([1.0]))
    array([[5., 5.]])
    """
    north, east = np.broadcast_arrays(np.asarray(north, float), np.asarray(east, float))
    geometry = grid.geometry
    row, col = geometry.to_fractional_index(north, east)
    per_index = sample_gradient(grid.depth, row.ravel(), col.ravel())
    spacing = np.array([geometry.spacing_north, geometry.spacing_east])
    return np.asarray((per_index / spacing).reshape(*north.shape, 2), dtype=np.float64)
