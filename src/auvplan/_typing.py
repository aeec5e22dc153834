"""Array type aliases and the shape vocabulary used across auvplan.

Arrays are **time-major**: time on axis 0, components last.

===================  =============================  ==================================
name                 shape                          meaning
===================  =============================  ==================================
states               ``(n_t, n_x)``                 one vehicle's (or a stacked fleet's) state
inputs               ``(n_t, n_u)``                 inputs on the same grid (zero-order hold)
fleet states         ``(n_vehicles, n_t, n_x)``     per-vehicle states
grid maps            ``(n_rows, n_cols)``           row 0 is the southern edge, col 0 the western
path cells           ``(n_cells, 2)``               integer ``[row, col]`` pairs
world points         ``(n_points, 2)``              ``[north, east]`` in metres
===================  =============================  ==================================

python-control uses the opposite order; we choose time-major because the Riccati and LQ
sweeps walk along time.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
BoolArray = npt.NDArray[np.bool_]

__all__ = ["BoolArray", "FloatArray", "IntArray"]
