r"""Seabed-depth sensors: a single-beam altimeter or a multibeam swath (defaults with sources).

Each beam ``j`` of a sensor looks down at an angle :math:`\theta_j` across track (positive to
starboard), evenly spread over the swath. With the vehicle at depth :math:`z_v` over seabed
depth :math:`h` (altitude :math:`a = h - z_v`), the beam's footprint lies (flat-seabed
geometry) :math:`a \tan\theta_j` to starboard, i.e. at the offset
:math:`a \tan\theta_j\, (-\sin\psi, \cos\psi)` in (north, east) for heading :math:`\psi`, at
slant range :math:`\rho_j = a / \cos\theta_j`. The sounding is the seabed depth there,

.. math::

    z_j = h(p + o_j) + \varepsilon_j, \qquad
    \varepsilon_j \sim \mathcal N\left(0,\; \sigma_{map}^2 + (\kappa \rho_j)^2\right),

the variance the filter's likelihood uses too (MB-System: map variance plus the beam's
``(percentRangeError · range)²``), so the simulated measurements match the filter's model.
The footprint offsets are known to the filter (they follow from the measured range and beam
angle); only the depth carries noise. Map error is modelled as white, per sounding.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.navigation._checks import require_nonnegative
from auvplan.navigation.depth import depth_at
from auvplan.terrain import BathymetryGrid

SensorKind = Literal["altimeter", "multibeam"]


@dataclass(frozen=True)
class SensorModel:
    """A seabed-depth sensor and the noise of its soundings.

    Parameters
    ----------
    n_beams : int
        Beams per ping (1 for an altimeter).
    swath_angle : float
        Full across-track swath [rad] (0 for an altimeter).
    range_error_fraction : float
        Standard deviation of a beam's range as a fraction ``kappa`` of the range. Default
        0.01: 1 % of range, MB-System TRN's ``percentRangeError`` for DVL/altimeter beams.
    map_variance : float
        Variance [m²] added for the map's own error. Default 1.0 m²: MB-System TRN's
        ``mapVar`` (``TNavParticleFilter::measUpdate``).
    vehicle_depth : float
        Depth [m] of the vehicle (0: at the surface, as a MEDUSA usually is); the altitude is
        the seabed depth minus this.
    """

    n_beams: int = 1
    swath_angle: float = 0.0
    range_error_fraction: float = 0.01
    map_variance: float = 1.0
    vehicle_depth: float = 0.0

    def __post_init__(self) -> None:
        if self.n_beams < 1:
            raise InputError(f"sensor n_beams must be >= 1, got {self.n_beams}")
        if not 0.0 <= self.swath_angle < math.pi:
            raise InputError(f"sensor swath_angle must be in [0, pi) rad, got {self.swath_angle}")
        for name in ("range_error_fraction", "map_variance", "vehicle_depth"):
            require_nonnegative(f"sensor {name}", getattr(self, name))
        if self.map_variance == 0.0 and self.range_error_fraction == 0.0:
            raise InputError("sensor needs a non-zero map_variance or range_error_fraction")

    @classmethod
    def altimeter(cls) -> SensorModel:
        """A single vertical beam (an altimeter or a DVL's range)."""
        return cls()

    @classmethod
    def multibeam(cls) -> SensorModel:
        """11 soundings over a 90° swath: MB-System ``mbtrnpp``'s example configuration.

        (``soundings=11``, ``swath-width=90`` in ``src/mbtrn/tools/cfg/mbtrnpp-cfg.example``.)
        """
        return cls(n_beams=11, swath_angle=math.radians(90.0))

    @classmethod
    def named(cls, kind: SensorKind) -> SensorModel:
        """The default sensor of a kind, ``"altimeter"`` or ``"multibeam"``."""
        if kind == "altimeter":
            return cls.altimeter()
        if kind == "multibeam":
            return cls.multibeam()
        raise InputError(f"sensor must be 'altimeter' or 'multibeam', got {kind!r}")

    @property
    def beam_angles(self) -> FloatArray:
        """Across-track beam angles [rad], shape ``(n_beams,)``, starboard positive."""
        half = 0.5 * self.swath_angle
        return np.linspace(-half, half, self.n_beams) if self.n_beams > 1 else np.zeros(1)


def beam_geometry(
    sensor: SensorModel,
    grid: BathymetryGrid,
    positions: FloatArray,
    heading: FloatArray,
    *,
    vehicle_depth: FloatArray | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Footprint offsets and likelihood variances of every beam along a track.

    Parameters
    ----------
    sensor : SensorModel
        The sensor.
    grid : BathymetryGrid
        The seabed.
    positions : ndarray of shape (n, 2)
        True positions ``north, east`` [m].
    heading : ndarray of shape (n,)
        Heading [rad], clockwise from north.
    vehicle_depth : ndarray of shape (n,), optional
        The vehicle's depth [m] at each position (a depth profile); ``None``: the sensor's
        constant ``vehicle_depth``. The altitude is the seabed depth minus it.

    Returns
    -------
    offsets : ndarray of shape (n, n_beams, 2)
        Footprint offsets ``north, east`` [m] from the vehicle (module notes); NaN where the
        vehicle is over no data or not above the seabed.
    variances : ndarray of shape (n, n_beams)
        ``map_variance + (range_error_fraction * range)²`` [m²].
    """
    depth = sensor.vehicle_depth if vehicle_depth is None else vehicle_depth
    altitude = depth_at(grid, positions[:, 0], positions[:, 1]) - depth
    altitude = np.where(altitude > 0.0, altitude, np.nan)
    angles = sensor.beam_angles
    across = altitude[:, None] * np.tan(angles)[None, :]
    offsets = np.stack(
        [-np.sin(heading)[:, None] * across, np.cos(heading)[:, None] * across], axis=-1
    )
    slant = altitude[:, None] / np.cos(angles)[None, :]
    variances = sensor.map_variance + (sensor.range_error_fraction * slant) ** 2
    return offsets, variances


def simulate_soundings(
    grid: BathymetryGrid,
    positions: FloatArray,
    offsets: FloatArray,
    variances: FloatArray,
    rng: np.random.Generator,
) -> FloatArray:
    """Noisy seabed depths [m] ``(n, n_beams)`` at the beam footprints of true ``positions``.

    NaN where a footprint has no depth (off the map, on no-data cells, no altitude). Draws
    ``n * n_beams`` normals from ``rng``.
    """
    north = positions[:, 0, None] + offsets[..., 0]
    east = positions[:, 1, None] + offsets[..., 1]
    noise = np.sqrt(variances) * rng.standard_normal(variances.shape)
    return np.asarray(depth_at(grid, north, east) + noise, dtype=np.float64)
