r"""A C²-smooth surface through a map on a regular grid: a uniform tensor-product cubic B-spline.

For a map ``F_ij`` on nodes ``(n_i, e_j)`` with spacings ``Δn``, ``Δe`` the surface is

.. math::

    S(n, e) = \sum_{i,j} F_{ij}\, β\big((n - n_i)/Δn\big)\, β\big((e - e_j)/Δe\big)

with ``β`` the uniform cubic B-spline (support ``[-2, 2]``; nodes beyond the grid repeat the
edge values). ``S`` is twice continuously differentiable, its value, gradient and Hessian
are exact, and it is a mild smoothing of ``F`` (at a node it is ``(F_{i-1} + 4 F_i + F_{i+1})/6``
along each axis), which is what an optimiser steering by the map needs: no kinks between
cells. NaN cells (land, no data) count as 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from auvplan import _numba_cache  # noqa: F401 (damaged numba cache files heal: first)
from auvplan._typing import FloatArray
from auvplan.terrain.grid import GridGeometry

__all__ = ["SplineSurface"]


@numba.njit(cache=True)
def _basis(t: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Weights of the 4 supporting nodes at offset ``t ∈ [0, 1)``, and their derivatives."""
    s = 1.0 - t
    value = np.array([s**3 / 6.0, (3 * t**3 - 6 * t**2 + 4) / 6.0,
                      (-3 * t**3 + 3 * t**2 + 3 * t + 1) / 6.0, t**3 / 6.0])  # fmt: skip
    first = np.array([-(s**2) / 2.0, (3 * t**2 - 4 * t) / 2.0, (-3 * t**2 + 2 * t + 1) / 2.0,
                      t**2 / 2.0])  # fmt: skip
    second = np.array([s, 3 * t - 2.0, -3 * t + 1.0, t])
    return value, first, second


@numba.njit(cache=True)
def _evaluate(
    table: FloatArray,
    origin: FloatArray,
    spacing: FloatArray,
    north: FloatArray,
    east: FloatArray,
    out: FloatArray,
) -> None:
    """``out[k] = (S, S_n, S_e, S_nn, S_ne, S_ee)`` at every point.

    ``origin`` is the position of ``table[0, 0]``; the segment ``[i, i + 1)`` of table-index
    coordinates is spanned by the control points ``i − 1 .. i + 2``.
    """
    rows, cols = table.shape
    for k in range(north.size):
        u = (north[k] - origin[0]) / spacing[0]
        v = (east[k] - origin[1]) / spacing[1]
        u = min(max(u, 1.0), rows - 2.0 - 1e-9)  # table index; the padding keeps it in range
        v = min(max(v, 1.0), cols - 2.0 - 1e-9)
        i, j = int(np.floor(u)), int(np.floor(v))
        bu, du, ddu = _basis(u - i)
        bv, dv, ddv = _basis(v - j)
        acc = np.zeros(6)
        for a in range(4):
            for b in range(4):
                f = table[i - 1 + a, j - 1 + b]
                acc[0] += f * bu[a] * bv[b]
                acc[1] += f * du[a] * bv[b]
                acc[2] += f * bu[a] * dv[b]
                acc[3] += f * ddu[a] * bv[b]
                acc[4] += f * du[a] * dv[b]
                acc[5] += f * bu[a] * ddv[b]
        out[k, 0] = acc[0]
        out[k, 1] = acc[1] / spacing[0]
        out[k, 2] = acc[2] / spacing[1]
        out[k, 3] = acc[3] / spacing[0] ** 2
        out[k, 4] = acc[4] / (spacing[0] * spacing[1])
        out[k, 5] = acc[5] / spacing[1] ** 2


@dataclass(frozen=True)
class SplineSurface:
    """The cubic B-spline surface of a gridded map (module equations).

    Examples
    --------
    >>> import numpy as np
    >>> from auvplan.terrain import GridGeometry
    >>> geometry = GridGeometry(6, 7, 2.0, 2.0)
    >>> plane = np.add.outer(3.0 * geometry.north, geometry.east)   # F = 3 n + e
    >>> values = SplineSurface.fit(geometry, plane).evaluate(np.array([5.0]), np.array([7.0]))
    >>> values[0, :3].round(9).tolist()   # a plane is reproduced away from the edges
    [22.0, 3.0, 1.0]
    """

    table: FloatArray
    origin: FloatArray
    spacing: FloatArray

    @classmethod
    def fit(cls, geometry: GridGeometry, values: FloatArray) -> SplineSurface:
        """The surface of ``values`` ``(n_north, n_east)`` on a regular ``geometry``."""
        field = np.nan_to_num(np.asarray(values, dtype=np.float64), nan=0.0)
        table = np.pad(field, 3, mode="edge")  # the support reaches 2 nodes beyond the edge
        spacing = np.array([geometry.spacing_north, geometry.spacing_east])
        origin = np.array([geometry.origin_north, geometry.origin_east]) - 3.0 * spacing
        return cls(np.ascontiguousarray(table), origin, spacing)

    def evaluate(self, north: FloatArray, east: FloatArray) -> FloatArray:
        """``(S, ∂S/∂n, ∂S/∂e, ∂²S/∂n², ∂²S/∂n∂e, ∂²S/∂e²)`` per point, shape ``(K, 6)``."""
        north = np.ascontiguousarray(north, dtype=np.float64).ravel()
        east = np.ascontiguousarray(east, dtype=np.float64).ravel()
        out = np.empty((north.size, 6))
        _evaluate(self.table, self.origin, self.spacing, north, east, out)
        return out
