"""Fleet missions for the optimiser benchmarks, and one measurement per process.

A case is a real mission run through the pipeline up to the stage-3 problem (pre-planning and
deconfliction as ``auvplan plan`` does them): the ``demo`` crossing, or ``fleet-N-T-DT``, N
MEDUSAs for T seconds at control interval DT on a synthetic bank sized to the mission, half of
them on northbound lanes and half on eastbound lanes that cross them mid-way. Each
measurement runs in its own process (``python benchmarks/_fleet.py CASE SOLVER [--max-iter N]
[--repeats R]``), so that the peak memory is its own and the kernel cache is exactly what
``AUVPLAN_CACHE_DIR`` holds. It prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import resource
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
import tomli_w

from auvplan.mission import load_mission
from auvplan.mission.assembly import AssembledProblem, assemble_problem
from auvplan.mission.decomposition import solve_decomposed
from auvplan.mission.pipeline import fleet_layout
from auvplan.mission.preplan import PreplanStage, run_preplan
from auvplan.mission.timing import run_deconfliction
from auvplan.optimization import (
    ModelCache,
    ProntoOptions,
    StageBackend,
    project_guess,
    solve_fatrop,
    solve_ipopt,
    solve_pronto,
)
from auvplan.scenarios._terrain import write_synthetic_terrain
from auvplan.terrain import synthetic_bank

DEMO = Path(__file__).resolve().parents[1] / "src/auvplan/data/missions/demo.toml"
#: Cruise speed of the lane missions [m/s] and the path-length allowance for detours.
SPEED = 0.45
DETOUR = 1.2
#: Lane spacing [m] and terrain margin around the lanes [m].
LANE = 60.0
MARGIN = 120.0


def lane_mission(n_vehicles: int, horizon: float, dt: float, folder: Path) -> Path:
    """Write a lane-crossing mission of ``n_vehicles`` and its terrain into ``folder``."""
    length = SPEED * horizon / DETOUR
    extent = length + 2 * MARGIN
    spacing = max(4.0, extent / 300.0)
    write_synthetic_terrain(
        synthetic_bank(seed=11, extent_north=extent, extent_east=extent, spacing=spacing),
        folder / "terrain.nc",
    )
    vehicles = []
    middle = extent / 2
    for i in range(n_vehicles):
        lane = middle + LANE * ((i // 2) - (n_vehicles // 2 - 1) / 2)
        if i % 2 == 0:  # northbound
            start, goal, heading = (MARGIN, lane), (MARGIN + length, lane), 0.0
        else:  # eastbound
            start, goal, heading = (lane, MARGIN), (lane, MARGIN + length), 90.0
        vehicles.append(
            {
                "name": f"v{i}",
                "type": "medusa",
                "start": {"north": start[0], "east": start[1], "heading_deg": heading,
                          "speed": SPEED},
                "goal": {"north": goal[0], "east": goal[1], "heading_deg": heading},
            }
        )  # fmt: skip
    mission = {
        "terrain": {"file": "terrain.nc"},
        "maps": {"block": [2, 2]},
        "fleet": {"horizon_s": horizon, "safety_radius_m": 5.0},
        "vehicle": vehicles,
        "solver": {"dt_s": dt},
    }
    path = folder / "mission.toml"
    path.write_text(tomli_w.dumps(mission), encoding="utf-8")
    return path


def build_case(
    name: str, folder: Path, *, decomposed: bool = False
) -> tuple[AssembledProblem, ProntoOptions, PreplanStage]:
    """The stage-3 problem of a case (``demo`` energy-only, or ``fleet-N-T-DT``).

    Also returns stage 1's result, which the ``decomposed`` solve reads (the maps).
    """
    if name == "demo":
        config, terrain_weight = load_mission(DEMO), 0.0
    else:
        _, n, horizon, dt = name.split("-")
        path = lane_mission(int(n), float(horizon), float(dt), folder)
        config = load_mission(path)
        terrain_weight = config.weights.terrain
    preplan = run_preplan(config)
    layout = fleet_layout(config)
    deconfliction = run_deconfliction(
        layout, preplan.paths, preplan.starts[:, 2], preplan.goals[:, 2], fleet=config.fleet,
        settings=config.deconfliction, dt=config.solver.dt,
    )  # fmt: skip
    assembled = assemble_problem(
        layout, preplan, deconfliction, weights=config.weights, terrain_weight=terrain_weight,
        safety_radius=config.fleet.safety_radius, comms=config.comms, decomposed=decomposed,
    )  # fmt: skip
    return assembled, config.solver.pronto_options(), preplan


def measure(
    case: str, solver: str, max_iter: int | None = None, repeats: int = 1
) -> dict[str, Any]:
    """Solve ``case`` with ``solver`` and time it.

    ``kernels``/``casadi``: PRONTO with/without the compiled stage kernels (the time includes
    building the model: loading or compiling kernels). ``ipopt``/``ipopt-mx``: CasADi + IPOPT
    on the same discretised problem from PRONTO's projected initial trajectory, hard
    constraints, the NLP expanded to SX (fastest evaluation, memory grows with the horizon) or
    kept as MX (``ipopt-c``: MX with the stage Function compiled to C with its derivatives,
    cached in ``AUVPLAN_CACHE_DIR``: the first run's ``wall_s − solve_s`` includes the
    compilation); ``fatrop``/``fatrop-c``: CasADi + FATROP alike on the MX NLP (expanded, the
    crossing's took > 10 GB to build and compile), the stage Function on CasADi's virtual
    machine or compiled (``solve_s``: the solve alone).
    ``decomposed``/``decomposed-2``: vehicle by vehicle (:mod:`auvplan.mission.decomposition`)
    in one or two processes; ``directions`` counts the vehicles' iterations.
    ``kernels-solve``: the solve alone, like the CasADi solvers' ``solve_s`` (their NLP built
    and compiled code loaded): a second solve in the process, with the model and every
    numba kernel loaded by the first (``wall_s`` is the second solve's).
    ``kernels-projected``: the same from the CasADi solvers' start, PRONTO's projected
    initial trajectory, solved as it is (``solve_pronto(…, projected=True)``: no projection
    of the guess inside the time). ``kernels-2``/``kernels-solve-2``/``kernels-projected-2``:
    alike with the stage evaluations on two threads (``n_threads = 2``, as ``auvplan plan``
    runs a coupled fleet on two cores).
    ``max_iter`` caps the solver's iterations (for per-iteration timing). ``repeats``: a
    solve alone (``kernels-solve``, the CasADi solvers' ``solve_s``) is the fastest of that
    many solves in the process from the same start (``solves_s`` lists auvplan's), the same
    for every solver: on a machine whose speed varies from second to second, one solve
    measures the machine as much as the solver.
    """
    decomposed = solver.startswith("decomposed")
    with tempfile.TemporaryDirectory() as scratch:
        assembled, options, preplan = build_case(case, Path(scratch), decomposed=decomposed)
    problem, guess = assembled.problem, assembled.guess
    if max_iter is not None:
        options = ProntoOptions(**{**options.__dict__, "max_iter": max_iter})
    record: dict[str, Any] = {
        "case": case, "solver": solver, "n_x": problem.n_states, "n_steps": problem.n_steps,
        "n_substeps": problem.n_substeps,
    }  # fmt: skip
    started = time.perf_counter()
    solves: list[float] = []  # a solve alone, each of the repeats
    if solver.startswith(("ipopt", "fatrop")):
        initial, _ = project_guess(ModelCache().get(problem), guess, options)
        started = time.perf_counter()
        cap = {} if max_iter is None else {"max_iter": max_iter}
        compiled = solver.endswith("-c")
        if solver.startswith("ipopt"):
            expand = solver == "ipopt"
            result = solve_ipopt(
                problem, initial, expand=expand, compiled=compiled, repeats=repeats, **cap
            )
        else:
            result = solve_fatrop(
                problem, initial, expand=False, compiled=compiled, repeats=repeats, **cap
            )
        record.update(
            status=str(result.status), iterations=result.n_iter, cost=result.cost,
            solve_s=result.solve_time, repeats=repeats,
        )  # fmt: skip
    elif decomposed:
        jobs = 2 if solver.endswith("-2") else 1
        outcome = solve_decomposed(assembled, preplan, options, jobs=jobs)
        record.update(
            status=outcome.status.name, iterations=outcome.n_iter, cost=outcome.cost,
            objective=outcome.running_cost + outcome.terminal_cost,
            directions=len(outcome.history), jobs=jobs,
        )  # fmt: skip
    else:
        threads = 2 if solver.endswith("-2") else 1
        kind = solver.removesuffix("-2")
        backend = StageBackend(stage_kernels=kind != "casadi", n_threads=threads)
        options = ProntoOptions(
            **{**options.__dict__, "stage_kernels": backend.stage_kernels, "n_threads": threads}
        )
        cache = ModelCache()
        model = cache.get(problem, backend)
        record["model_s"] = time.perf_counter() - started
        record["threads"] = threads
        if kind in ("kernels-solve", "kernels-projected"):
            projected = kind == "kernels-projected"
            start = project_guess(model, guess, options)[0] if projected else guess
            solve_pronto(problem, start, options=options, cache=cache, projected=projected)
            for _ in range(repeats):
                started = time.perf_counter()
                outcome = solve_pronto(
                    problem, start, options=options, cache=cache, projected=projected
                )
                solves.append(time.perf_counter() - started)
            record.update(repeats=repeats, solves_s=solves)
        else:
            outcome = solve_pronto(problem, guess, options=options, cache=cache)
        stamps = np.array([0.0, *[it.wall_time for it in outcome.history]])
        record.update(
            status=outcome.status.name,
            iterations=outcome.n_iter,
            cost=outcome.cost,
            objective=outcome.running_cost + outcome.terminal_cost,
            iteration_s=float(np.median(np.diff(stamps))) if outcome.history else None,
        )
    record["wall_s"] = min(solves) if solves else time.perf_counter() - started
    record["peak_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    # the decomposed solve's second process (forked, ended by now): its own peak
    record["peak_child_mb"] = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    return record


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="One measurement of a case by a solver.")
    parser.add_argument("case")
    parser.add_argument("solver")
    parser.add_argument("--max-iter", type=int, default=None)
    parser.add_argument("--repeats", type=int, default=1)
    args = parser.parse_args()
    record = measure(args.case, args.solver, args.max_iter, args.repeats)
    print(json.dumps(record), flush=True)
