r"""Dead reckoning: what the vehicle's DVL and compass say it moved, and the filter's motion model.

The simulated odometry of one run perturbs each true displacement :math:`d_k` (north, east) as

.. math::

    \hat d_k = (1 + s)\, R(b)\, d_k + w_k, \qquad
    s, b \sim \mathcal N(0, \sigma_b^2) \text{ once per run}, \quad
    w_k \sim \mathcal N(0, (\sigma_v \Delta t_k)^2 I),

with :math:`s` a DVL scale-factor error (along track), :math:`b` a heading bias [rad] (across
track, :math:`R(b)` the rotation by ``b``) and :math:`w_k` white DVL velocity noise. Over a
straight leg of length :math:`D` the position error is then isotropic with standard deviation
:math:`\sigma_b D` per axis, so its circular error probable is
:math:`\mathrm{CEP} = \sqrt{2 \ln 2}\, \sigma_b D`; :math:`\sigma_b` is chosen so that the CEP is
``drift_fraction`` of the distance travelled.

The particle filter moves each particle by :math:`\hat d_k` plus Gaussian noise of standard
deviation per axis (MB-System's terrain-relative navigation, ``TNavParticleFilter.cpp``)

.. math::

    \sigma_k = \max\left(m \, \frac{\mathrm{drift} \cdot \|\hat d_k\|}{\sqrt{2 \ln 2}},\;
    \sigma_{min}\right).

(MB-System's code takes the square root of the CEP in metres there, a line its own comment
doubts; the form above keeps metres.)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.navigation._checks import require_nonnegative

#: Ratio CEP / sigma of an isotropic 2-D Gaussian: the median radius, sqrt(2 ln 2) = 1.1774.
CEP_PER_SIGMA: Final = float(np.sqrt(2.0 * np.log(2.0)))


@dataclass(frozen=True)
class DeadReckoningModel:
    """DVL + compass dead reckoning and the filter's process noise (defaults with sources).

    Parameters
    ----------
    drift_fraction : float
        CEP of the dead-reckoning position error as a fraction of the distance travelled.
        Default 0.01: MB-System's terrain-relative navigation default ``driftRate`` = 1 %
        (dwcaress/MB-System, ``src/mbtrnav/terrain-nav/TNavParticleFilter.cpp``). A
        navigation-grade INS aided by DVL does 0.1 % (river) to 0.2 % (sea) (Tang et al.,
        Sensors 13(11), 2013), so 0.001-0.03 is the range worth sweeping.
    velocity_noise : float
        White DVL velocity noise [m/s] per axis. Default 0.005: the ±0.5 cm/s term of the DVL
        of Tang et al. (2013) (0.5 % V ± 0.5 cm/s).
    noise_multiplier : float
        Factor ``m`` on the filter's process noise. Default 2.0: MB-System's
        ``MOTION_NOISE_MULTIPLIER``.
    noise_floor : float
        Floor ``sigma_min`` [m] of the filter's process noise per update. Default 0.25:
        MB-System's ``PF_NOISE_STDEV_MIN`` (zero noise when the vehicle stands still would
        freeze the filter).
    """

    drift_fraction: float = 0.01
    velocity_noise: float = 0.005
    noise_multiplier: float = 2.0
    noise_floor: float = 0.25

    def __post_init__(self) -> None:
        for name in ("drift_fraction", "velocity_noise", "noise_multiplier", "noise_floor"):
            require_nonnegative(f"dead reckoning {name}", getattr(self, name))

    @property
    def bias_sigma(self) -> float:
        """Standard deviation of the per-run scale error and heading bias [1, rad]."""
        return self.drift_fraction / CEP_PER_SIGMA


def simulate_odometry(
    model: DeadReckoningModel,
    displacements: FloatArray,
    intervals: FloatArray,
    rng: np.random.Generator,
) -> FloatArray:
    """Dead-reckoned displacements of one run (module notes).

    Parameters
    ----------
    model : DeadReckoningModel
        Error model.
    displacements : ndarray of shape (K, 2)
        True displacements ``north, east`` [m] between consecutive updates.
    intervals : ndarray of shape (K,)
        Their durations [s].
    rng : numpy.random.Generator
        The run's random stream (draws 2 + 2K normals).

    Returns
    -------
    ndarray of shape (K, 2)
        Measured displacements [m].
    """
    scale, bias = model.bias_sigma * rng.standard_normal(2)
    cos_b, sin_b = np.cos(bias), np.sin(bias)
    rotated = np.column_stack(
        [
            cos_b * displacements[:, 0] - sin_b * displacements[:, 1],
            sin_b * displacements[:, 0] + cos_b * displacements[:, 1],
        ]
    )
    white = model.velocity_noise * intervals[:, None] * rng.standard_normal(displacements.shape)
    return np.asarray((1.0 + scale) * rotated + white, dtype=np.float64)


def process_noise_sigma(model: DeadReckoningModel, increments: FloatArray) -> FloatArray:
    """The filter's process-noise standard deviation [m] per axis for each increment.

    Parameters
    ----------
    model : DeadReckoningModel
        Error model.
    increments : ndarray of shape (K, 2)
        Measured displacements [m].

    Returns
    -------
    ndarray of shape (K,)
        ``max(m * drift * |d| / sqrt(2 ln 2), sigma_min)`` (module notes).

    Examples
    --------
    >>> process_noise_sigma(DeadReckoningModel(), np.array([[0.5, 0.0], [100.0, 0.0]]))
    array([0.25     , 1.6986436])
    """
    distance = np.hypot(increments[:, 0], increments[:, 1])
    drift = model.noise_multiplier * model.drift_fraction * distance / CEP_PER_SIGMA
    return np.asarray(np.maximum(drift, model.noise_floor), dtype=np.float64)


def dead_reckon(initial: FloatArray, increments: FloatArray) -> FloatArray:
    """Track ``(K + 1, 2)`` [m] from an initial position ``(2,)`` and increments ``(K, 2)``.

    Examples
    --------
    >>> dead_reckon(np.array([1.0, 2.0]), np.array([[1.0, 0.0], [0.0, 3.0]]))
    array([[1., 2.],
           [2., 2.],
           [2., 5.]])
    """
    steps = np.vstack([initial[None, :], increments])
    return np.asarray(np.cumsum(steps, axis=0), dtype=np.float64)
