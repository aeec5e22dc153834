r"""Temporal deconfliction in the coordination space: weighted A* and prioritised planning.

Both methods search the grid of :class:`~auvplan.deconfliction.CoordinationProblem` (time
step ``dt``; per step a vehicle waits or advances ``h_i = v_i dt``) against the pairwise
forbidden sets of :mod:`auvplan.deconfliction.conflicts`, inflated by ``(h_i + h_j)/2`` so
that grid schedules are safe in continuous time; every returned schedule is re-checked by the
independent certificate :func:`~auvplan.deconfliction.certify_separation`.

``method="astar"`` (paper Sec. III-B)
    Weighted A* on the N-dimensional coordination grid. Any non-empty subset of the vehicles
    not yet at their goals advances one step per move. Minimised, lexicographically: the
    makespan, then the total delay (sum over vehicles of the steps spent waiting before
    arrival). Heuristic ``weight · max_i (n_i - k_i)``; ``weight = 1`` gives the grid
    optimum, ``weight = w`` a makespan within ``w`` times it. The default ``weight = √N``
    follows the paper (which used a Euclidean heuristic with ``ω >= √N``). Exact but
    exponential in ``N`` (``2^N - 1`` moves per node): meant for up to about 4 vehicles.
``method="prioritized"``
    Prioritised velocity tuning: vehicles in decreasing order of nominal duration; each
    takes the earliest-arrival time law along its own path that avoids the already-timed
    vehicles (an exact safe-interval dynamic programme on its ``(k, t)`` grid). Linear in the
    number of vehicles, so it serves 8–16 vehicles on 10-minute missions at 0.01 s.
    *Incomplete*: if a vehicle finds no time law (e.g. its start is swept by an earlier
    vehicle before it can leave), it is promoted to the front and the planning restarts, at
    most ``N`` times; it can still miss a schedule that A* would find, and makes no
    optimality claim beyond each vehicle's own earliest arrival.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from auvplan._typing import IntArray
from auvplan.deconfliction._astar_kernel import astar_coordination
from auvplan.deconfliction._sipp_kernel import earliest_arrival_schedule
from auvplan.deconfliction.conflicts import (
    ConflictTable,
    PairHeuristic,
    build_conflict_table,
    build_pair_heuristic,
    check_endpoints,
    check_pairwise_timing,
)
from auvplan.deconfliction.problem import CoordinationProblem
from auvplan.deconfliction.result import CoordinationResult, CoordinationStatus
from auvplan.deconfliction.schedule import arrival_times_of, certify_separation
from auvplan.errors import InfeasibleError, InputError, SolverError

logger = logging.getLogger(__name__)

METHODS = ("astar", "prioritized")
HEURISTICS = ("pairwise", "max")
#: Largest product of per-vehicle grid sizes that A* can key in an int64.
MAX_ASTAR_GRID = 1 << 62


def deconflict(
    problem: CoordinationProblem,
    *,
    method: str = "astar",
    weight: float | None = None,
    heuristic: str = "pairwise",
    coarsening: int = 1,
    max_expanded: int = 1_000_000,
) -> CoordinationResult:
    """Time laws along fixed paths that keep every pair at least ``2 r_c`` apart.

    Parameters
    ----------
    problem : CoordinationProblem
        Paths, safety radius, cruise speeds and time step.
    method : {"astar", "prioritized"}
        The search (module notes).
    weight : float, optional
        A* heuristic weight ``>= 1`` (default ``√N``); must be None for ``"prioritized"``.
    heuristic : {"pairwise", "max"}
        A*: ``"max"`` is ``max_i (n_i - k_i)``; ``"pairwise"`` (default) raises it to the
        exact two-vehicle makespan-to-go of every pair (module notes of the kernel), which
        costs one pass over each pair's 2-D grid but cuts the search by orders of magnitude.
    coarsening : int
        Search on the grid with time step ``coarsening · dt`` (and its per-step motion in the
        collision inflation), then return that schedule sampled every ``dt``. The schedule is
        the same piecewise-linear time law, so it stays certified (finer sampling never
        lowers the certificate); optimality then refers to the coarse grid. ``1`` (default)
        searches the problem's own grid.
    max_expanded : int
        A* expansion budget. Memory grows with it: up to ``2^N - 1`` heap entries (32 B)
        per expansion, about 0.5 GB at the default for four vehicles.

    Returns
    -------
    CoordinationResult
        Grid schedule sampled every ``time_step`` from 0 to the makespan.

    Raises
    ------
    InputError
        Unknown method, bad weight, or a grid too large for A* (use ``"prioritized"``).
    InfeasibleError
        Two starts or two goals within ``2 r_c``; a pair that no timing separates (message
        names the pair and places); or no schedule found on the grid.
    SolverError
        A* exhausted ``max_expanded``.

    Examples
    --------
    >>> problem = CoordinationProblem(
    ...     (np.array([[-10.0, 0.0], [10.0, 0.0]]), np.array([[0.0, -10.0], [0.0, 10.0]])),
    ...     safety_radius=1.0, cruise_speeds=np.ones(2), time_step=0.5)
    >>> result = deconflict(problem, weight=1.0)
    >>> result.status.name, result.min_separation >= 2.0, float(result.delays.max()) > 0
    ('OPTIMAL', True, True)
    """
    if method not in METHODS:
        raise InputError(f"method must be one of {METHODS}, got {method!r}")
    if not (isinstance(coarsening, int) and coarsening >= 1):
        raise InputError(f"coarsening must be an integer >= 1, got {coarsening!r}")
    n = problem.n_vehicles
    check_endpoints(problem)
    fine = problem
    if coarsening > 1:
        problem = CoordinationProblem(
            fine.paths, fine.safety_radius, fine.cruise_speeds, fine.time_step * coarsening
        )
    if method == "astar":
        if weight is None:
            weight = math.sqrt(n)
        if not (math.isfinite(weight) and weight >= 1.0):
            raise InputError(f"weight must be finite and >= 1, got {weight}")
        grid_size = 1.0
        for n_i in problem.n_steps:
            grid_size *= float(n_i) + 1.0
        if grid_size >= MAX_ASTAR_GRID:
            raise InputError(
                f"the {n}-D coordination grid has {grid_size:.3g} nodes, too many for A*; "
                "use method='prioritized' or a coarser time_step"
            )
        pairs = tuple((i, j) for i in range(n) for j in range(i + 1, n))
        table = build_conflict_table(problem, ordered_pairs=pairs)
        check_pairwise_timing(problem, table)
        if heuristic not in HEURISTICS:
            raise InputError(f"heuristic must be one of {HEURISTICS}, got {heuristic!r}")
        grid, n_expanded = _solve_astar(problem, table, weight, heuristic, max_expanded)
        status = (
            CoordinationStatus.OPTIMAL if weight == 1.0 else CoordinationStatus.BOUNDED_SUBOPTIMAL
        )
        note = f"weighted A* (weight {weight:.3g}) on the {n}-D coordination grid"
    else:
        if weight is not None:
            raise InputError(f"weight applies to method='astar' only, got {weight}")
        table = build_conflict_table(problem)
        check_pairwise_timing(problem, table)
        grid, n_expanded = _solve_prioritized(problem, table)
        status = CoordinationStatus.FEASIBLE
        note = "prioritised velocity tuning"
    if coarsening > 1:
        note += f" at coarsening {coarsening} (search time step {problem.time_step:g} s)"
    return _grid_result(problem, fine, coarsening, grid, status, note, method, weight, n_expanded)


def _solve_astar(
    problem: CoordinationProblem,
    table: ConflictTable,
    weight: float,
    heuristic: str,
    max_expanded: int,
) -> tuple[IntArray, int]:
    if heuristic == "pairwise":
        pair = build_pair_heuristic(problem, table)
    else:
        none = np.zeros(0, dtype=np.int64)
        pair = PairHeuristic(
            np.full(problem.n_vehicles**2, -1, dtype=np.int64),
            none,
            none,
            none,
            np.zeros(0, dtype=np.uint16),
        )
    code, path, n_expanded = astar_coordination(
        problem.n_steps,
        table.pair_base,
        table.row_ptr,
        table.lo,
        table.hi,
        pair.pair_base,
        pair.row_first,
        pair.row_start,
        pair.row_len,
        pair.excess,
        weight,
        max_expanded,
    )
    if code == 1:
        raise InfeasibleError(
            f"no collision-free schedule exists on the coordination grid "
            f"(dt = {problem.time_step:g} s, {n_expanded} nodes expanded) although every pair "
            "alone can be separated; the vehicles block each other jointly"
        )
    if code == 2:
        raise SolverError(
            f"A* expanded max_expanded={max_expanded} nodes without reaching the goal; "
            "raise weight or coarsening, or use method='prioritized'"
        )
    return np.ascontiguousarray(path.T), int(n_expanded)


def _schedule_from_arrival(arrival: IntArray, horizon: int) -> IntArray:
    """Grid index at each time step ``0 … horizon`` from per-index arrival steps."""
    return np.searchsorted(arrival, np.arange(horizon + 1), side="right").astype(np.int64) - 1


def _solve_prioritized(problem: CoordinationProblem, table: ConflictTable) -> tuple[IntArray, int]:
    n = problem.n_vehicles
    order = sorted(range(n), key=lambda i: (-int(problem.n_steps[i]), i))
    tried: set[tuple[int, ...]] = set()
    n_states_total = 0
    while tuple(order) not in tried:
        tried.add(tuple(order))
        arrivals: dict[int, IntArray] = {}
        failed = -1
        for vehicle in order:
            planned = list(arrivals)
            schedules = [_schedule_from_arrival(arrivals[j], int(arrivals[j][-1])) for j in planned]
            ptr = np.zeros(len(planned) + 1, dtype=np.int64)
            ptr[1:] = np.cumsum([s.shape[0] for s in schedules])
            found, arrival, n_states = earliest_arrival_schedule(
                int(problem.n_steps[vehicle]),
                np.arange(len(planned), dtype=np.int64),
                np.concatenate(schedules) if schedules else np.zeros(0, dtype=np.int64),
                ptr,
                np.array([problem.n_steps[j] for j in planned], dtype=np.int64),
                np.array([table.pair_base[vehicle * n + j] for j in planned], dtype=np.int64),
                table.row_ptr,
                table.lo,
                table.hi,
            )
            n_states_total += int(n_states)
            if not found:
                failed = vehicle
                break
            arrivals[vehicle] = arrival
        if failed < 0:
            makespan = max(int(a[-1]) for a in arrivals.values())
            grid = np.stack([_schedule_from_arrival(arrivals[i], makespan) for i in range(n)])
            return grid, n_states_total
        logger.info("prioritized: vehicle %d found no time law; promoting it", failed)
        order = [failed] + [v for v in order if v != failed]
    raise InfeasibleError(
        f"prioritised planning found no schedule for vehicle {problem.label(failed)} in any of "
        f"{len(tried)} priority orders (the method is incomplete; try method='astar')"
    )


def _grid_result(
    problem: CoordinationProblem,
    fine: CoordinationProblem,
    coarsening: int,
    grid: IntArray,
    status: CoordinationStatus,
    note: str,
    method: str,
    weight: float | None,
    n_expanded: int,
) -> CoordinationResult:
    n_t = grid.shape[1]
    progress = np.stack([problem.grid_progress(i, grid[i]) for i in range(problem.n_vehicles)])
    if coarsening > 1:  # the same piecewise-linear time law, sampled every fine time step
        samples = np.arange((n_t - 1) * coarsening + 1) / coarsening
        progress = np.stack([np.interp(samples, np.arange(n_t), row) for row in progress])
        n_t = samples.shape[0]
    problem = fine
    time = np.arange(n_t, dtype=np.float64) * problem.time_step
    certificate = certify_separation(problem, time, progress)
    arrivals = arrival_times_of(problem, time, progress)
    delays = arrivals - problem.nominal_arrival_times
    message = (
        f"{note}: makespan {arrivals.max():.6g} s, total delay {delays.sum():.6g} s, "
        f"certified separation {certificate.min_separation:.4g} m >= "
        f"2 r_c = {problem.separation:g} m"
    )
    if not certificate.holds:
        status = CoordinationStatus.UNCERTIFIED
        message = f"{note}: separation NOT certified ({certificate.min_separation:.4g} m)"
        logger.warning(message)
    return CoordinationResult(
        status=status,
        message=message,
        method=method,
        weight=float("nan") if weight is None else float(weight),
        time=time,
        progress=progress,
        arrival_times=arrivals,
        delays=delays,
        certificate=certificate,
        n_expanded=n_expanded,
        objective=(float(arrivals.max()), float(delays.sum())),
    )
