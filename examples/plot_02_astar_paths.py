"""
A* pre-planned routes over the cost map: paper vs crossed edge model
====================================================================

Stage 1 of the paper's pipeline (Sec. III): one globally optimal 8-neighbour grid path per
vehicle on the shifted cost map ``10 + 10 cos(pi/2 M_E)`` of the synthetic volcanic bank,
avoiding a circular and a polygonal obstacle (with 8 m clearance).

* ``paper`` edge model: entering a cell costs that cell's cost, straight or diagonal alike.
  Diagonal moves are "free" distance, so paths zig-zag and cut across the map diagonally.
* ``crossed`` edge model (the paper's future work): edge length [m] x mean cost of the two
  cells, so the path length counts and paths are straighter.

Each grid path is then smoothed into a C² curve (within half a cell of the grid path, never in
a blocked cell) and resampled every 2 m, ready for the timing and deconfliction stage.

Run ``python examples/plot_02_astar_paths.py [OUTPUT.png]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle, Patch, Polygon

from auvplan.planning import (
    CircleObstacle,
    EdgeModel,
    Obstacle,
    PolygonObstacle,
    blocked_cells,
    blocked_lookup,
    path_length,
    plan_route,
    smooth_path,
)
from auvplan.terrain import MapParameters, compute_terrain_maps, synthetic_bank

maps = compute_terrain_maps(synthetic_bank(seed=7), MapParameters(block=(2, 2)))
cost, geometry = maps.shifted_cost, maps.cost_geometry
obstacles: list[Obstacle] = [
    CircleObstacle(north=200.0, east=300.0, radius=35.0),
    PolygonObstacle(np.array([[60.0, 520.0], [250.0, 560.0], [250.0, 590.0], [60.0, 600.0]])),
]
clearance = 8.0
vehicles = {
    "auv1": ((20.0, 20.0), (380.0, 780.0)),
    "auv2": ((380.0, 30.0), (30.0, 760.0)),
}
is_blocked = blocked_lookup(
    geometry, blocked_cells(cost, geometry, obstacles=obstacles, clearance=clearance)
)
half_cell = 0.5 * min(geometry.spacing_north, geometry.spacing_east)

figure, axes = plt.subplots(2, 1, figsize=(9, 9), sharex=True, sharey=True, layout="constrained")
extent = (*geometry.east_bounds, *geometry.north_bounds)
for ax, model in zip(axes, EdgeModel, strict=True):
    image = ax.imshow(cost, origin="lower", extent=extent, cmap="viridis_r")
    for obstacle in obstacles:
        patch: Patch = (
            Circle((obstacle.east, obstacle.north), obstacle.radius)
            if isinstance(obstacle, CircleObstacle)
            else Polygon(obstacle.vertices[:, ::-1])
        )
        patch.set(facecolor="0.85", edgecolor="k", hatch="//")
        ax.add_patch(patch)
    for (name, (start, goal)), color in zip(
        vehicles.items(), ("tab:red", "tab:orange"), strict=True
    ):
        route = plan_route(
            cost,
            geometry,
            start,
            goal,
            obstacles=obstacles,
            clearance=clearance,
            edge_model=model,
            name=name,
        )
        curve = smooth_path(
            route.points, spacing=2.0, max_deviation=half_cell, is_blocked=is_blocked
        )
        ax.plot(route.points[:, 1], route.points[:, 0], ":", color=color, lw=1.2)
        ax.plot(curve[:, 1], curve[:, 0], "-", color=color, lw=2.0, label=f"{name}")
        ax.plot(*np.array([start, goal])[:, ::-1].T, "o", color=color, mec="k")
        print(
            f"{model.value:>8} {name}: cost {route.cost:10.1f}, {len(route.cells)} cells, "
            f"grid path {path_length(route.points):6.1f} m, smooth {path_length(curve):6.1f} m, "
            f"{route.n_expanded} cells expanded"
        )
    ax.set_title(f"edge model '{model.value}' (dotted: grid path, solid: smoothed)")
    ax.set_ylabel("north [m]")
    ax.set_aspect("equal")
    ax.legend(loc="upper left")
    figure.colorbar(image, ax=ax, label="shifted cost ω + w·M_C")
axes[-1].set_xlabel("east [m]")

output = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("plot_02_astar_paths.png")
figure.savefig(output, dpi=120)
print(f"wrote {output}")
