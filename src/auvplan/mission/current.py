"""The mission's ocean current: loading the ``[current]`` table, and speeds along the paths.

The pre-planned paths are fixed curves; in a current ``v_c`` a vehicle moving at ``U_w``
through the water covers them at the ground speed of :func:`auvplan.ocean.ground_speed`.
:func:`path_ground_speeds` evaluates it along a path (current at ``t = 0``: the deconfliction
works on geometry and time laws before the times are known), and :func:`check_crossable`
refuses a path on which the cross-path current is stronger than the vehicle. Before there is
a path, :func:`current_move_factor` weighs each A* move by the time it takes in the current.
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
]

#: Slowest ground speed of an A* move, per speed through the water: a move the current slows
#: below this is barred (the vehicle would spend ten times the energy per metre on it).
MIN_GROUND_FRACTION: Final = 0.1


def load_current(config: MissionConfig, bathymetry: BathymetryGrid) -> CurrentField | None:
    """The ``[current]`` of the mission on its map (None: still water).

    A uniform current of zero is still water (the plan is then exactly the still-water one;
    the current's code path gives it up to round-off, ~1e-6 m on positions). A file is read
    onto the terrain's local frame (:func:`auvplan.io.currents.read_current`), with time
    relative to ``[mission] start_time`` when the mission gives one; it must hold values over
    the map's water cells (NaN there is an error, NaN over land is still water).
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
    )


def path_ground_speeds(
    path: FloatArray, water_speed: float, current: CurrentField
) -> tuple[FloatArray, FloatArray]:
    """Ground speed [m/s] on each segment of ``path`` at ``water_speed``, and segment lengths [m].

    ``path`` ``(n, 2)`` north/east [m]; the current is taken at each segment's midpoint at
    ``t = 0`` (a segment of length 0 counts as heading north). NaN marks a segment whose
    cross-path current exceeds ``water_speed``.
    """
    steps = np.diff(path, axis=0)
    lengths = np.hypot(steps[:, 0], steps[:, 1])
    safe = np.where(lengths > 0.0, lengths, 1.0)
    tangent = np.where(lengths[:, None] > 0.0, steps / safe[:, None], [1.0, 0.0])
    middle = 0.5 * (path[:-1] + path[1:])
    velocity = np.column_stack(
        current.velocity(middle[:, 0], middle[:, 1], np.zeros(middle.shape[0]))
    )
    return ground_speed(water_speed, velocity, tangent), lengths


def mean_ground_speed(path: FloatArray, water_speed: float, current: CurrentField) -> float:
    """Length over travel time [m/s] of ``path`` at ``water_speed`` (NaN if it cannot be held)."""
    speeds, lengths = path_ground_speeds(path, water_speed, current)
    moving = lengths > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        travel = np.sum(lengths[moving] / np.where(speeds[moving] > 0.0, speeds[moving], np.nan))
    return float(np.sum(lengths) / travel) if travel > 0.0 else float("nan")


def check_crossable(
    name: str, path: FloatArray, water_speed: float, current: CurrentField
) -> FloatArray:
    """Ground speeds of :func:`path_ground_speeds`, all positive, or one line naming the cause.

    Raises
    ------
    InfeasibleError
        If somewhere on the path the current pushes vehicle ``name`` off the path or back
        along it at its fastest planned speed ``water_speed`` through the water.
    """
    speeds, lengths = path_ground_speeds(path, water_speed, current)
    stuck = ~(speeds > 0.0) & (lengths > 0.0)
    if np.any(stuck):
        k = int(np.argmax(stuck))
        where = 0.5 * (path[k] + path[k + 1])
        v_n, v_e = current.velocity(where[:1], where[1:], np.zeros(1))
        raise InfeasibleError(
            f"vehicle {name} cannot hold its path at north {where[0]:.0f} m, east "
            f"{where[1]:.0f} m: the current ({float(v_n[0]):.2f}, {float(v_e[0]):.2f}) m/s "
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
