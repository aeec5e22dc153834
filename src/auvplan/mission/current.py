"""The mission's ocean current: loading the ``[current]`` table, and speeds along the paths.

The pre-planned paths are fixed curves; in a current ``v_c(p, t)`` a vehicle moving at ``U_w``
through the water covers them at the ground speed of :func:`auvplan.ocean.ground_speed`.
:func:`path_ground_speeds` evaluates it along a path with the current at the time the vehicle
passes each segment: :func:`segment_times` for a time law of constant ground speed (the
deconfliction's), :func:`water_speed_times` for a constant speed through the water (a fixed
point, since the passage times depend on the ground speeds they give). :func:`check_crossable`
refuses a path on which the cross-path current is stronger than the vehicle. Before there is
a path, :func:`current_move_factor` weighs each A* move by the time it takes in the current at
``t = 0`` (routes are geometry; their times are not known yet).
"""

from __future__ import annotations

from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InfeasibleError
from auvplan.io.currents import read_current
from auvplan.mission.config import MissionConfig
from auvplan.ocean import CurrentField, UniformCurrent, ground_speed
from auvplan.planning.problem import MOVES
from auvplan.terrain import BathymetryGrid, GridGeometry

__all__ = [
    "MIN_GROUND_FRACTION",
    "cell_currents",
    "check_crossable",
    "current_move_factor",
    "load_current",
    "mean_ground_speed",
    "path_ground_speeds",
    "segment_times",
    "water_speed_times",
]

#: Slowest ground speed of an A* move, per speed through the water: a move the current slows
#: below this is barred (the vehicle would spend ten times the energy per metre on it).
MIN_GROUND_FRACTION: Final = 0.1
#: Fixed-point rounds of :func:`water_speed_times`, and the change [s] at which it stops.
PASSAGE_ROUNDS: Final = 12
PASSAGE_TOLERANCE_S: Final = 0.5


def load_current(config: MissionConfig, bathymetry: BathymetryGrid) -> CurrentField | None:
    """The ``[current]`` of the mission on its map (None: still water).

    A uniform current of zero is still water (the plan is then exactly the still-water one;
    the current's code path gives it up to round-off, ~1e-6 m on positions). A file is read
    onto the terrain's local frame (:func:`auvplan.io.currents.read_current`), with time
    relative to ``[mission] start_time`` when the mission gives one (only the slices around a
    given ``fleet.horizon_s`` are read); it must hold values over the map's water cells (NaN
    there is an error, NaN over land is still water).
    """
    table = config.current
    if table is None:
        return None
    if table.file is None:
        north, east = table.north or 0.0, table.east or 0.0
        return UniformCurrent(north, east) if north or east else None
    geometry = bathymetry.geometry
    given = "start_time" in config.mission.model_fields_set
    rows, cols = np.nonzero(np.isfinite(bathymetry.depth))
    return read_current(
        table.file,
        projection=bathymetry.projection,
        extent=(
            (float(geometry.north[0]), float(geometry.north[-1])),
            (float(geometry.east[0]), float(geometry.east[-1])),
        ),
        start_time=config.mission.start_time if given else None,
        depth=config.mission.depth,
        water=geometry.to_world(rows, cols),
        horizon=config.fleet.horizon,
    )


def _segments(path: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Lengths [m], unit tangents (length 0: north) and midpoints [m] of ``path``'s segments."""
    steps = np.diff(path, axis=0)
    lengths = np.hypot(steps[:, 0], steps[:, 1])
    safe = np.where(lengths > 0.0, lengths, 1.0)
    tangent = np.where(lengths[:, None] > 0.0, steps / safe[:, None], [1.0, 0.0])
    return lengths, tangent, 0.5 * (path[:-1] + path[1:])


def segment_times(path: FloatArray, ground_speed: float, start: float = 0.0) -> FloatArray:
    """Mission time [s] at each segment's midpoint of ``path`` covered at ``ground_speed``.

    ``t_k = t_0 + (s_k + ℓ_k / 2) / V`` with ``s_k`` the arc length [m] before segment ``k``
    of length ``ℓ_k``: the passage times of the deconfliction's time law of constant ground
    speed ``V`` [m/s] (its waits, a few seconds, are left out).
    """
    lengths = _segments(path)[0]
    return start + (np.cumsum(lengths) - 0.5 * lengths) / ground_speed


def path_ground_speeds(
    path: FloatArray,
    water_speed: float,
    current: CurrentField,
    times: FloatArray | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Ground speed [m/s] on each segment of ``path`` at ``water_speed``, and segment lengths [m].

    ``path`` ``(n, 2)`` north/east [m]; the current is taken at each segment's midpoint at
    ``times`` ``(n - 1,)`` [s] (None: ``t = 0``; a segment of length 0 counts as heading
    north). NaN marks a segment whose cross-path current exceeds ``water_speed``.
    """
    lengths, tangent, middle = _segments(path)
    when = np.zeros(middle.shape[0]) if times is None else times
    velocity = np.column_stack(current.velocity(middle[:, 0], middle[:, 1], when))
    return ground_speed(water_speed, velocity, tangent), lengths


def water_speed_times(
    path: FloatArray, water_speed: float, current: CurrentField, start: float = 0.0
) -> FloatArray:
    r"""Passage times [s] of ``path``'s segment midpoints at ``water_speed`` through the water.

    The fixed point of ``t_k = t_0 + Σ_{j<k} ℓ_j / s_j(t_j) + ℓ_k / (2 s_k(t_k))`` with
    ``s_j(t)`` the ground speed of :func:`path_ground_speeds` in the current at time ``t``;
    iterated from the still-water times until no time moves by more than
    :data:`PASSAGE_TOLERANCE_S` (a current that changes over hours converges in two or three
    rounds). Where the current holds the vehicle off or back on the path (no positive ground
    speed) the times of the last round are kept: :func:`check_crossable` names that place.
    """
    times = segment_times(path, water_speed, start)
    for _round in range(PASSAGE_ROUNDS):
        speeds, lengths = path_ground_speeds(path, water_speed, current, times)
        if not np.all((speeds > 0.0) | (lengths == 0.0)):
            break
        durations = lengths / np.where(lengths > 0.0, speeds, 1.0)
        updated = start + np.cumsum(durations) - 0.5 * durations
        done = np.max(np.abs(updated - times), initial=0.0) <= PASSAGE_TOLERANCE_S
        times = updated
        if done:
            break
    return times


def mean_ground_speed(path: FloatArray, water_speed: float, current: CurrentField) -> float:
    """Length over travel time [m/s] of ``path`` at ``water_speed`` (NaN if it cannot be held).

    The current is taken when the vehicle passes (:func:`water_speed_times`).
    """
    times = water_speed_times(path, water_speed, current)
    speeds, lengths = path_ground_speeds(path, water_speed, current, times)
    moving = lengths > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        travel = np.sum(lengths[moving] / np.where(speeds[moving] > 0.0, speeds[moving], np.nan))
    return float(np.sum(lengths) / travel) if travel > 0.0 else float("nan")


def check_crossable(
    name: str,
    path: FloatArray,
    water_speed: float,
    current: CurrentField,
    times: FloatArray | None = None,
) -> FloatArray:
    """Ground speeds of :func:`path_ground_speeds`, all positive, or one line naming the cause.

    ``times`` [s] per segment as for :func:`path_ground_speeds` (None: ``t = 0``).

    Raises
    ------
    InfeasibleError
        If somewhere on the path the current pushes vehicle ``name`` off the path or back
        along it at its fastest planned speed ``water_speed`` through the water.
    """
    speeds, lengths = path_ground_speeds(path, water_speed, current, times)
    stuck = ~(speeds > 0.0) & (lengths > 0.0)
    if np.any(stuck):
        k = int(np.argmax(stuck))
        where = 0.5 * (path[k] + path[k + 1])
        when = np.zeros(1) if times is None else times[k : k + 1]
        v_n, v_e = current.velocity(where[:1], where[1:], when)
        at = f" at t = {float(when[0]):.0f} s" if times is not None else ""
        raise InfeasibleError(
            f"vehicle {name} cannot hold its path at north {where[0]:.0f} m, east "
            f"{where[1]:.0f} m{at}: the current ({float(v_n[0]):.2f}, {float(v_e[0]):.2f}) m/s "
            f"north/east is stronger than its {water_speed:.2f} m/s through the water"
        )
    return speeds[lengths > 0.0]


def cell_currents(geometry: GridGeometry, current: CurrentField) -> FloatArray:
    """The current ``(v_N, v_E)`` [m/s] at every cell centre at ``t = 0``, shape ``(n, 2)``."""
    rows, cols = np.meshgrid(np.arange(geometry.n_rows), np.arange(geometry.n_cols), indexing="ij")
    north, east = geometry.to_world(rows.ravel(), cols.ravel())
    return np.column_stack(current.velocity(north, east, np.zeros(north.size)))


def current_move_factor(
    geometry: GridGeometry, velocity: FloatArray, water_speed: float
) -> FloatArray:
    r"""Factor ``U_w / s`` of each A* move's weight in the current, shape ``(8, n_rows, n_cols)``.

    At ``U_w`` through the water a move along unit vector ``t̂`` takes ``U_w / s`` times its
    still-water time (and energy), ``s`` the ground speed of :func:`auvplan.ocean.ground_speed`
    with the current ``velocity`` at the centre of the cell entered (:func:`cell_currents`).
    Moves on which the current is stronger across than ``U_w``, or holds the vehicle below
    :data:`MIN_GROUND_FRACTION` ``U_w``, get ``inf`` (A* avoids them).

    Examples
    --------
    >>> from auvplan.ocean import UniformCurrent
    >>> grid = GridGeometry(1, 1, 1.0, 1.0)
    >>> factor = current_move_factor(grid, cell_currents(grid, UniformCurrent(0.0, 0.5)), 1.0)
    >>> factor[[4, 3], 0, 0].tolist()  # east with the current, west against it
    [0.6666666666666666, 2.0]
    """
    factor = np.empty((len(MOVES), len(velocity)))
    for k, (d_row, d_col) in enumerate(MOVES):
        step = np.array([d_row * geometry.spacing_north, d_col * geometry.spacing_east])
        tangent = np.broadcast_to(step / np.hypot(*step), velocity.shape)
        speed = ground_speed(water_speed, velocity, tangent)
        with np.errstate(invalid="ignore"):
            fast_enough = speed >= MIN_GROUND_FRACTION * water_speed
        factor[k] = np.where(fast_enough, water_speed / np.where(fast_enough, speed, 1.0), np.inf)
    return factor.reshape(len(MOVES), geometry.n_rows, geometry.n_cols)
