r"""Navigation metrics of one run: RMSE, NEES, convergence time and divergence.

* **RMSE** :math:`\sqrt{\frac{1}{K+1}\sum_k \|\hat x_k - x_k\|^2}` [m] over every update.
* **NEES** (normalised estimation error squared, Bar-Shalom, Li and Kirubarajan, *Estimation
  with Applications to Tracking and Navigation*, 2001, Sec. 5.4):
  :math:`\epsilon_k = e_k^\top P_k^{-1} e_k`; for a consistent filter its mean is the state
  dimension, 2.
* **Convergence** (MB-System ``mbtrnpp``'s rule): the filter has converged once its position
  standard deviation :math:`\sqrt{P_{nn} + P_{ee}}` has stayed at or below 5 m for 200
  consecutive updates (``covariance-magnitude-max``, ``convergence-repeat-min``; MB-System also
  counts the depth variance, which this planar filter does not estimate).
* **Divergence**: the true error lies outside the filter's 3-sigma ellipse
  (:math:`\epsilon_k > 9`) for a sustained window of consecutive updates. For a consistent
  Gaussian estimate a single update is outside with probability :math:`e^{-9/2} = 1.1\%`.
"""

from __future__ import annotations

from typing import Final

import numpy as np

from auvplan._typing import BoolArray, FloatArray

#: MB-System ``mbtrnpp`` convergence rule: position sigma [m] and consecutive updates.
CONVERGENCE_SIGMA_M: Final = 5.0
CONVERGENCE_UPDATES: Final = 200
#: Divergence: Mahalanobis radius of the error, and consecutive updates it must persist.
DIVERGENCE_SIGMAS: Final = 3.0
DIVERGENCE_UPDATES: Final = 30


def rmse(error: FloatArray) -> FloatArray:
    """Root mean square [m] over the last axis of position error norms ``(..., K + 1)`` [m].

    Examples
    --------
    >>> rmse(np.array([[3.0, 4.0, 0.0, 0.0], [1.0, 1.0, 1.0, 1.0]]))
    array([2.5, 1. ])
    """
    squared = np.asarray(error, dtype=np.float64) ** 2
    return np.asarray(np.sqrt(np.mean(squared, axis=-1)), dtype=np.float64)


def nees(errors: FloatArray, covariance: FloatArray) -> FloatArray:
    r""":math:`e_k^\top P_k^{-1} e_k` for errors ``(K + 1, 2)`` and covariances ``(K + 1, 2, 2)``.

    A singular covariance gives ``inf`` unless the error is zero along its null direction.

    Examples
    --------
    >>> nees(np.array([[3.0, 4.0]]), np.array([[[9.0, 0.0], [0.0, 4.0]]]))
    array([5.])
    """
    p_nn, p_ee, p_ne = covariance[:, 0, 0], covariance[:, 1, 1], covariance[:, 0, 1]
    e_n, e_e = errors[:, 0], errors[:, 1]
    determinant = p_nn * p_ee - p_ne * p_ne
    quadratic = p_ee * e_n**2 - 2.0 * p_ne * e_n * e_e + p_nn * e_e**2
    with np.errstate(divide="ignore", invalid="ignore"):
        value = quadratic / determinant
    value = np.where(determinant > 0.0, value, np.where(quadratic > 0.0, np.inf, 0.0))
    return np.asarray(value, dtype=np.float64)


def first_run_end(flags: BoolArray, length: int) -> int | None:
    """Index at which ``flags`` first completes ``length`` consecutive ``True`` values.

    Examples
    --------
    >>> first_run_end(np.array([True, False, True, True, True]), 2)
    3
    >>> first_run_end(np.array([True, False]), 2) is None
    True
    """
    count = 0
    for index, flag in enumerate(np.asarray(flags, dtype=bool)):
        count = count + 1 if flag else 0
        if count >= length:
            return index
    return None


def convergence_time(
    time: FloatArray,
    sigma: FloatArray,
    *,
    threshold: float = CONVERGENCE_SIGMA_M,
    n_updates: int = CONVERGENCE_UPDATES,
) -> float:
    """Time [s] at which the convergence rule (module notes) is first met; NaN if never.

    Parameters
    ----------
    time : ndarray of shape (K + 1,)
        Update times [s].
    sigma : ndarray of shape (K + 1,)
        Filter position standard deviation [m].
    threshold : float
        Largest sigma [m] counted as converged.
    n_updates : int
        Consecutive updates required.
    """
    index = first_run_end(sigma <= threshold, n_updates)
    return float("nan") if index is None else float(time[index])


def has_diverged(
    nees_values: FloatArray,
    *,
    n_sigmas: float = DIVERGENCE_SIGMAS,
    n_updates: int = DIVERGENCE_UPDATES,
) -> bool:
    """True when the error stays outside the ``n_sigmas`` ellipse for ``n_updates`` in a row."""
    return first_run_end(nees_values > n_sigmas**2, n_updates) is not None
