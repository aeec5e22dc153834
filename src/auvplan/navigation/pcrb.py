r"""Posterior Cramér-Rao bound of terrain-aided navigation along a track: what the terrain allows.

For the filter's model (random-walk motion with process covariance :math:`Q_k = \sigma_k^2 I`,
soundings :math:`z_j = h(x + o_j) + \varepsilon_j` of variance :math:`r_j`), the information
matrix of any unbiased estimator obeys the recursion of Tichavský, Muravchik and Nehorai
(IEEE TSP 46(5), 1998) for additive Gaussian noise and a linear motion model:

.. math::

    J_0 = P_0^{-1} + \sum_j \frac{H_{0j}^\top H_{0j}}{r_{0j}}, \qquad
    J_k = \left(J_{k-1}^{-1} + Q_k\right)^{-1} + \sum_j \frac{H_{kj}^\top H_{kj}}{r_{kj}},

with :math:`H_{kj} = \nabla h(x_k + o_{kj})` taken at the true position (the expectation over
the state replaced by its value on the track, the usual evaluation along a planned path; as in
the open TAN template ``jbrodovsky/geo-fixability``). Flat terrain adds no information. The
bound :math:`\sqrt{\operatorname{tr} J_k^{-1}}` [m] is the filter-free yardstick: a consistent,
efficient filter's position error approaches it, none beats it on average.
"""

from __future__ import annotations

import numpy as np

from auvplan._typing import FloatArray
from auvplan.navigation._prediction_kernel import covariance_recursion
from auvplan.navigation.depth import depth_gradient_at
from auvplan.terrain import BathymetryGrid


def posterior_crb(
    grid: BathymetryGrid,
    positions: FloatArray,
    offsets: FloatArray,
    variances: FloatArray,
    process_sigma: FloatArray,
    initial_sigma: float,
) -> FloatArray:
    r"""Posterior Cramér-Rao bound on the position covariance at every update.

    Parameters
    ----------
    grid : BathymetryGrid
        The map.
    positions : ndarray of shape (K + 1, 2)
        True positions ``north, east`` [m] at the updates.
    offsets : ndarray of shape (K + 1, n_beams, 2)
        Beam footprint offsets [m] (NaN: no sounding).
    variances : ndarray of shape (K + 1, n_beams)
        Sounding variances [m²].
    process_sigma : ndarray of shape (K,)
        Process-noise standard deviation [m] per axis of each motion step.
    initial_sigma : float
        Prior standard deviation [m] per axis at update 0.

    Returns
    -------
    ndarray of shape (K + 1, 2, 2)
        Bound :math:`J_k^{-1}` [m²] (module notes).

    Examples
    --------
    A plane of slope 0.1 north and 4 soundings of variance 1 m²: the north variance is
    :math:`1 / (1 / 10^2 + 4 \cdot 0.1^2) = 20` m², the east variance stays at the prior.

    >>> from auvplan.terrain import GridGeometry
    >>> depth = 30.0 + 0.1 * np.arange(20.0)[:, None] + np.zeros((20, 20))
    >>> grid = BathymetryGrid(depth, GridGeometry(20, 20, 1.0, 1.0))
    >>> bound = posterior_crb(
    ...     grid, np.full((4, 2), 10.0), np.zeros((4, 1, 2)), np.ones((4, 1)), np.zeros(3), 10.0
    ... )
    >>> np.round(bound[-1], 9)
    array([[ 20.,   0.],
           [  0., 100.]])
    """
    fisher = sounding_information(grid, positions, offsets, variances)
    packed = covariance_recursion(
        fisher[:, [0, 0, 1], [0, 1, 1]],
        np.zeros(positions.shape[0] - 1),
        np.asarray(process_sigma, dtype=np.float64) ** 2,
        float(initial_sigma) ** 2,
        0.0,
    )
    return unpack_covariance(packed)


def sounding_information(
    grid: BathymetryGrid, positions: FloatArray, offsets: FloatArray, variances: FloatArray
) -> FloatArray:
    r"""Fisher information :math:`\sum_j \nabla h_j \nabla h_j^\top / r_j` [1/m²] of each ping.

    ``positions`` ``(n, 2)``, ``offsets`` ``(n, n_beams, 2)`` and ``variances``
    ``(n, n_beams)`` as :func:`posterior_crb`; beams without a sounding add nothing.
    Returns ``(n, 2, 2)``.
    """
    footprints = positions[:, None, :] + offsets
    gradient = depth_gradient_at(grid, footprints[..., 0], footprints[..., 1])
    usable = np.all(np.isfinite(gradient), axis=-1) & np.isfinite(variances)
    weights = np.where(usable, 1.0 / np.where(usable, variances, 1.0), 0.0)
    gradient = np.where(usable[..., None], gradient, 0.0)
    return np.asarray(np.einsum("kj,kja,kjb->kab", weights, gradient, gradient), np.float64)


def unpack_covariance(packed: FloatArray) -> FloatArray:
    """``(n, 3)`` entries ``p00, p01, p11`` as symmetric ``(n, 2, 2)`` matrices."""
    out = np.empty((packed.shape[0], 2, 2))
    out[:, 0, 0], out[:, 1, 1] = packed[:, 0], packed[:, 2]
    out[:, 0, 1] = out[:, 1, 0] = packed[:, 1]
    return out
