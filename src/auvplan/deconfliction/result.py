"""The result of temporal deconfliction: time laws, arrivals and a separation certificate."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from auvplan._typing import FloatArray


class DeconflictionMethod(enum.StrEnum):
    """The coordination-space search; the plain strings are accepted too.

    ``AUTO`` chooses and falls back by itself (:func:`auvplan.deconfliction.deconflict`).
    """

    AUTO = "auto"
    ASTAR = "astar"
    PRIORITIZED = "prioritized"


class CoordinationStatus(enum.Enum):
    """How good the returned schedule is (every returned schedule is certified safe)."""

    OPTIMAL = "optimal"
    """A* with ``weight = 1``: lexicographic (makespan, total delay) optimum on the grid."""
    BOUNDED_SUBOPTIMAL = "bounded_suboptimal"
    """Weighted A*: makespan at most ``weight`` times the grid optimum."""
    FEASIBLE = "feasible"
    """Prioritised planning: safe, each vehicle arrives as early as the earlier ones allow."""


@dataclass(frozen=True)
class SeparationCertificate:
    """A lower bound on the pairwise distance over the whole continuous schedule.

    Parameters
    ----------
    min_separation : float
        Certified lower bound [m] on every pairwise distance at every time (not only at
        samples): ``min over pairs and steps of (d_a + d_b - Δs_i - Δs_j) / 2``.
    pair : tuple of int
        The pair ``(i, j)``, ``i < j``, attaining it (``(-1, -1)`` for a single vehicle).
    time : float
        Time [s] at which the bound is attained.
    min_sampled_separation : float
        Smallest pairwise distance [m] at the samples themselves (>= ``min_separation``).
    required : float
        ``2 r_c`` [m].
    """

    min_separation: float
    pair: tuple[int, int]
    time: float
    min_sampled_separation: float
    required: float

    @property
    def holds(self) -> bool:
        """True when ``min_separation >= 2 r_c`` (up to 1e-9 m of rounding)."""
        return self.min_separation >= self.required - 1e-9


@dataclass(frozen=True, eq=False)
class CoordinationResult:
    """Time laws along fixed paths that keep every pair at least ``2 r_c`` apart.

    Between samples every vehicle moves linearly in arc length (constant speed), so the
    schedule is defined for all ``t``; the certificate covers all ``t`` (see
    :func:`auvplan.deconfliction.certify_separation`).

    Parameters
    ----------
    status : CoordinationStatus
        Quality of the schedule.
    message : str
        One line for humans.
    method : DeconflictionMethod
        The search that produced the schedule: ``ASTAR`` or ``PRIORITIZED``.
    weight : float
        Heuristic weight of A* (``nan`` for the prioritised method).
    time : ndarray of shape (n_t,)
        Common time grid [s], from 0.
    progress : ndarray of shape (n_vehicles, n_t)
        Arc length [m] along each vehicle's own path, non-decreasing, from 0 to its length.
    arrival_times : ndarray of shape (n_vehicles,)
        First time [s] each vehicle reaches its goal.
    delays : ndarray of shape (n_vehicles,)
        ``arrival_times - L_i / v_i`` [s] (>= 0; includes < one time step of grid rounding).
    certificate : SeparationCertificate
        The continuous separation bound of this schedule.
    n_expanded : int
        Search effort: expanded A* nodes, or (grid index, safe interval) states visited.
    objective : tuple of float
        What the search minimised, lexicographically: ``(makespan [s], total delay [s])``
        for A*; for the prioritised method the same numbers of the returned schedule (each
        vehicle minimised its own arrival time in turn).
    """

    status: CoordinationStatus
    message: str
    method: DeconflictionMethod
    weight: float
    time: FloatArray
    progress: FloatArray
    arrival_times: FloatArray
    delays: FloatArray
    certificate: SeparationCertificate
    n_expanded: int
    objective: tuple[float, float]
    fallback: str = ""
    speeds: FloatArray | None = None
    within_limits: tuple[bool, ...] = ()

    @property
    def success(self) -> bool:
        """True when the schedule is certified collision-free."""
        return self.certificate.holds

    @property
    def min_separation(self) -> float:
        """Certified minimum pairwise distance [m] over continuous time."""
        return self.certificate.min_separation

    @property
    def min_separation_pair(self) -> tuple[int, int]:
        """The pair ``(i, j)`` attaining :attr:`min_separation`."""
        return self.certificate.pair

    @property
    def min_separation_time(self) -> float:
        """Time [s] at which :attr:`min_separation` is attained."""
        return self.certificate.time

    @property
    def makespan(self) -> float:
        """Latest arrival time [s]."""
        return float(self.arrival_times.max())
