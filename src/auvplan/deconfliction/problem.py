r"""The temporal-deconfliction problem: fixed geometric paths, one time law per vehicle.

A vehicle ``i`` follows a fixed polyline ``p_i(s)``, ``s`` its arc length in metres
``0 <= s <= L_i``. Deconfliction chooses the time laws ``s_i(t)`` (monotone non-decreasing)
so that every pair keeps

.. math::

    \lVert p_i(s_i(t)) - p_j(s_j(t)) \rVert \ge 2 r_c \quad \forall t,

without changing any path (SPEC §2; paper Sec. III-B; LaValle, *Planning Algorithms*,
Sec. 7.2).

The coordination grid
---------------------
Time is gridded with step ``dt``. In one step vehicle ``i`` either waits or advances one
arc-length step ``h_i = v_i dt`` at its cruise speed ``v_i``; its grid progress
``k_i = 0 … n_i`` with ``n_i = ceil(L_i / h_i)`` maps to ``s = min(k_i h_i, L_i)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from auvplan._typing import FloatArray, IntArray
from auvplan.errors import InputError

#: Upper bound on grid steps per vehicle (about 28 h at 0.01 s); keeps index arithmetic in int64.
MAX_STEPS_PER_VEHICLE = 10_000_000


@dataclass(frozen=True, eq=False)
class CoordinationProblem:
    """Fixed paths of a fleet, to be timed apart.

    Parameters
    ----------
    paths : tuple of ndarray of shape (n_i, 2)
        Per vehicle its polyline ``[north, east]`` [m], at least two points, consecutive
        points may repeat (zero-length segments are ignored), total length > 0.
    safety_radius : float
        ``r_c`` [m], > 0; every pair must keep a distance of at least ``2 r_c``.
    cruise_speeds : ndarray of shape (n_vehicles,)
        Nominal (and maximal) speed along the path [m/s], > 0. The nominal schedule runs the
        whole path at this speed from ``t = 0``; deconfliction only waits or slows down.
    time_step : float
        Grid step ``dt`` [s], > 0 (the paper uses 0.01 s).
    names : tuple of str
        Optional vehicle names used in messages (default: the vehicle indices).
    min_speeds : ndarray of shape (n_vehicles,), optional
        Smallest useful speed along the path [m/s], ``0 <= min_speeds <= cruise_speeds``
        (default 0). :func:`~auvplan.deconfliction.retime_for_arrival` keeps the speed above
        it wherever the schedule allows (waiting by slowing down, not stopping).
    max_accelerations : ndarray of shape (n_vehicles,), optional
        Largest speed change along the path [m/s²], > 0 (default inf: no bound). The
        retimed laws ramp their speed within it wherever the schedule allows.

    Examples
    --------
    >>> problem = CoordinationProblem(
    ...     paths=(np.array([[0.0, 0.0], [10.0, 0.0]]), np.array([[5.0, -5.0], [5.0, 5.0]])),
    ...     safety_radius=1.0,
    ...     cruise_speeds=np.array([1.0, 1.0]),
    ...     time_step=0.1,
    ... )
    >>> problem.n_vehicles, problem.path_lengths.tolist(), problem.n_steps.tolist()
    (2, [10.0, 10.0], [100, 100])
    """

    paths: tuple[FloatArray, ...]
    safety_radius: float
    cruise_speeds: FloatArray
    time_step: float
    names: tuple[str, ...] = ()
    min_speeds: FloatArray | None = None
    max_accelerations: FloatArray | None = None
    # derived, filled in __post_init__ (not constructor arguments)
    arc_lengths: tuple[FloatArray, ...] = field(init=False, repr=False, compare=False)
    path_lengths: FloatArray = field(init=False, repr=False, compare=False)
    step_lengths: FloatArray = field(init=False, repr=False, compare=False)
    n_steps: IntArray = field(init=False, repr=False, compare=False)

    def label(self, vehicle: int) -> str:
        """The name of ``vehicle`` for messages (its index when no names were given)."""
        return self.names[vehicle] if self.names else str(vehicle)

    def __post_init__(self) -> None:
        if not isinstance(self.paths, tuple) or len(self.paths) < 1:
            raise InputError(f"paths must be a non-empty tuple of arrays, got {type(self.paths)}")
        if self.names and len(self.names) != len(self.paths):
            raise InputError(f"{len(self.names)} names given for {len(self.paths)} paths")
        n_vehicles = len(self.paths)
        cleaned: list[FloatArray] = []
        arcs: list[FloatArray] = []
        for index, raw in enumerate(self.paths):
            path = np.asarray(raw, dtype=np.float64)
            if path.ndim != 2 or path.shape[1] != 2 or path.shape[0] < 2:
                raise InputError(
                    f"path {index} must have shape (n >= 2, 2) [north, east], got {path.shape}"
                )
            if not np.all(np.isfinite(path)):
                raise InputError(f"path {index} contains non-finite coordinates")
            segment = np.hypot(*np.diff(path, axis=0).T)
            keep = np.concatenate(([True], segment > 0.0))
            path = np.array(path[keep], dtype=np.float64, order="C")
            path.flags.writeable = False
            if path.shape[0] < 2:
                raise InputError(f"path {index} has zero length (start equals goal)")
            cleaned.append(path)
            arcs.append(np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T)))))
        if not (np.isfinite(self.safety_radius) and self.safety_radius > 0.0):
            raise InputError(f"safety_radius must be > 0 m, got {self.safety_radius}")
        speeds = np.array(self.cruise_speeds, dtype=np.float64)
        if speeds.shape != (n_vehicles,):
            raise InputError(
                f"cruise_speeds must have shape ({n_vehicles},), got {np.shape(self.cruise_speeds)}"
            )
        if not np.all(np.isfinite(speeds) & (speeds > 0.0)):
            raise InputError(f"cruise_speeds must be > 0 m/s, got {speeds.tolist()}")
        if not (np.isfinite(self.time_step) and self.time_step > 0.0):
            raise InputError(f"time_step must be > 0 s, got {self.time_step}")
        speeds.flags.writeable = False
        slowest = self._per_vehicle("min_speeds", self.min_speeds, 0.0)
        if not np.all((slowest >= 0.0) & (slowest <= speeds)):
            raise InputError(
                f"min_speeds must lie in [0, cruise_speeds] m/s, got {slowest.tolist()}"
            )
        accelerations = self._per_vehicle("max_accelerations", self.max_accelerations, np.inf)
        if not np.all(accelerations > 0.0):
            raise InputError(f"max_accelerations must be > 0 m/s², got {accelerations.tolist()}")
        lengths = np.array([arc[-1] for arc in arcs])
        steps = speeds * self.time_step
        # in floating point first: a tiny speed must not overflow the integer step count.
        # The small tolerance keeps L = 60.0, h = 0.01 at 6000 steps, not 6001 by rounding
        n_float = np.ceil(lengths / steps * (1.0 - 1e-12))
        if not np.all(n_float <= MAX_STEPS_PER_VEHICLE):  # also catches inf and nan
            worst = int(np.argmax(np.where(np.isfinite(n_float), n_float, np.inf)))
            raise InputError(
                f"vehicle {self.label(worst)} needs {n_float[worst]:.3g} grid steps "
                f"(> {MAX_STEPS_PER_VEHICLE}) for its {lengths[worst]:.0f} m path at "
                f"{speeds[worst]:.3g} m/s with time_step = {self.time_step:g} s; raise the "
                "cruise speed (fleet.cruise_speed, or a shorter fleet.horizon_s) or "
                "deconfliction.time_step_s"
            )
        n_steps = np.maximum(n_float.astype(np.int64), 1)
        object.__setattr__(self, "paths", tuple(cleaned))
        object.__setattr__(self, "cruise_speeds", speeds)
        object.__setattr__(self, "min_speeds", slowest)
        object.__setattr__(self, "max_accelerations", accelerations)
        object.__setattr__(self, "arc_lengths", tuple(arcs))
        object.__setattr__(self, "path_lengths", lengths)
        object.__setattr__(self, "step_lengths", steps)
        object.__setattr__(self, "n_steps", n_steps)

    def _per_vehicle(self, name: str, values: FloatArray | None, default: float) -> FloatArray:
        """``values`` as a read-only float array of shape (n_vehicles,), or ``default``."""
        n_vehicles = len(self.paths)
        array = np.full(n_vehicles, default) if values is None else np.array(values, dtype=float)
        if array.shape != (n_vehicles,) or np.any(np.isnan(array)):
            raise InputError(
                f"{name} must have shape ({n_vehicles},) without NaN, got {array.shape}"
            )
        array.flags.writeable = False
        return array

    @property
    def n_vehicles(self) -> int:
        """Number of vehicles."""
        return len(self.paths)

    @property
    def separation(self) -> float:
        """Required pairwise distance ``2 r_c`` [m]."""
        return 2.0 * self.safety_radius

    @property
    def nominal_arrival_times(self) -> FloatArray:
        """Nominal arrival times ``L_i / v_i`` [s] (cruise speed, no wait), shape (n_vehicles,)."""
        return self.path_lengths / self.cruise_speeds

    def grid_progress(self, vehicle: int, k: IntArray) -> FloatArray:
        """Arc length [m] of grid indices ``k``: ``k h_i`` below ``n_i``, ``L_i`` at ``n_i``."""
        k = np.asarray(k)
        length = self.path_lengths[vehicle]
        s = np.minimum(k.astype(np.float64) * self.step_lengths[vehicle], length)
        return np.asarray(np.where(k >= self.n_steps[vehicle], length, s), dtype=np.float64)

    def grid_points(self, vehicle: int) -> FloatArray:
        """Positions ``[north, east]`` [m] of all grid progress values, shape (n_i + 1, 2)."""
        s = self.grid_progress(vehicle, np.arange(self.n_steps[vehicle] + 1))
        return positions_along(self.paths[vehicle], self.arc_lengths[vehicle], s)


def positions_along(path: FloatArray, arc: FloatArray, s: FloatArray) -> FloatArray:
    """Points of a polyline at arc lengths ``s`` (clamped to ``[0, L]``), shape (..., 2) [m].

    Examples
    --------
    >>> path = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 4.0]])
    >>> arc = np.array([0.0, 3.0, 7.0])
    >>> positions_along(path, arc, np.array([1.5, 5.0])).tolist()
    [[1.5, 0.0], [3.0, 2.0]]
    """
    s = np.clip(np.asarray(s, dtype=np.float64), 0.0, arc[-1])
    north = np.interp(s, arc, path[:, 0])
    east = np.interp(s, arc, path[:, 1])
    return np.stack([north, east], axis=-1)


def headings_along(path: FloatArray, arc: FloatArray, s: FloatArray) -> FloatArray:
    """Path heading ``psi`` [rad] (clockwise from north, unwrapped) at arc lengths ``s``.

    Each segment's heading ``atan2(d east, d north)`` is attached to its midpoint and
    interpolated linearly in between (constant beyond the first and last midpoints).

    Examples
    --------
    >>> path = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    >>> np.round(headings_along(path, np.array([0.0, 1.0, 2.0]), np.array([0.0, 1.0, 2.0])), 4)
    array([0.    , 0.7854, 1.5708])
    """
    delta = np.diff(path, axis=0)
    psi = np.unwrap(np.arctan2(delta[:, 1], delta[:, 0]))
    midpoints = 0.5 * (arc[:-1] + arc[1:])
    return np.asarray(np.interp(np.asarray(s, dtype=np.float64), midpoints, psi), dtype=np.float64)
