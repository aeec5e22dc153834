r"""The compiled step of the predicted TAN error: drift growth, process noise, soundings.

One step of length :math:`\ell` [m] from the covariance :math:`P` (symmetric 2 × 2, stored as
``p00, p01, p11`` [m²]) and the variance :math:`V` [m²] that dead reckoning has added since
the last fixes:

.. math::

    \delta = \sigma_b^2 \left((d + \ell)^2 - d^2\right), \quad
    d = \sqrt{V} / \sigma_b, \qquad
    P^- = P + \max(\delta, w)\, I, \quad V^- = V + \delta,

.. math::

    P^+ = \left((P^-)^{-1} + F\right)^{-1}, \qquad
    V^+ = V^- \, \operatorname{tr} P^+ / \operatorname{tr} P^-.

Dead reckoning with a scale and heading bias :math:`\sigma_b` (per metre) makes the error of a
straight leg grow as :math:`\sigma_b D` — quadratically in variance, from the last fix on:
:math:`d` is the distance flown since it, and a fix shrinks it with the error. Over a flat
seabed (:math:`F = 0`) the variance is exactly :math:`\sigma_0^2 + \sigma_b^2 D^2` per axis, the
dead-reckoning error. ``w`` [m²] is the white variance the filter itself adds over the step (its
process noise): it sets the growth where dead reckoning grows slower (just after a fix), and so
the accuracy a filter keeps over informative seabed, but it is no drift: it does not advance
:math:`d`. :math:`F` [1/m²] is the Fisher information of the soundings of the step. With
:math:`\sigma_b = 0` this is the posterior Cramér-Rao recursion of
:mod:`~auvplan.navigation.pcrb`.
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
    grown: float,
    drift_variance: float,
    length: float,
    white: float,
    f00: float,
    f01: float,
    f11: float,
) -> tuple[float, float, float, float]:  # pragma: no cover - compiled
    r"""One step of the recursion (module notes).

    ``drift_variance`` is :math:`\sigma_b^2` [1], ``grown`` is :math:`V` [m²], ``length``
    is :math:`\ell` [m]; returns ``p00, p01, p11`` and :math:`V` after the step.
    """
    drift = 0.0
    if drift_variance > 0.0:
        since = math.sqrt(grown / drift_variance)
        drift = drift_variance * length * (2.0 * since + length)
    increment = max(drift, white)
    p00 += increment
    p11 += increment
    grown += drift
    before = p00 + p11
    inverse = 1.0 / (p00 * p11 - p01 * p01)
    j00 = p11 * inverse + f00
    j01 = f01 - p01 * inverse
    j11 = p00 * inverse + f11
    inverse = 1.0 / (j00 * j11 - j01 * j01)
    q00, q01, q11 = j11 * inverse, 0.0 - j01 * inverse, j00 * inverse
    return q00, q01, q11, grown * (q00 + q11) / before


@njit(cache=True)
def covariance_recursion(
    fisher: FloatArray,
    steps: FloatArray,
    white: FloatArray,
    initial_variance: float,
    drift_variance: float,
) -> FloatArray:  # pragma: no cover - compiled
    r"""Covariances ``(K + 1, 3)`` after updates ``0..K`` (``fisher`` ``(K + 1, 3)``).

    Update 0 adds ``fisher[0]`` to the prior :math:`I / \sigma_0^2`; step ``k`` flies
    ``steps[k - 1]`` metres, adds ``white[k - 1]`` and ``fisher[k]``.
    """
    n = fisher.shape[0]
    out = np.empty((n, 3))
    j00 = 1.0 / initial_variance + fisher[0, 0]
    j01 = fisher[0, 1]
    j11 = 1.0 / initial_variance + fisher[0, 2]
    det_j = j00 * j11 - j01 * j01
    out[0, 0], out[0, 1], out[0, 2] = j11 / det_j, 0.0 - j01 / det_j, j00 / det_j
    grown = 0.0
    for k in range(1, n):
        out[k, 0], out[k, 1], out[k, 2], grown = propagate(
            out[k - 1, 0], out[k - 1, 1], out[k - 1, 2], grown, drift_variance, steps[k - 1],
            white[k - 1], fisher[k, 0], fisher[k, 1], fisher[k, 2],
        )  # fmt: skip
    return out
