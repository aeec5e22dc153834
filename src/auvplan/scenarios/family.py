"""A public, seeded family of valid missions that nobody tuned the planner to.

:func:`generate` with the default ``kind="reliability"`` draws, from
``numpy.random.default_rng(seed)`` only:

* the horizon ``T``, log-uniform in 10 min – 3 h (a multiple of 10 s), and ``dt_s`` as a user
  would choose it: 0.5 s up to 15 min, 1 s up to 50 min, 2 s beyond;
* 2–6 MEDUSAs, each with a mean speed ``U(0.25, 0.6)`` m/s (top speed 1.48 m/s) that sets its
  straight start-goal distance ``v T / DETOUR`` (A* paths are longer than straight lines);
* the safety radius ``r_c`` and the pre-planner's edge model;
* the terrain: the packaged bank, a new synthetic bank, or a window of a real grid of the
  shared data folder (Monterey canyon head, South Lisbon shelf, Balanus seamount), among those
  whose size and resolution suit the distances (real grids are skipped when absent, so the
  family depends on whether the folder exists);
* a layout (random, lanes, rendezvous) of start and goal poses: in water, away from no-go
  cells and the map edge, starts (and goals) pairwise at least ``2 r_c + max(r_c, 5 m)``
  apart, in lat/lon on real grids; headings along the start-goal line within ~20°; about a
  third of the vehicles start at rest;
* sometimes (35 %) one or two circular/polygonal obstacles across a vehicle's line but clear
  of every start and goal; sometimes (30 %) one or two communication pairs whose range is
  comfortably above what their straight lines need.

Valid means ``auvplan plan --stage preplan`` accepts the mission. ``kind="transit"`` draws
long transits instead (:mod:`auvplan.scenarios.transit`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Final

import numpy as np

from auvplan.errors import InputError
from auvplan.planning import CircleObstacle, PolygonObstacle
from auvplan.record.files import MISSION_FILE
from auvplan.scenarios import _poses, _terrain, transit
from auvplan.scenarios._scenario import (
    DT_BY_HORIZON,
    VEHICLE_NAMES,
    Scenario,
    position_table,
)

#: Horizon range [s].
HORIZON_RANGE_S: Final = (600.0, 10800.0)
#: Mean-speed range [m/s] of each vehicle along its path.
SPEED_RANGE: Final = (0.25, 0.6)
#: Assumed ratio of A* path length to straight start-goal distance.
DETOUR: Final = 1.2
#: Fleet sizes drawn.
FLEET_SIZES: Final = (2, 6)
SAFETY_RADII_M: Final = (2.5, 5.0, 5.0, 10.0)
#: Terrain draws tried before falling back to a synthetic bank.
TERRAIN_ATTEMPTS: Final = 4
#: Family kinds :func:`generate` draws from.
KINDS: Final = ("reliability", "transit")
#: Largest seed: seeds fit a signed 64-bit integer, as the sweep's tables store them (and a
#: seed's folder name ``seed_NNNN`` stays short).
MAX_SEED: Final = 2**63 - 1

__all__ = [
    "DT_BY_HORIZON",
    "KINDS",
    "MAX_SEED",
    "MISSION_FILE",
    "VEHICLE_NAMES",
    "Scenario",
    "generate",
]


def generate(seed: int, *, data_dir: Path | None = None, kind: str = "reliability") -> Scenario:
    """The scenario of ``seed`` (deterministic for a given availability of the real grids).

    Parameters
    ----------
    seed : int
        Seed of :func:`numpy.random.default_rng`, the only source of randomness.
    data_dir : Path, optional
        Folder of the real bathymetry grids; default
        :func:`auvplan.scenarios._terrain.default_data_dir`. Grids not found are skipped.
    kind : {"reliability", "transit"}
        ``"reliability"`` (this module's family, the default) or ``"transit"``: a long
        transit over a plain with rough features beside the line, or over a real grid
        (:func:`auvplan.scenarios.transit.generate_transit`).

    Returns
    -------
    Scenario

    Raises
    ------
    InputError
        If ``seed`` is not in 0 … :data:`MAX_SEED` or ``kind`` is not one of :data:`KINDS`.
    """
    if not 0 <= seed <= MAX_SEED:
        raise InputError(f"scenario seed must be in 0 … {MAX_SEED} (2**63 - 1), got {seed}")
    if kind == "transit":
        return transit.generate_transit(seed, data_dir=data_dir)
    if kind != "reliability":
        raise InputError(f"scenario kind must be one of {', '.join(KINDS)}, got {kind!r}")
    rng = np.random.default_rng(seed)
    data_dir = _terrain.default_data_dir() if data_dir is None else Path(data_dir)
    horizon = 10.0 * round(math.exp(rng.uniform(*np.log(HORIZON_RANGE_S))) / 10.0)
    dt = next(step for longest, step in DT_BY_HORIZON if horizon <= longest)
    n_vehicles = int(rng.integers(FLEET_SIZES[0], FLEET_SIZES[1] + 1))
    speeds = rng.uniform(*SPEED_RANGE, n_vehicles)
    distances = speeds * horizon / DETOUR
    safety_radius = float(rng.choice(SAFETY_RADII_M))
    separation = 2.0 * safety_radius + max(safety_radius, 5.0)
    layout = str(rng.choice(_poses.LAYOUTS))
    kinds = _terrain.feasible_kinds(data_dir, float(distances.min()), float(distances.max()))
    kind = str(rng.choice(kinds))
    for attempt in range(TERRAIN_ATTEMPTS + 1):
        drawn = _terrain.draw_terrain(
            kind if attempt < TERRAIN_ATTEMPTS else "synthetic",
            rng,
            max_distance=float(distances.max()),
            safety_radius=safety_radius,
            data_dir=data_dir,
        )
        if drawn is None:
            continue
        margin = _terrain.pose_margin(drawn.cell_size, safety_radius)
        space = _poses.free_space(drawn, safety_radius=safety_radius, margin=margin)
        if not space.usable.any():
            continue
        poses = _poses.draw_poses(rng, space, distances, layout=layout, separation=separation)
        if poses is not None:
            break
    else:
        raise RuntimeError(f"scenario {seed}: no terrain fits (a bug in the generator)")
    starts, goals = poses
    obstacles = (
        _poses.draw_obstacles(rng, drawn, starts, goals, safety_radius=safety_radius, margin=margin)
        if rng.uniform() < 0.35
        else ()
    )
    comms = (
        _poses.draw_comm_pairs(rng, starts, goals, safety_radius=safety_radius)
        if rng.uniform() < 0.3
        else []
    )
    vehicles = _vehicle_tables(rng, drawn, starts, goals, speeds)
    mission: dict[str, Any] = {
        "terrain": drawn.table,
        "maps": {"block": list(drawn.block)},
        "fleet": {"horizon_s": horizon, "safety_radius_m": safety_radius},
        "vehicle": vehicles,
    }
    if obstacles:
        mission["obstacle"] = [_obstacle_table(obstacle, drawn) for obstacle in obstacles]
    if comms:
        mission["comm"] = [
            {"pair": [VEHICLE_NAMES[i], VEHICLE_NAMES[j]], "max_range_m": max_range}
            for i, j, max_range in comms
        ]
    mission["planner"] = {"edge_model": str(rng.choice(["paper", "crossed"]))}
    mission["solver"] = {"dt_s": dt}
    description = (
        f"{drawn.label}, {n_vehicles} vehicles ({layout}), horizon {horizon:g} s, dt {dt:g} s"
        f", r_c {safety_radius:g} m, {len(obstacles)} obstacles, {len(comms)} comm pairs"
    )
    return Scenario(
        seed, mission, drawn.kind, n_vehicles, horizon, dt, description, drawn.synthetic
    )


def _heading_deg(rng: np.random.Generator, line: np.ndarray) -> float:
    """Bearing of ``line`` (north, east) in degrees, perturbed by N(0, 20°), in (-180, 180]."""
    bearing = math.degrees(math.atan2(line[1], line[0])) + rng.normal(0.0, 20.0)
    return round(-((-bearing + 180.0) % 360.0 - 180.0), 1)


def _vehicle_tables(
    rng: np.random.Generator,
    drawn: _terrain.DrawnTerrain,
    starts: np.ndarray,
    goals: np.ndarray,
    speeds: np.ndarray,
) -> list[dict[str, Any]]:
    tables = []
    for i, (start, goal) in enumerate(zip(starts, goals, strict=True)):
        line = goal - start
        speed = 0.0 if rng.uniform() < 0.3 else round(float(speeds[i]) / 0.05) * 0.05
        tables.append(
            {
                "name": VEHICLE_NAMES[i],
                "type": "medusa",
                "start": {
                    **position_table(start, drawn),
                    "heading_deg": _heading_deg(rng, line),
                    "speed": round(speed, 2),
                },
                "goal": {**position_table(goal, drawn), "heading_deg": _heading_deg(rng, line)},
            }
        )
    return tables


def _obstacle_table(
    obstacle: CircleObstacle | PolygonObstacle, drawn: _terrain.DrawnTerrain
) -> dict[str, Any]:
    """A circle's centre in lat/lon on geographic terrain; polygons always in north/east."""
    if isinstance(obstacle, CircleObstacle):
        centre = np.array([obstacle.north, obstacle.east])
        return {"center": position_table(centre, drawn), "radius_m": round(obstacle.radius, 2)}
    return {"polygon": [[round(float(n), 2), round(float(e), 2)] for n, e in obstacle.vertices]}
