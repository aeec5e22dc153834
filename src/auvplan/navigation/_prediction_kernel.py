r"""The compiled step of the predicted TAN error: drift growth, process noise, soundings.

One step from covariance :math:`P` (symmetric 2 × 2, stored as ``p00, p01, p11`` [m²]):

.. math::

    P^- = \left(\sqrt{P} + g I\right)^2 + w I, \qquad
    P^+ = \left((P^-)^{-1} + F\right)^{-1},

with :math:`g` [m] the growth of the standard deviation by dead-reckoning drift over the step
(a scale or heading bias: the error of a straight leg of length :math:`D` grows as
:math:`\sigma_b D`, linearly), :math:`w` [m²] the white process variance added over the step
and :math:`F` [1/m²] the Fisher information of the soundings taken in it. With :math:`g = 0`
this is the posterior Cramér-Rao recursion of :mod:`~auvplan.navigation.pcrb`. The square
root of a 2 × 2 SPD matrix is closed-form: :math:`\sqrt P = (P + sI)/t` with
:math:`s = \sqrt{\det P}` and :math:`t = \sqrt{\operatorname{tr} P + 2s}`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from auvplan._typing import FloatArray


@njit(cache=True)
def propagate(
    p00: float,
    p01: float,
    p11: float,
    growth: float,
    white: float,
    f00: float,
    f01: float,
    f11: float,
) -> tuple[float, float, float]:  # pragma: no cover - compiled
    """One step of the recursion (module notes); returns ``p00, p01, p11`` after it."""
    if growth > 0.0:
        s = math.sqrt(max(p00 * p11 - p01 * p01, 0.0))
        t = math.sqrt(p00 + p11 + 2.0 * s)
        p00 += 2.0 * growth * (p00 + s) / t + growth * growth
        p01 += 2.0 * growth * p01 / t
        p11 += 2.0 * growth * (p11 + s) / t + growth * growth
    p00 += white
    p11 += white
    det = p00 * p11 - p01 * p01
    j00 = p11 / det + f00
    j01 = -p01 / det + f01
    j11 = p00 / det + f11
    det_j = j00 * j11 - j01 * j01
    return j11 / det_j, 0.0 - j01 / det_j, j00 / det_j


@njit(cache=True)
def covariance_recursion(
    fisher: FloatArray,
    growth: FloatArray,
    white: FloatArray,
    initial_variance: float,
) -> FloatArray:  # pragma: no cover - compiled
    r"""Covariances ``(K + 1, 3)`` after updates ``0..K`` (``fisher`` ``(K + 1, 3)``).

    Update 0 adds ``fisher[0]`` to the prior :math:`I / \sigma_0^2`; step ``k`` grows by
    ``growth[k - 1]``, ``white[k - 1]`` and adds ``fisher[k]``.
    """
    n = fisher.shape[0]
    out = np.empty((n, 3))
    j00 = 1.0 / initial_variance + fisher[0, 0]
    j01 = fisher[0, 1]
    j11 = 1.0 / initial_variance + fisher[0, 2]
    det_j = j00 * j11 - j01 * j01
    out[0, 0], out[0, 1], out[0, 2] = j11 / det_j, 0.0 - j01 / det_j, j00 / det_j
    for k in range(1, n):
        out[k, 0], out[k, 1], out[k, 2] = propagate(
            out[k - 1, 0], out[k - 1, 1], out[k - 1, 2], growth[k - 1], white[k - 1],
            fisher[k, 0], fisher[k, 1], fisher[k, 2],
        )  # fmt: skip
    return out
