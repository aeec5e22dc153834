r"""Temporal deconfliction in the coordination space: weighted A* and prioritised planning.

Both methods search the grid of :class:`~auvplan.deconfliction.CoordinationProblem` (time
step ``dt``; per step a vehicle waits or advances ``h_i = v_i dt``) against the pairwise
forbidden sets of :mod:`auvplan.deconfliction.conflicts`, inflated by ``(h_i + h_j)/2`` so
that grid schedules are safe in continuous time; every returned schedule is re-checked by the
independent certificate :func:`~auvplan.deconfliction.certify_separation`.

``method="auto"`` (default)
    Exact A* for up to :data:`AUTO_ASTAR_MAX_VEHICLES` vehicles; when it exceeds a budget
    (expansions, stored nodes, the pairwise heuristic's cells or the grid's size) it falls
    back to A* on a grid :data:`FALLBACK_MARGIN` coarser (when that is at least twice as
    coarse as the grid searched), then to prioritised planning. Larger fleets use
    prioritised planning. The result's ``method`` says which search produced the schedule
    and ``fallback`` why the requested one did not (measured on the paper-sized four-vehicle
    crossing of ``benchmarks/bench_deconfliction.py``: the coarse A* returns a makespan
    7.5 s shorter than prioritised planning, in 0.3 s).
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

import enum
import logging
import math
from dataclasses import dataclass
from typing import Final, TypeVar

import numpy as np

from auvplan._typing import IntArray
from auvplan.deconfliction._astar_kernel import AstarOutcome, astar_coordination
from auvplan.deconfliction._budget import MAX_ASTAR_STORED, MAX_HEURISTIC_CELLS, check_grid_budget
from auvplan.deconfliction._sipp_kernel import earliest_arrival_schedule
from auvplan.deconfliction.conflicts import (
    PairHeuristic,
    build_conflict_table,
    build_pair_heuristic,
    check_endpoints,
    check_pairwise_timing,
)
from auvplan.deconfliction.problem import CoordinationProblem
from auvplan.deconfliction.result import (
    CoordinationResult,
    CoordinationStatus,
    DeconflictionMethod,
)
from auvplan.deconfliction.schedule import arrival_times_of, certify_separation
from auvplan.errors import InfeasibleError, InputError, SolverError

logger = logging.getLogger(__name__)


class AstarHeuristic(enum.StrEnum):
    """The A* heuristic: ``max_i (n_i - k_i)``, or raised to every pair's exact cost-to-go."""

    PAIRWISE = "pairwise"
    MAX = "max"


#: ``method="auto"`` runs A* for fleets up to this size (its moves per node grow as ``2^N``).
AUTO_ASTAR_MAX_VEHICLES: Final = 4
#: Grid margin ``(h_i + h_j) / 2`` of the coarser grid ``"auto"`` falls back to, as a fraction
#: of ``2 r_c`` (5 %: the four-vehicle benchmark then expands 5.5·10^4 nodes instead of
#: more than 10^6).
FALLBACK_MARGIN: Final = 0.05
#: Largest product of per-vehicle grid sizes that A* can key in an int64.
MAX_ASTAR_GRID: Final = 1 << 62


@dataclass(frozen=True)
class _Schedule:
    """A grid schedule found by one search, and how it was found."""

    grid: IntArray
    problem: CoordinationProblem
    coarsening: int
    method: DeconflictionMethod
    status: CoordinationStatus
    note: str
    weight: float | None
    n_expanded: int


EnumT = TypeVar("EnumT", bound=enum.StrEnum)


class _AstarGaveUp(Exception):
    """A* stopped at one of its budgets; ``str()`` says which (a fallback reason)."""


def deconflict(
    problem: CoordinationProblem,
    *,
    method: DeconflictionMethod | str = DeconflictionMethod.AUTO,
    weight: float | None = None,
    heuristic: AstarHeuristic | str = AstarHeuristic.PAIRWISE,
    coarsening: int = 1,
    max_expanded: int = 1_000_000,
) -> CoordinationResult:
    """Time laws along fixed paths that keep every pair at least ``2 r_c`` apart.

    Parameters
    ----------
    problem : CoordinationProblem
        Paths, safety radius, cruise speeds and time step.
    method : DeconflictionMethod or {"auto", "astar", "prioritized"}
        The search (module notes); ``"auto"`` (default) chooses and falls back by itself.
    weight : float, optional
        A* heuristic weight ``>= 1`` (default ``√N``); must be None for ``"prioritized"``.
    heuristic : AstarHeuristic or {"pairwise", "max"}
        A*: ``"max"`` is ``max_i (n_i - k_i)``; ``"pairwise"`` (default) raises it to the
        exact two-vehicle makespan-to-go of every pair (module notes of the kernel), which
        costs one pass over each pair's 2-D grid but cuts the search by orders of magnitude.
    coarsening : int
        Search on the grid with time step ``coarsening · dt`` (and its per-step motion in the
        collision inflation), then return that schedule sampled every ``dt``. The schedule is
        the same piecewise-linear time law, so it stays certified (finer sampling never
        lowers the certificate); optimality then refers to the coarse grid. ``1`` (default)
        searches the problem's own grid. A search step may move a vehicle at most ``2 r_c``.
    max_expanded : int
        A* expansion budget (about 10 s per 10^6 expansions of four vehicles). Stored nodes
        are capped separately to keep the run within the memory budget.

    Returns
    -------
    CoordinationResult
        Grid schedule sampled every ``time_step`` from 0 to the makespan, certified:
        ``method`` is the search that produced it, ``fallback`` why it is not the requested
        one (empty otherwise).

    Raises
    ------
    InputError
        Unknown method or heuristic, bad weight, a search step longer than ``2 r_c``
        (names ``deconfliction.time_step_s`` or ``deconfliction.coarsening``), or a grid
        whose estimated time or memory exceeds the budget of
        :mod:`auvplan.deconfliction._budget`; with ``"astar"``, a grid too large for A* or a
        pairwise heuristic over its budget.
    InfeasibleError
        Two starts or two goals within ``2 r_c``; a pair that no timing separates (message
        names the pair and places); no schedule found on the grid; or a schedule whose
        continuous separation certificate fails (names the pair and the time; an uncertified
        schedule is never returned).
    SolverError
        ``"astar"`` exhausted ``max_expanded`` (``"auto"`` falls back instead).

    Examples
    --------
    >>> problem = CoordinationProblem(
    ...     (np.array([[-10.0, 0.0], [10.0, 0.0]]), np.array([[0.0, -10.0], [0.0, 10.0]])),
    ...     safety_radius=1.0, cruise_speeds=np.ones(2), time_step=0.5)
    >>> result = deconflict(problem, weight=1.0)
    >>> result.status.name, str(result.method), result.min_separation >= 2.0
    ('OPTIMAL', 'astar', True)
    >>> float(result.delays.max()) > 0, result.fallback
    (True, '')
    """
    method = _parse(DeconflictionMethod, method, "method")
    heuristic = _parse(AstarHeuristic, heuristic, "heuristic")
    if not (isinstance(coarsening, int) and coarsening >= 1):
        raise InputError(f"coarsening must be an integer >= 1, got {coarsening!r}")
    n = problem.n_vehicles
    if weight is not None and not (math.isfinite(weight) and weight >= 1.0):
        raise InputError(f"weight must be finite and >= 1, got {weight}")
    if method is DeconflictionMethod.PRIORITIZED and weight is not None:
        raise InputError(f"weight applies to method='astar' only, got {weight}")
    check_endpoints(problem)
    if n == 1:  # no pair to keep apart: the nominal time law is optimal
        return _result(problem, _nominal_schedule(problem, method), "")
    search = _search_problem(problem, coarsening)
    fallback = ""
    if method is DeconflictionMethod.AUTO and n > AUTO_ASTAR_MAX_VEHICLES:
        fallback = f"auto: {n} vehicles > {AUTO_ASTAR_MAX_VEHICLES}, A* is exponential in the fleet"
    elif method is not DeconflictionMethod.PRIORITIZED:
        astar = (weight, heuristic, max_expanded)
        try:
            return _result(problem, _solve_astar(search, coarsening, *astar), "")
        except _AstarGaveUp as error:
            if method is DeconflictionMethod.ASTAR:
                raise _astar_error(error, search, coarsening) from None
            fallback = str(error)
        coarser = _fallback_coarsening(problem, coarsening)
        if coarser > 0:
            logger.info("auto: %s; A* at coarsening %d", fallback, coarser)
            try:
                schedule = _solve_astar(_search_problem(problem, coarser), coarser, *astar)
                return _result(problem, schedule, f"{fallback}; A* on a {coarser}x coarser grid")
            except _AstarGaveUp as error:
                fallback += f"; at coarsening {coarser}: {error}"
        fallback += "; prioritised planning"
        logger.info("auto: %s", fallback)
    return _result(problem, _solve_prioritized(search, coarsening), fallback)


def _parse(kind: type[EnumT], value: str, name: str) -> EnumT:
    try:
        return kind(value)
    except ValueError:
        choices = tuple(member.value for member in kind)
        raise InputError(f"{name} must be one of {choices}, got {value!r}") from None


def _search_problem(problem: CoordinationProblem, coarsening: int) -> CoordinationProblem:
    """The grid searched (time step ``coarsening · dt``); refuses steps longer than ``2 r_c``."""
    step = problem.step_lengths * coarsening
    worst = int(np.argmax(step))
    if step[worst] > problem.separation:
        motion = (
            f"vehicle {problem.label(worst)} would move {step[worst]:.3g} m per search step "
            f"at {problem.cruise_speeds[worst]:.3g} m/s, more than 2 r_c = "
            f"{problem.separation:g} m (the grid's collision margin grows with the step)"
        )
        if coarsening > 1:
            limit = max(int(problem.separation / problem.step_lengths[worst]), 1)
            raise InputError(
                f"deconfliction.coarsening = {coarsening} is too large: {motion}; "
                f"use coarsening <= {limit}"
            )
        limit_s = problem.separation / problem.cruise_speeds[worst]
        raise InputError(
            f"deconfliction.time_step_s = {problem.time_step:g} s is too coarse: {motion}; "
            f"use time_step_s <= {limit_s:.3g} s"
        )
    if coarsening == 1:
        return problem
    return CoordinationProblem(
        problem.paths,
        problem.safety_radius,
        problem.cruise_speeds,
        problem.time_step * coarsening,
        problem.names,
    )


def _fallback_coarsening(problem: CoordinationProblem, coarsening: int) -> int:
    """The coarsening of ``"auto"``'s coarser A* (0 when not at least twice ``coarsening``)."""
    coarser = int(FALLBACK_MARGIN * problem.separation / float(np.max(problem.step_lengths)))
    return coarser if coarser >= 2 * coarsening else 0


def _grid_setting(problem: CoordinationProblem, coarsening: int) -> str:
    """The settings that fix the grid's step, for messages."""
    setting = f"deconfliction.time_step_s = {problem.time_step / coarsening:g} s"
    return setting if coarsening == 1 else f"{setting} x deconfliction.coarsening = {coarsening}"


def _solve_astar(
    problem: CoordinationProblem,
    coarsening: int,
    weight: float | None,
    heuristic: AstarHeuristic,
    max_expanded: int,
) -> _Schedule:
    n = problem.n_vehicles
    if weight is None:
        weight = math.sqrt(n)
    grid_size = 1.0
    for n_i in problem.n_steps:
        grid_size *= float(n_i) + 1.0
    if grid_size >= MAX_ASTAR_GRID:
        raise _AstarGaveUp(f"the {n}-D coordination grid has {grid_size:.3g} nodes, too many")
    check_grid_budget(
        problem, n_ordered_pairs=n * (n - 1) // 2, what=_grid_setting(problem, coarsening)
    )
    table = build_conflict_table(
        problem, ordered_pairs=tuple((i, j) for i in range(n) for j in range(i + 1, n))
    )
    check_pairwise_timing(problem, table)
    if heuristic is AstarHeuristic.PAIRWISE:
        pair = build_pair_heuristic(problem, table, max_cells=MAX_HEURISTIC_CELLS)
        if pair is None:
            raise _AstarGaveUp(
                f"the pairwise A* heuristic needs more than {MAX_HEURISTIC_CELLS:.3g} cells"
            )
    else:
        none = np.zeros(0, dtype=np.int64)
        pair = PairHeuristic(
            np.full(n * n, -1, dtype=np.int64), none, none, none, np.zeros(0, dtype=np.uint16)
        )
    outcome, path, n_expanded = astar_coordination(
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
        MAX_ASTAR_STORED,
    )
    if outcome is AstarOutcome.NO_SCHEDULE:
        raise InfeasibleError(
            f"no collision-free schedule exists on the coordination grid "
            f"(dt = {problem.time_step:g} s, {n_expanded} nodes expanded) although every pair "
            "alone can be separated; the vehicles block each other jointly"
        )
    if outcome is AstarOutcome.BUDGET_EXHAUSTED:
        raise _AstarGaveUp(
            f"A* stopped after {n_expanded} expansions (max_expanded = {max_expanded}, "
            f"at most {MAX_ASTAR_STORED} stored nodes) without reaching the goal"
        )
    status = CoordinationStatus.OPTIMAL if weight == 1.0 else CoordinationStatus.BOUNDED_SUBOPTIMAL
    note = f"weighted A* (weight {weight:.3g}) on the {n}-D coordination grid"
    return _Schedule(
        np.ascontiguousarray(path.T),
        problem,
        coarsening,
        DeconflictionMethod.ASTAR,
        status,
        note,
        weight,
        int(n_expanded),
    )


def _astar_error(error: _AstarGaveUp, problem: CoordinationProblem, coarsening: int) -> Exception:
    """The user-facing error of ``method="astar"`` stopping at a budget."""
    advice = "use method='auto' or 'prioritized'"
    if "max_expanded" in str(error):
        return SolverError(f"{error}; raise weight or deconfliction.coarsening, or {advice}")
    return InputError(
        f"{_grid_setting(problem, coarsening)} is too fine for A*: {error}; raise it, or {advice}"
    )


def _schedule_from_arrival(arrival: IntArray, horizon: int) -> IntArray:
    """Grid index at each time step ``0 … horizon`` from per-index arrival steps."""
    return np.searchsorted(arrival, np.arange(horizon + 1), side="right").astype(np.int64) - 1


def _nominal_schedule(problem: CoordinationProblem, method: DeconflictionMethod) -> _Schedule:
    """The one vehicle of ``problem`` at its cruise speed: a grid index per time step."""
    grid = np.arange(int(problem.n_steps[0]) + 1, dtype=np.int64)[None, :]
    if method is DeconflictionMethod.PRIORITIZED:
        solved, status = DeconflictionMethod.PRIORITIZED, CoordinationStatus.FEASIBLE
    else:
        solved, status = DeconflictionMethod.ASTAR, CoordinationStatus.OPTIMAL
    return _Schedule(grid, problem, 1, solved, status, "nominal time law", None, 0)


def _solve_prioritized(problem: CoordinationProblem, coarsening: int) -> _Schedule:
    n = problem.n_vehicles
    check_grid_budget(problem, n_ordered_pairs=n * (n - 1), what=_grid_setting(problem, coarsening))
    table = build_conflict_table(problem)
    check_pairwise_timing(problem, table)
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
            return _Schedule(
                grid,
                problem,
                coarsening,
                DeconflictionMethod.PRIORITIZED,
                CoordinationStatus.FEASIBLE,
                "prioritised velocity tuning",
                None,
                n_states_total,
            )
        logger.info("prioritized: vehicle %d found no time law; promoting it", failed)
        order = [failed] + [v for v in order if v != failed]
    raise InfeasibleError(
        f"prioritised planning found no schedule for vehicle {problem.label(failed)} in any of "
        f"{len(tried)} priority orders (the method is incomplete; try method='astar')"
    )


def _result(problem: CoordinationProblem, schedule: _Schedule, fallback: str) -> CoordinationResult:
    """The certified result of a grid schedule, sampled every ``problem.time_step``.

    Raises
    ------
    InfeasibleError
        When the continuous certificate fails (names the pair, the time and the bound).
    """
    coarse = schedule.problem
    c = schedule.coarsening
    n_t = schedule.grid.shape[1]
    progress = np.stack(
        [coarse.grid_progress(i, schedule.grid[i]) for i in range(coarse.n_vehicles)]
    )
    if c > 1:  # the same piecewise-linear time law, sampled every fine time step
        samples = np.arange((n_t - 1) * c + 1) / c
        progress = np.stack([np.interp(samples, np.arange(n_t), row) for row in progress])
        n_t = samples.shape[0]
    time = np.arange(n_t, dtype=np.float64) * problem.time_step
    certificate = certify_separation(problem, time, progress)
    note = schedule.note
    if c > 1:
        note += f" at coarsening {c} (search time step {coarse.time_step:g} s)"
    if not certificate.holds:
        i, j = certificate.pair
        raise InfeasibleError(
            f"{note}: the schedule of vehicles {problem.label(i)} and {problem.label(j)} is not "
            f"certified ({certificate.min_separation:.4g} m < 2 r_c = {problem.separation:g} m "
            f"at t = {certificate.time:.6g} s); the grid is too coarse or too fine for these "
            "coordinates, change deconfliction.time_step_s"
        )
    arrivals = arrival_times_of(problem, time, progress)
    delays = arrivals - problem.nominal_arrival_times
    message = (
        f"{note}: makespan {arrivals.max():.6g} s, total delay {delays.sum():.6g} s, "
        f"certified separation {certificate.min_separation:.4g} m >= "
        f"2 r_c = {problem.separation:g} m"
    )
    if fallback:
        message += f" ({fallback})"
    return CoordinationResult(
        status=schedule.status,
        message=message,
        method=schedule.method,
        weight=float("nan") if schedule.weight is None else float(schedule.weight),
        time=time,
        progress=progress,
        arrival_times=arrivals,
        delays=delays,
        certificate=certificate,
        n_expanded=schedule.n_expanded,
        objective=(float(arrivals.max()), float(delays.sum())),
        fallback=fallback,
    )
