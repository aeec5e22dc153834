r"""Predicted TAN error along a path: the information recursion with dead-reckoning drift.

The planner needs to know, cheaply and before any Monte-Carlo run, how well a vehicle will
know its position along a path. Per TAN update (every ``update_period`` seconds) the
covariance :math:`P` of the position error (north, east) follows
(:mod:`~auvplan.navigation._prediction_kernel`)

.. math::

    P^- = P + \max\left(\sigma_b^2 \left((d + \ell_k)^2 - d^2\right), q_k\right) I, \qquad
    P^+ = \left((P^-)^{-1} + \sum_j \frac{\nabla h_j \nabla h_j^\top}{r_j}\right)^{-1},

* :math:`\sigma_b`: the DVL scale and heading biases of
  :class:`~auvplan.navigation.DeadReckoningModel` make the error of a straight leg grow
  linearly, :math:`\sigma_b D` per axis (CEP = ``drift`` × D); :math:`d` is the distance
  flown since the last fixes (shrunk with the error by each fix), :math:`\ell_k` the step
  (details in :mod:`~auvplan.navigation._prediction_kernel`);
* :math:`q_k`: the filter's own process variance per update
  (:func:`~auvplan.navigation.process_noise_sigma`, MB-System's rule) — the rate at which the
  filter forgets, which bounds its accuracy over informative terrain;
* :math:`\nabla h_j`, :math:`r_j`: seabed gradient and sounding variance at each beam's
  footprint (:func:`~auvplan.navigation.beam_geometry`). A flat seabed adds nothing, and the
  error grows at the drift rate.

Starting from :math:`P_0 = \sigma_0^2 I` (``initial_sigma``). The predicted error is the 1-σ
radial error :math:`\sqrt{\operatorname{tr} P}` [m], the quantity the particle filter's RMSE
is compared with. Without drift this is the posterior Cramér-Rao bound of
:mod:`~auvplan.navigation.pcrb`.

:func:`fisher_map` precomputes the per-update Fisher information of every cell of a planning
grid, so that a search can run the same recursion move by move
(:mod:`auvplan.planning.belief`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.navigation._prediction_kernel import covariance_recursion
from auvplan.navigation.depth import depth_at
from auvplan.navigation.montecarlo import NavigationSettings, Track
from auvplan.navigation.motion import process_noise_sigma
from auvplan.navigation.pcrb import sounding_information, unpack_covariance
from auvplan.navigation.sensors import SensorModel, beam_geometry
from auvplan.terrain import BathymetryGrid, GridGeometry

#: Headings [rad] over which a swath sensor's information is averaged in :func:`fisher_map`
#: (a swath is symmetric, so [0, π) covers every direction).
SWATH_HEADINGS: Final = tuple(k * math.pi / 4.0 for k in range(4))


@dataclass(frozen=True)
class ErrorPrediction:
    """Predicted position error at the TAN updates of one track.

    ``time`` ``(n,)`` [s], ``positions`` ``(n, 2)`` [m], ``covariance`` ``(n, 2, 2)`` [m²].
    """

    time: FloatArray
    positions: FloatArray
    covariance: FloatArray

    @property
    def sigma(self) -> FloatArray:
        r"""1-σ radial error :math:`\sqrt{\operatorname{tr} P}` [m] at each update."""
        return np.asarray(np.sqrt(np.trace(self.covariance, axis1=1, axis2=2)), np.float64)

    @property
    def rms(self) -> float:
        """Root mean square of :attr:`sigma` over the updates [m] (comparable to a TAN RMSE)."""
        return float(np.sqrt(np.mean(self.sigma**2)))

    def peak_after(self, settle_s: float) -> float:
        """Largest :attr:`sigma` [m] after the first ``settle_s`` seconds (0 if none)."""
        late = self.sigma[self.time - self.time[0] >= settle_s]
        return float(np.max(late)) if late.size else 0.0


def predict_error(
    grid: BathymetryGrid, track: Track, settings: NavigationSettings
) -> ErrorPrediction:
    r"""The predicted error (module notes) at every TAN update along ``track``.

    Parameters
    ----------
    grid : BathymetryGrid
        The seabed.
    track : Track
        The planned track, sampled every ``settings.update_period``.
    settings : NavigationSettings
        Sensor, dead reckoning, initial error and update period (the evaluator's model).

    Returns
    -------
    ErrorPrediction

    Examples
    --------
    Over a flat seabed the error grows at the drift rate, as dead reckoning's,
    :math:`\sqrt{2 (\sigma_0^2 + \sigma_b^2 D^2)}` radially (here without the filter's
    process noise):

    >>> from auvplan.navigation import DeadReckoningModel, ParticleFilterOptions
    >>> grid = BathymetryGrid(np.full((50, 50), 40.0), GridGeometry(50, 50, 100.0, 100.0))
    >>> settings = NavigationSettings(
    ...     motion=DeadReckoningModel(noise_floor=0.0, noise_multiplier=0.0),
    ...     filter=ParticleFilterOptions(initial_sigma=5.0))
    >>> east = np.linspace(100.0, 3100.0, 5)
    >>> track = Track(np.linspace(0.0, 3000.0, 5), np.column_stack([east * 0 + 2000.0, east]),
    ...               np.full(5, np.pi / 2))
    >>> prediction = predict_error(grid, track, settings)
    >>> bias = settings.motion.bias_sigma
    >>> bool(np.isclose(prediction.sigma[-1], np.sqrt(2.0 * (25.0 + (bias * 3000.0) ** 2))))
    True
    """
    samples = track.sampled(settings.update_period)
    positions = samples.positions
    offsets, variances = beam_geometry(
        settings.sensor, grid, positions, samples.heading, vehicle_depth=samples.depth
    )
    fisher = sounding_information(grid, positions, offsets, variances)
    steps = np.diff(positions, axis=0)
    packed = covariance_recursion(
        fisher[:, [0, 0, 1], [0, 1, 1]],
        np.hypot(steps[:, 0], steps[:, 1]),
        process_noise_sigma(settings.motion, steps) ** 2,
        settings.filter.initial_sigma**2,
        settings.motion.bias_sigma**2,
    )
    return ErrorPrediction(samples.time, positions, unpack_covariance(packed))


def fisher_map(
    grid: BathymetryGrid,
    geometry: GridGeometry,
    sensor: SensorModel,
    *,
    samples: int = 2,
    altitude: float | None = None,
) -> FloatArray:
    r"""Per-update Fisher information :math:`F` [1/m²] of every cell of ``geometry``.

    The mean of :func:`~auvplan.navigation.pcrb.sounding_information` over ``samples`` ×
    ``samples`` points spread evenly inside each cell (the seabed a vehicle crossing the cell
    sounds); for a swath sensor also over the headings :data:`SWATH_HEADINGS` (the
    heading-averaged information; an altimeter's does not depend on heading). Cells without
    a sounding (land, no data, off the map) get 0. With ``altitude`` [m] the vehicle follows
    the seabed at that height (``[mission] altitude_m``; depth ``max(h - altitude, 0)``)
    instead of flying at the sensor's constant ``vehicle_depth``.

    Returns
    -------
    ndarray of shape (n_rows, n_cols, 3)
        :math:`F_{nn}, F_{ne}, F_{ee}` per cell.
    """
    fractions = (np.arange(samples) + 0.5) / samples - 0.5
    inside_north = geometry.spacing_north * fractions[None, None, :, None]
    inside_east = geometry.spacing_east * fractions[None, None, None, :]
    north, east = np.broadcast_arrays(
        geometry.north[:, None, None, None] + inside_north,
        geometry.east[None, :, None, None] + inside_east,
    )
    points = np.column_stack([north.ravel(), east.ravel()])
    headings = SWATH_HEADINGS if sensor.n_beams > 1 else (0.0,)
    total = np.zeros((points.shape[0], 2, 2))
    depth = None
    if altitude is not None:
        depth = np.maximum(
            np.nan_to_num(depth_at(grid, points[:, 0], points[:, 1])) - altitude, 0.0
        )
    for heading in headings:
        offsets, variances = beam_geometry(
            sensor, grid, points, np.full(points.shape[0], heading), vehicle_depth=depth
        )
        total += sounding_information(grid, points, np.nan_to_num(offsets), variances)
    mean = total.reshape(*geometry.shape, samples * samples, 2, 2).mean(axis=2) / len(headings)
    return np.ascontiguousarray(mean[..., [0, 0, 1], [0, 1, 1]])
