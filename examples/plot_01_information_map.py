"""
Terrain-information maps of the synthetic volcanic bank (paper Fig. 5)
======================================================================

The embedded default terrain is a seeded synthetic volcanic bank, 800 m east x 400 m north at
4 m spacing, depths 20-60 m, with a crater rim, flanks, radial gullies and fractal roughness.
From its bathymetry we compute the paper's maps (Sec. III-A):

* information (eq. 13): the normalised depth-gradient magnitude, high where terrain-based
  navigation works well;
* excitation (eq. 14): its 2 x 2 block mean;
* cost: ``cos(pi/2 * excitation)``, cheap over rich terrain, shifted to ``10 + 10 * cost``
  (eq. 15) for the A* pre-planner.

Run ``python examples/plot_01_information_map.py [OUTPUT.png]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from auvplan.terrain import MapParameters, compute_terrain_maps, synthetic_bank
from auvplan.viz.maps import plot_terrain_maps

bank = synthetic_bank(seed=7)
maps = compute_terrain_maps(
    bank, MapParameters(exponent=1.0, block=(2, 2), omega=10.0, weight=10.0)
)

# Where is the terrain richest? On the outer flanks of the crater rim; the demo mission crosses
# the eastern one (east about 420-480 m) from south to north.
row, col = np.unravel_index(np.nanargmax(maps.excitation), maps.excitation.shape)
north, east = maps.cost_geometry.to_world(np.array([row]), np.array([col]))
print(f"depth {bank.depth.min():.1f}-{bank.depth.max():.1f} m on {bank.depth.shape} nodes")
print(f"richest block at north {north[0]:.0f} m, east {east[0]:.0f} m")
print(f"shifted cost {np.nanmin(maps.shifted_cost):.2f}-{np.nanmax(maps.shifted_cost):.2f}")

figure = plot_terrain_maps(maps)
output = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("plot_01_information_map.png")
figure.savefig(output, dpi=120)
print(f"wrote {output}")
