"""Long transits: a seeded family to measure what terrain-aided navigation is worth.

:func:`generate_transit` (``auvplan.scenarios.generate(seed, kind="transit")``) draws, from
``numpy.random.default_rng(seed)`` only:

* the horizon ``T``, uniform in 1–3 h (a multiple of 10 s), ``dt_s`` as a user would choose it
  (2 s beyond 50 min, :data:`~auvplan.scenarios.family.DT_BY_HORIZON`);
* the straight start-goal distance ``D``, uniform in 2–8 km and such that ``D / T`` lies in
  :data:`LINE_SPEED_RANGE` (at most 0.75 m/s, half the MEDUSA's top speed of 1.48 m/s);
* 1–4 MEDUSAs on parallel lines of length ``D`` (``"lanes"``: starts abreast; ``"formation"``:
  starts staggered along the lines), the lines ``1.5–4 x (2 r_c + max(r_c, 5 m))`` apart,
  headings along the lines; the fleet starts at rest or at its mean line speed;
* the terrain (:attr:`~auvplan.scenarios.Scenario.features`): in 20 % of seeds a flat plain
  (``"flat"``); in 20 % a window of a real grid of the shared data folder large enough for
  the lines (``"real"``: South Lisbon shelf, Balanus seamount; the Monterey grid is too small
  for 2 km), poses in lat/lon, in water away from no-go cells and the map edge, every line
  clear of no-go cells; otherwise (and when no real grid fits or the folder is absent) a
  plain with one or two rough features beside the lines (``"offset"``), each at a drawn
  perpendicular offset of 0–800 m from the nearest line on its side
  (:mod:`auvplan.scenarios._plain`). Plains are written as ``terrain.nc`` with the mission.

No obstacles and no communication ranges. Valid means ``auvplan plan --stage preplan`` accepts
the mission.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.scenarios import _plain, _poses, _terrain
from auvplan.scenarios._scenario import (
    DT_BY_HORIZON,
    VEHICLE_NAMES,
    Scenario,
    position_table,
)

#: Horizon range [s] (1–3 h).
HORIZON_RANGE_S: Final = (3600.0, 10800.0)
#: Straight start-goal distance range [m].
DISTANCE_RANGE_M: Final = (2000.0, 8000.0)
#: Range of the straight-line speed ``D / T`` [m/s]; MEDUSA's top speed is 1.48 m/s.
LINE_SPEED_RANGE: Final = (0.25, 0.75)
#: Fleet sizes drawn.
FLEET_SIZES: Final = (1, 4)
SAFETY_RADII_M: Final = (2.5, 5.0, 5.0, 10.0)
LAYOUTS: Final = ("lanes", "formation")
#: Spacing of the lines as a multiple of the least separation ``2 r_c + max(r_c, 5 m)``.
LANE_SPACING_FACTORS: Final = (1.5, 4.0)
#: Share of seeds over a flat plain, and over a real grid (when one fits).
FLAT_SHARE: Final = 0.2
REAL_SHARE: Final = 0.2
#: Share of fleets that start at rest (else at their mean line speed).
AT_REST_SHARE: Final = 0.25
#: Real-grid windows tried before falling back to a plain with features.
REAL_ATTEMPTS: Final = 4
#: Placements of the lines tried in one real-grid window.
PLACEMENT_ATTEMPTS: Final = 200


def generate_transit(seed: int, *, data_dir: Path | None = None) -> Scenario:
    """The transit scenario of ``seed`` (deterministic for a given availability of real grids).

    Parameters
    ----------
    seed : int
        Seed of :func:`numpy.random.default_rng`, the only source of randomness.
    data_dir : Path, optional
        Folder of the real bathymetry grids; default
        :func:`auvplan.scenarios._terrain.default_data_dir`. Grids not found are skipped.

    Returns
    -------
    Scenario
        With ``kind="transit"``, ``features`` in ``{"flat", "offset", "real"}``,
        ``distance_m`` and (on plains with features) ``feature_offsets_m`` and ``relief``.
    """
    rng = np.random.default_rng(seed)
    data_dir = _terrain.default_data_dir() if data_dir is None else Path(data_dir)
    horizon = 10.0 * round(float(rng.uniform(*HORIZON_RANGE_S)) / 10.0)
    dt = next(step for longest, step in DT_BY_HORIZON if horizon <= longest)
    shortest = max(DISTANCE_RANGE_M[0], LINE_SPEED_RANGE[0] * horizon)
    longest = min(DISTANCE_RANGE_M[1], LINE_SPEED_RANGE[1] * horizon)
    distance = 10.0 * math.floor(float(rng.uniform(shortest, longest)) / 10.0)
    n_vehicles = int(rng.integers(FLEET_SIZES[0], FLEET_SIZES[1] + 1))
    safety_radius = float(rng.choice(SAFETY_RADII_M))
    separation = 2.0 * safety_radius + max(safety_radius, 5.0)
    layout = str(rng.choice(LAYOUTS))
    spacing = separation * float(rng.uniform(*LANE_SPACING_FACTORS))
    lanes = spacing * (np.arange(n_vehicles, dtype=np.float64) - 0.5 * (n_vehicles - 1))
    stagger = (
        rng.uniform(-1.0, 1.0, n_vehicles) * spacing
        if layout == "formation"
        else np.zeros(n_vehicles)
    )
    at_rest = bool(rng.uniform() < AT_REST_SHARE)
    draw = rng.uniform()
    features = "flat" if draw < FLAT_SHARE else "offset"
    if FLAT_SHARE <= draw < FLAT_SHARE + REAL_SHARE:
        features = "real"
    placed = None
    if features == "real":
        placed = _real_terrain(rng, data_dir, distance, lanes, stagger, safety_radius)
        features = "offset" if placed is None else "real"
    relief: tuple[_plain.Feature, ...] = ()
    if placed is None:
        bearing = float(rng.uniform(0.0, 2.0 * math.pi))
        corridor = _plain.Corridor(
            np.zeros(2), np.array([math.cos(bearing), math.sin(bearing)]), distance, lanes, stagger
        )
        grid, corridor, relief, label = _plain.draw_plain(rng, corridor, flat=features == "flat")
        drawn = _terrain.with_maps("plain", {"file": _terrain.SYNTHETIC_FILE}, grid, grid, label)
        space = _poses.free_space(
            drawn,
            safety_radius=safety_radius,
            margin=_terrain.pose_margin(drawn.cell_size, safety_radius),
        )
        if not all(space.is_usable(p) for p in (*corridor.starts, *corridor.goals)):
            raise RuntimeError(f"transit scenario {seed}: a pose off the plain (a generator bug)")
    else:
        drawn, corridor = placed
    speed = 0.0 if at_rest else round(0.05 * round(distance / horizon / 0.05), 2)
    vehicles = _vehicle_tables(drawn, corridor, speed)
    mission: dict[str, Any] = {
        "terrain": drawn.table,
        "maps": {"block": list(drawn.block)},
        "fleet": {"horizon_s": horizon, "safety_radius_m": safety_radius},
        "vehicle": vehicles,
        "solver": {"dt_s": dt},
    }
    offsets = tuple(feature.offset_m for feature in relief)
    if features == "flat":
        beside = "flat (no feature)"
    elif features == "real":
        beside = "real terrain"
    else:
        beside = "features " + ", ".join(f"{f.kind} at offset {f.offset_m:.0f} m" for f in relief)
    fleet = f"{n_vehicles} vehicle{'s' if n_vehicles > 1 else ''} ({layout})"
    description = (
        f"transit over {drawn.label}, {beside}, {fleet}, horizon "
        f"{horizon / 3600.0:.2f} h ({horizon:g} s), distance {distance / 1e3:.2f} km, "
        f"dt {dt:g} s, r_c {safety_radius:g} m"
    )
    return Scenario(
        seed,
        mission,
        drawn.kind,
        n_vehicles,
        horizon,
        dt,
        description,
        drawn.synthetic,
        kind="transit",
        features=features,
        distance_m=distance,
        feature_offsets_m=offsets,
        relief=relief,
    )


def _real_terrain(
    rng: np.random.Generator,
    data_dir: Path,
    distance: float,
    lanes: FloatArray,
    stagger: FloatArray,
    safety_radius: float,
) -> tuple[_terrain.DrawnTerrain, _plain.Corridor] | None:
    """A real-grid window holding the lines, and the lines placed in it; None if none fits."""
    span = math.hypot(distance + float(np.ptp(stagger)), float(np.ptp(lanes)))
    kinds = [
        kind
        for kind in _terrain.feasible_kinds(data_dir, distance, span)
        if kind in _terrain.REAL_GRIDS
    ]
    if not kinds:
        return None
    kind = str(rng.choice(kinds))
    for _ in range(REAL_ATTEMPTS):
        drawn = _terrain.draw_terrain(
            kind, rng, max_distance=span, safety_radius=safety_radius, data_dir=data_dir
        )
        if drawn is None:
            continue
        margin = _terrain.pose_margin(drawn.cell_size, safety_radius)
        space = _poses.free_space(drawn, safety_radius=safety_radius, margin=margin)
        if not space.usable.any():
            continue
        for _ in range(PLACEMENT_ATTEMPTS):
            bearing = float(rng.uniform(0.0, 2.0 * math.pi))
            direction = np.array([math.cos(bearing), math.sin(bearing)])
            middle = space.random_point(rng)
            origin = middle - 0.5 * distance * direction
            corridor = _plain.Corridor(origin, direction, distance, lanes, stagger)
            if _lines_clear(space, corridor):
                return drawn, corridor
    return None


def _lines_clear(space: _poses.FreeSpace, corridor: _plain.Corridor) -> bool:
    """True if every start and goal is usable and every line crosses no no-go cell."""
    if not all(space.is_usable(p) for p in (*corridor.starts, *corridor.goals)):
        return False
    step = 0.5 * min(space.geometry.spacing_north, space.geometry.spacing_east)
    fractions = np.linspace(0.0, 1.0, math.ceil(corridor.length_m / step) + 1)
    region = space.region(corridor.starts[0])
    for start, goal in zip(corridor.starts, corridor.goals, strict=True):
        points = start + fractions[:, None] * (goal - start)
        north, east = points[:, 0], points[:, 1]
        if not bool(np.all(space.geometry.contains(north, east))):
            return False
        rows, cols = space.geometry.to_index(north, east)
        if not bool(np.all(space.labels[rows, cols] == region)):
            return False
    return True


def _vehicle_tables(
    drawn: _terrain.DrawnTerrain, corridor: _plain.Corridor, speed: float
) -> list[dict[str, Any]]:
    """One MEDUSA per line, headed along it, starting at ``speed`` [m/s]."""
    bearing = math.degrees(math.atan2(corridor.direction[1], corridor.direction[0]))
    heading = round(-((-bearing + 180.0) % 360.0 - 180.0), 1)
    return [
        {
            "name": VEHICLE_NAMES[i],
            "type": "medusa",
            "start": {**position_table(start, drawn), "heading_deg": heading, "speed": speed},
            "goal": {**position_table(goal, drawn), "heading_deg": heading},
        }
        for i, (start, goal) in enumerate(zip(corridor.starts, corridor.goals, strict=True))
    ]
