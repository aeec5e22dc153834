r"""Ocean current fields: the water's velocity over ground in the local north/east frame.

A field gives ``v_c(n, e, t) = (v_N, v_E)`` [m/s], the direction the water flows **to**
(oceanographic convention, CF ``eastward_sea_water_velocity``), and its spatial Jacobian

.. math::

    G = \begin{bmatrix} ∂v_N/∂n & ∂v_N/∂e \\ ∂v_E/∂n & ∂v_E/∂e \end{bmatrix} \quad [1/s].

:class:`UniformCurrent` is constant; :class:`GriddedCurrent` is a tensor-product uniform cubic
B-spline in space (C², :class:`auvplan.terrain.spline.SplineSurface` on the file's own lattice)
and in time (C²), so an optimiser that steers through it sees smooth first and second
derivatives. The file's axes (latitude/longitude, a projected CRS, or the local frame) map to
the local frame by an affine map fixed at construction (:mod:`auvplan.io.currents`).

References
----------
.. [1] T. I. Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed.,
   Wiley 2021, Sec. 10.3 (ocean currents, relative velocity ν_r = ν − ν_c).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.terrain.spline import SplineSurface

__all__ = ["CurrentField", "GriddedCurrent", "UniformCurrent"]


class CurrentField(Protocol):
    """A current field in the local frame (module notes); arrays broadcast to ``(K,)``."""

    def velocity(
        self, north: FloatArray, east: FloatArray, time: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """``(v_N, v_E)`` [m/s] at positions [m] and mission times [s], each of shape ``(K,)``."""
        ...

    def gradient(self, north: FloatArray, east: FloatArray, time: FloatArray) -> FloatArray:
        """Spatial Jacobian ``G`` of shape ``(K, 2, 2)`` [1/s] (module notes)."""
        ...


def _points(north: FloatArray, east: FloatArray, time: FloatArray) -> tuple[FloatArray, ...]:
    arrays = np.broadcast_arrays(
        np.asarray(north, dtype=np.float64),
        np.asarray(east, dtype=np.float64),
        np.asarray(time, dtype=np.float64),
    )
    return tuple(np.ascontiguousarray(a).reshape(-1) for a in arrays)


@dataclass(frozen=True)
class UniformCurrent:
    """The same current everywhere and always.

    Parameters
    ----------
    north, east : float
        Components of the water's velocity over ground [m/s] (the direction it flows to).

    Examples
    --------
    >>> UniformCurrent(0.0, 0.2).velocity(np.zeros(2), np.zeros(2), np.zeros(2))[1].tolist()
    [0.2, 0.2]
    """

    north: float
    east: float

    def velocity(
        self, north: FloatArray, east: FloatArray, time: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """``(v_N, v_E)`` [m/s], each of shape ``(K,)``."""
        size = _points(north, east, time)[0].size
        return np.full(size, self.north), np.full(size, self.east)

    def gradient(self, north: FloatArray, east: FloatArray, time: FloatArray) -> FloatArray:
        """Zero Jacobian of shape ``(K, 2, 2)`` [1/s]."""
        return np.zeros((_points(north, east, time)[0].size, 2, 2))


def _time_basis(offset: FloatArray) -> FloatArray:
    """Cubic B-spline weights ``(K, 4)`` of the slices ``i-1 … i+2`` at ``offset ∈ [0, 1]``."""
    t = offset[:, None]
    s = 1.0 - t
    return np.hstack([s**3, 3 * t**3 - 6 * t**2 + 4, -3 * t**3 + 3 * t**2 + 3 * t + 1, t**3]) / 6.0


@dataclass(frozen=True, eq=False)
class GriddedCurrent:
    """A current on a regular lattice of the file's axes, smooth in space and time.

    Parameters
    ----------
    north_component, east_component : tuple of SplineSurface
        ``v_N``, ``v_E`` [m/s] per time slice, over the file's axes (row axis northing or
        latitude, column axis easting or longitude; NaN cells, land, count as still water).
    time_step : float
        Interval between slices [s] (any positive value for a single slice).
    start_offset : float
        Mission time [s] of the first slice.
    to_axes : ndarray of shape (2, 3)
        Affine map from ``(north, east, 1)`` [m] of the local frame to the file's axes:
        ``A = to_axes[:, :2]`` is ``∂(axes)/∂(north, east)``.

    Notes
    -----
    ``v(p, t) = Σ_j β_j(t) S_j(A p + b)`` with ``β_j`` the uniform cubic B-spline weights of the
    slices (held at the first and last slice outside the file's time span), so
    ``G = [∂S/∂(axes)] A``.
    """

    north_component: tuple[SplineSurface, ...]
    east_component: tuple[SplineSurface, ...]
    time_step: float
    start_offset: float
    to_axes: FloatArray

    def __post_init__(self) -> None:
        if len(self.north_component) != len(self.east_component) or not self.north_component:
            raise InputError(
                "a gridded current needs the same number (>= 1) of slices per component"
            )
        if not self.time_step > 0.0:
            raise InputError(f"time_step must be > 0 s, got {self.time_step}")

    @property
    def n_slices(self) -> int:
        """Number of time slices [-]."""
        return len(self.north_component)

    def _evaluate(self, north: FloatArray, east: FloatArray, time: FloatArray) -> FloatArray:
        """``(K, 2, 3)``: per component ``v_N``, ``v_E`` the value and ``∂/∂n``, ``∂/∂e``."""
        north, east, time = _points(north, east, time)
        axes = self.to_axes[:, :2] @ np.vstack([north, east]) + self.to_axes[:, 2:]
        last = self.n_slices - 1
        position = np.clip((time - self.start_offset) / self.time_step, 0.0, last)
        base = np.minimum(np.floor(position), max(last - 1, 0)).astype(np.int64)
        weights = _time_basis(position - base)
        nodes = np.clip(base[:, None] + np.arange(-1, 3), 0, last)
        result = np.zeros((north.size, 2, 3))
        for j in np.unique(nodes):
            weight = np.sum(np.where(nodes == j, weights, 0.0), axis=1)
            used = weight != 0.0
            for k, component in enumerate((self.north_component, self.east_component)):
                values = component[j].evaluate(axes[0, used], axes[1, used])[:, :3]
                result[used, k, :] += weight[used, None] * values
        result[:, :, 1:] = result[:, :, 1:] @ self.to_axes[:, :2]
        return result

    def velocity(
        self, north: FloatArray, east: FloatArray, time: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """``(v_N, v_E)`` [m/s], each of shape ``(K,)``."""
        values = self._evaluate(north, east, time)
        return values[:, 0, 0], values[:, 1, 0]

    def gradient(self, north: FloatArray, east: FloatArray, time: FloatArray) -> FloatArray:
        """Spatial Jacobian ``G`` of shape ``(K, 2, 2)`` [1/s]."""
        values = self._evaluate(north, east, time)
        return np.ascontiguousarray(values[:, :, 1:])
