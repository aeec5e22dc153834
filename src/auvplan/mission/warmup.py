"""Compiling a mission's stage-3 kernels ahead of need (first run on a machine only).

numba compiles each kernel on its first call and keeps the machine code on disk, so only a
machine's first mission pays for it — about 50 s on two cores, of which the optimiser's
kernels (the generated stage derivatives of each vehicle type, :mod:`auvplan.optimization`'s
Riccati and LQ sweeps) are half, and the A* and coordination-space searches of stages 1 and
2 the other half. :func:`warm_up` runs stages 2 and 3 on small missions of the same vehicle
types and settings (:func:`warm_up_missions`): a second process running it compiles the
optimiser's kernels while the mission's own process compiles its searches, and the stage-3
kernels are then read from the disk cache.

A small mission flies one vehicle of each type along a straight track over the synthetic
bank, with no obstacles or communication limits, in a uniform current when the mission has
a current. It needs no path search, and no coordination-space search for its lone vehicle
(:func:`~auvplan.deconfliction.deconflict`). Its results are discarded: it exists only to
call the kernels with the mission's argument types. Kernels of pairs of vehicles (barriers,
communication ranges) are compiled by the mission itself.
"""

from __future__ import annotations

from typing import Final

import numpy as np

from auvplan.mission.config import MissionConfig
from auvplan.mission.current import load_current
from auvplan.mission.pipeline import fleet_layout, run_optimization
from auvplan.mission.preplan import PreplanStage, compute_maps, load_terrain
from auvplan.mission.tables import CurrentConfig
from auvplan.mission.timing import run_deconfliction
from auvplan.optimization import StageWeights, convexify

__all__ = ["warm_up", "warm_up_missions"]

#: Length of each track of the small mission [m].
TRACK_LENGTH = 40.0
#: The small missions' current when the mission has one (its kind does not matter).
CURRENT: Final = CurrentConfig(north=0.1, east=0.05)
#: PRONTO iterations of the small mission: enough to call every kernel of an iteration.
ITERATIONS = 2


def warm_up_missions(config: MissionConfig) -> list[MissionConfig]:
    """The small missions of ``config``'s vehicle types and settings (module notes).

    One mission per distinct vehicle type of ``config``: its vehicle heads north over
    :data:`TRACK_LENGTH` on the synthetic bank; the solver, maps, weights and deconfliction
    settings are ``config``'s, with :data:`ITERATIONS` PRONTO iterations and without the C
    compilation of ``solver.compile`` (its code holds the mission's constants: no other
    mission can use it).
    """
    speeds = {vehicle.type: vehicle.start.speed for vehicle in config.vehicles}
    return [
        MissionConfig.model_validate(
            {
                "terrain": {"synthetic": True},
                "maps": config.maps,
                "fleet": {"cruise_speed": 0.5, "safety_radius_m": config.fleet.safety_radius},
                "vehicle": [
                    {
                        "name": "warm-up",
                        "type": kind,
                        "start": {"north": 20.0, "east": 20.0, "heading_deg": 0.0, "speed": speed},
                        "goal": {"north": 20.0 + TRACK_LENGTH, "east": 20.0, "heading_deg": 0.0},
                    }
                ],
                "weights": config.weights,
                "deconfliction": config.deconfliction,
                "solver": config.solver.model_copy(
                    update={"max_iter": ITERATIONS, "compile": False}
                ),
                "current": None if config.current is None else CURRENT,
            }
        )
        for kind, speed in speeds.items()
    ]


def warm_up(config: MissionConfig) -> None:
    """Run stages 2 and 3 of each of :func:`warm_up_missions` of ``config`` (results discarded).

    Every kernel that this calls is compiled and cached on disk (module notes). Errors of
    the small missions propagate; a caller that only wants the cache filled may ignore them.
    """
    for small in warm_up_missions(config):
        _stages_2_and_3(small)
    # the convexified model clipped on threads (a coupled solve with --jobs 2), which the
    # small missions' few iterations need not reach: its kernel takes any sizes
    empty = np.zeros((1, 1, 1))
    convexify(StageWeights(empty, empty, empty, np.eye(1)), floor=1.0, threads=2)


def _stages_2_and_3(small: MissionConfig) -> None:
    """Stages 2 and 3 of a small mission, on its straight tracks."""
    bathymetry = load_terrain(small.terrain)
    starts = np.array([(v.start.north, v.start.east, v.start.psi) for v in small.vehicles])
    goals = np.array([(v.goal.north, v.goal.east, v.goal.psi) for v in small.vehicles])
    step = 0.25 * min(bathymetry.geometry.spacing_north, bathymetry.geometry.spacing_east)
    samples = np.linspace(0.0, 1.0, int(TRACK_LENGTH / step) + 1)[:, None]
    paths = tuple(
        start[:2] + samples * (goal[:2] - start[:2])
        for start, goal in zip(starts, goals, strict=True)
    )
    preplan = PreplanStage(
        bathymetry=bathymetry,
        maps=compute_maps(bathymetry, small.maps),
        names=tuple(vehicle.name for vehicle in small.vehicles),
        starts=starts,
        start_speeds=np.array([vehicle.start.speed for vehicle in small.vehicles]),
        goals=goals,
        obstacles=(),
        obstacle_names=(),
        routes=(),
        paths=paths,
        current=load_current(small, bathymetry),
    )
    layout = fleet_layout(small)
    deconfliction = run_deconfliction(
        layout,
        paths,
        starts[:, 2],
        goals[:, 2],
        fleet=small.fleet,
        settings=small.deconfliction,
        dt=small.solver.dt,
        current=preplan.current,
    )
    run_optimization(small, layout, preplan, deconfliction, small.weights.terrain)
