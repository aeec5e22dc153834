r"""Run-time and memory budgets of deconfliction, checked before the large arrays exist.

Every array of the coordination-grid methods grows with the number of grid steps
:math:`n_i = \lceil L_i / (v_i\,dt) \rceil` of the vehicles, so the size of a run is known from
the problem before anything is allocated:

* the conflict tables hold one CSR row per grid step of every ordered pair searched
  (``N (N - 1) / 2`` pairs for A*, ``N (N - 1)`` for prioritised planning) — the row pointer,
  its concatenated copy and about one forbidden interval per row, :data:`BYTES_PER_PAIR_ROW`;
* the schedule, its certificate and the safe intervals of prioritised planning hold a few
  numbers per grid step and per vehicle, :data:`BYTES_PER_VEHICLE_STEP`.

Time is dominated by the same rows: building the tables, the monotone reachability test of
every pair, the safe-interval programme and the certificate together cost at most
:data:`SECONDS_PER_PAIR_ROW` per ordered-pair row.

The two structures whose size depends on the geometry — the pairwise cost-to-go of the A*
heuristic (one ``uint16`` per cell of the 2-D pair grid that some obstacle shadows) and the
A* node store — are capped inside their kernels: :data:`MAX_HEURISTIC_CELLS` and
:data:`MAX_ASTAR_STORED`. A search that reaches a cap stops before allocating more.

Measurements (2-core reference machine, two or eight 400 m straight paths crossing, r_c = 5 m,
v = 1 m/s, ``dt`` from 0.1 s to 0.001 s, i.e. up to 4·10^5 steps per vehicle):

* conflict table: 180–400 ns per ordered-pair row; whole prioritised run 320–670 ns per
  ordered-pair row (certificate included);
* pairwise cost-to-go: 34–38 ns per stored cell; a crossing stores about ``0.7 n_i w``
  cells with ``w = 4 r_c / h``, so ``dt = 0.001`` s stores 5.7·10^9 cells (11 GB, 217 s)
  where ``dt = 0.01`` s stores 5.7·10^7 (0.1 GB, 2 s);
* A*: 10 s for 10^6 expansions of four vehicles; a node costs 49 B in the node store,
  32 B per hash slot (two to four slots per node) and 32 B per heap entry.
"""

from __future__ import annotations

from typing import Final

import numpy as np

from auvplan.deconfliction.problem import CoordinationProblem
from auvplan.errors import InputError

#: Wall time a deconfliction run may take [s] (the pipeline's other stages take minutes).
TIME_BUDGET_S: Final = 60.0
#: Memory a deconfliction run may use [B].
MEMORY_BUDGET_BYTES: Final = 2 * 1024**3
#: Measured upper bound of the time per ordered-pair row of the grid [s] (module notes).
SECONDS_PER_PAIR_ROW: Final = 7e-7
#: Bytes per ordered-pair row: row pointer, its concatenated copy, one interval (lo, hi).
BYTES_PER_PAIR_ROW: Final = 32
#: Bytes per vehicle and grid step: grid point, progress, certificate positions and
#: distances, and the four safe-interval arrays of prioritised planning (4 entries per step).
BYTES_PER_VEHICLE_STEP: Final = 16 + 8 + 16 + 16 + 4 * 4 * 8
#: Largest number of cells of the pairwise A* cost-to-go (half the memory budget at 2 B per
#: cell; 20 s at the measured 38 ns per cell).
MAX_HEURISTIC_CELLS: Final = MEMORY_BUDGET_BYTES // 2 // 2
#: Largest number of stored A* nodes and heap entries (the other half of the memory budget at
#: 49 B + 2 x 32 B per node and 32 B per heap entry).
MAX_ASTAR_STORED: Final = MEMORY_BUDGET_BYTES // 2 // (49 + 2 * 32 + 32)


def check_grid_budget(problem: CoordinationProblem, *, n_ordered_pairs: int, what: str) -> None:
    """Raise before a run whose grid would exceed the time or memory budget.

    Parameters
    ----------
    problem : CoordinationProblem
        The grid to be searched.
    n_ordered_pairs : int
        Ordered pairs whose conflict tables the method builds.
    what : str
        The grid's time step setting for the message, e.g.
        ``"deconfliction.time_step_s = 0.001 s"``.

    Raises
    ------
    InputError
        Naming the grid size, the estimate against the budget, the vehicle with the most
        steps and what to change.
    """
    steps = problem.n_steps.astype(np.float64)
    pair_rows = n_ordered_pairs * float(steps.max() + 1.0)
    seconds = SECONDS_PER_PAIR_ROW * pair_rows
    memory = BYTES_PER_PAIR_ROW * pair_rows + BYTES_PER_VEHICLE_STEP * float(np.sum(steps + 1.0))
    if seconds <= TIME_BUDGET_S and memory <= MEMORY_BUDGET_BYTES:
        return
    worst = int(np.argmax(steps))
    factor = max(seconds / TIME_BUDGET_S, memory / MEMORY_BUDGET_BYTES)
    raise InputError(
        f"{what} is too fine for these paths: vehicle {problem.label(worst)}'s "
        f"{problem.path_lengths[worst]:.0f} m at {problem.cruise_speeds[worst]:.3g} m/s takes "
        f"{int(steps[worst])} grid steps, about {seconds:.0f} s and {memory / 1e9:.1f} GB of "
        f"deconfliction (budget {TIME_BUDGET_S:.0f} s, {MEMORY_BUDGET_BYTES / 1e9:.1f} GB); "
        f"make the time step about {factor:.2g} times larger, or raise the cruise speed "
        "(fleet.cruise_speed, or a shorter fleet.horizon_s)"
    )
