"""
Temporal deconfliction in the coordination space (paper Sec. III-B)
===================================================================

Stage 2 of the paper's pipeline keeps every vehicle's pre-planned path and only changes *when*
each vehicle is where. As in the paper's scenario, two vehicles cross the rim of a bank from
south to north at 0.5 m/s; their terrain-informed paths merge for about 100 m, so at equal
timing they would run side by side, closer than ``2 r_c = 10 m``.

* Left figure: the coordination space ``(s_0, s_1)``; red is where the pair is closer than
  ``2 r_c``; the nominal schedule (dashed diagonal) runs through it, the deconflicted one
  (weighted A*, 0.05 s grid) bends around it: one vehicle slows down and stays behind.
* Right figure: the timed trajectories and the pairwise distance over time, after stretching
  both schedules to a common arrival time (``retime_for_arrival``), with the certified
  continuous-time minimum.

A third vehicle crossing eastwards shows the prioritised method on the same problem.

Run ``python examples/plot_03_deconfliction.py [OUTPUT_PREFIX]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from auvplan.deconfliction import (
    CoordinationProblem,
    deconflict,
    retime_for_arrival,
)
from auvplan.viz.coordination import plot_coordination_space, plot_timed_paths

north = np.linspace(10.0, 390.0, 381)
merge = 0.5 * (1 - np.cos(np.pi * np.clip((north - 60.0) / 100.0, 0, 1)))  # 0 -> 1
split = 0.5 * (1 - np.cos(np.pi * np.clip((north - 260.0) / 100.0, 0, 1)))
shared = merge - split  # 1 on the shared stretch 160-260 m north
blue = np.column_stack([north, 400.0 + 27.0 * shared])
green = np.column_stack([north, 460.0 - 27.0 * shared])
red = np.column_stack([np.full(313, 300.0), np.linspace(76.0, 700.0, 313)])

pair = CoordinationProblem(
    paths=(blue, green), safety_radius=5.0, cruise_speeds=np.array([0.5, 0.5]), time_step=0.05
)
result = deconflict(pair, method="astar")
print(result.message)
print(f"delays [s]: {np.round(result.delays, 2)}, nodes expanded: {result.n_expanded}")

common_arrival = float(np.ceil(result.makespan + 20.0))
retimed = retime_for_arrival(result, pair, common_arrival)
print(retimed.message)

fleet = CoordinationProblem(
    paths=(blue, green, red),
    safety_radius=5.0,
    cruise_speeds=np.array([0.5, 0.5, 0.6]),
    time_step=0.05,
)
prioritized = deconflict(fleet, method="prioritized")
print(prioritized.message)

prefix = sys.argv[1] if len(sys.argv) > 1 else "plot_03_deconfliction"
for name, figure in (
    ("coordination_space", plot_coordination_space(pair, result, pair=(0, 1))),
    ("timed_paths", plot_timed_paths(pair, retimed)),
    ("three_vehicles", plot_timed_paths(fleet, prioritized)),
):
    output = Path(f"{prefix}_{name}.png")
    figure.savefig(output, dpi=110)
    print(f"wrote {output}")
