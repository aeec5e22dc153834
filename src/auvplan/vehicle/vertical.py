"""A vehicle type's vertical limits: how fast it may climb and dive, how near the seabed it may go.

The optimiser's model is planar (3-DOF: surge, sway, yaw); the depth a plan is flown at is a
profile along the optimised track (:mod:`auvplan.mission.depth_profile`) bounded by these
limits. A vehicle file gives them in its optional ``[vertical]`` table
(:class:`auvplan.io.vehicle_tables.VerticalTable`); a file without it gets the defaults here.

Sources. Neither reference set gives a climb or dive rate or a minimum altitude for the
packaged types: the MEDUSA notes (``reference/vehicle.md``, DSOR's stacks) describe the planar
surface craft of the paper, and Fossen's ``remus100.py`` (``reference/navigation-fleets-
formats.md`` §2) models the REMUS 100's heave and pitch (stern planes ±30°, a depth autopilot,
depths of 0 to 100 m) without stating a rate. Every figure below is therefore a stated
engineering assumption, derived in the vehicle files (``data/vehicles/*.toml``, ``[vertical]``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

from auvplan.errors import InputError

#: Default climb and dive rate [m/s] of a vehicle file without ``[vertical]`` (assumption):
#: 0.2 m/s, the slower of the packaged types' rates, so that an unknown vehicle is not asked
#: for more than the slowest known one gives.
DEFAULT_VERTICAL_RATE: Final = 0.2
#: Default minimum altitude above the seabed [m] (assumption): 2 m, about one hull length of
#: the packaged types (1 m MEDUSA, 1.6 m REMUS 100) of clearance.
DEFAULT_MIN_ALTITUDE: Final = 2.0


@dataclass(frozen=True)
class DepthLimits:
    """Vertical limits of a vehicle type.

    Parameters
    ----------
    climb_rate : float
        Largest rate of ascent [m/s]: the depth ``z`` (positive down) obeys
        ``-dz/dt <= climb_rate``.
    dive_rate : float
        Largest rate of descent [m/s]: ``dz/dt <= dive_rate``.
    min_altitude : float
        Smallest height above the seabed [m], a hard bound: ``z <= seabed - min_altitude``.

    Raises
    ------
    InputError
        If a rate is not finite and > 0 or the altitude not finite and >= 0.

    Examples
    --------
    >>> DepthLimits(climb_rate=0.3, dive_rate=0.3, min_altitude=3.0).climb_rate
    0.3
    """

    climb_rate: float = DEFAULT_VERTICAL_RATE
    dive_rate: float = DEFAULT_VERTICAL_RATE
    min_altitude: float = DEFAULT_MIN_ALTITUDE

    def __post_init__(self) -> None:
        for name in ("climb_rate", "dive_rate"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise InputError(
                    f"vehicle parameter vertical.{name} must be > 0 m/s, got {value!r}"
                )
        if not (math.isfinite(self.min_altitude) and self.min_altitude >= 0.0):
            raise InputError(
                f"vehicle parameter vertical.min_altitude must be >= 0 m, got {self.min_altitude!r}"
            )


__all__ = ["DEFAULT_MIN_ALTITUDE", "DEFAULT_VERTICAL_RATE", "DepthLimits"]
