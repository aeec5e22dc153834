"""Stage 3 side by side: auvplan's PRONTO vs CasADi VM vs CasADi+IPOPT vs CasADi+FATROP.

Run once and print every table (all ratios from this one run, on this machine)::

    .venv/bin/python benchmarks/bench_pronto.py           # comparison, targets, scaling
    .venv/bin/python benchmarks/bench_pronto.py --quick   # the crossing only
    .venv/bin/python benchmarks/bench_pronto.py --quick --repeats 10  # solves alone: best of 10

Cases are real missions up to the stage-3 problem (:mod:`_fleet`): ``demo`` is the built-in
two-MEDUSA crossing (600 s, ``dt_s`` 0.5, propeller order 3) optimised energy-only, and
``fleet-N-T-DT`` N MEDUSAs on crossing lanes for T seconds at ``dt_s`` DT. Every measurement
is a separate process (its own peak memory). ``cold``: an empty kernel cache, so the time
includes compiling the vehicle's kernels; ``warm``: the cache filled by the cold run.
PRONTO times include building the model; IPOPT times the solve from PRONTO's projected
initial trajectory with the path constraints hard (MUMPS, exact Hessian), on an MX NLP and,
for the crossing only, an SX NLP (which needs ~15 GB); ratios are against the faster of them.
FATROP (structure-exploiting interior point, in CasADi's wheel) solves the same stage-ordered
NLP (vehicles stacked in one stage state) on CasADi's VM; IPOPT and FATROP also with the
stage Function and its derivatives compiled to C (``compiled=True``; the first run, in an
empty cache, compiles). A CasADi solve that reaches the optimum is set, by its solve alone
(without building or compiling), against auvplan's warm stage 3 (in a fresh process: the
model built and numba's cached kernels loaded, about 0.3 s) and against auvplan's solve
alone (a second solve in the process, like for like), also from the CasADi solvers' own
start (PRONTO's projected initial trajectory, solved as it is: ``projected=True``); one that
does not is marked. With ``--repeats R`` every solve alone, auvplan's and the CasADi
solvers', is the fastest of R in its process (the same solve from the same start).

Tables: (1) auvplan vs CasADi VM vs IPOPT: wall time, iterations, final cost, peak memory;
(2) the targets of issues 12 and 27 (fleets of 4, 8, 16 and 32 for an hour, coupled and
decomposed in two processes; ``auvplan demo``
end to end, cold as on a fresh install and warm, with the default second process and
without);
(3) the cost of one iteration against horizon and fleet size (per stage and vehicle);
(4) the decomposed solve (:mod:`auvplan.mission.decomposition`) against fleet size.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
COMPARED = ("demo", "fleet-4-600-1")
TARGETS = ("fleet-4-3600-1", "fleet-8-3600-1", "fleet-16-3600-1", "fleet-32-3600-1")
SCALING_HORIZONS = (600, 1800, 3600, 10800)
SCALING_FLEETS = (2, 4, 8, 16, 32)
#: PRONTO iterations run per scaling point (the median iteration time is reported).
SCALING_ITERATIONS = 4


def run(
    case: str, solver: str, cache: Path, max_iter: int | None = None, repeats: int = 1
) -> dict[str, Any]:
    """One measurement in a fresh process (``_fleet.py``); its JSON record."""
    command = [sys.executable, str(HERE / "_fleet.py"), case, solver, "--repeats", str(repeats)]
    if max_iter is not None:
        command += ["--max-iter", str(max_iter)]
    env = {**os.environ, "AUVPLAN_CACHE_DIR": str(cache)}
    done = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
    if done.returncode != 0:
        lines = done.stderr.strip().splitlines()
        reason = lines[-1] if lines else f"exit status {done.returncode}"  # e.g. killed
        return {"case": case, "solver": solver, "error": reason}
    record: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return record


def timed_demo(cache: Path, jobs: int) -> tuple[float, float]:
    """Wall time [s] and peak memory [MB] of ``auvplan -q demo --jobs J`` end to end.

    ``cache`` holds both auvplan's and numba's caches (``NUMBA_CACHE_DIR``), so an empty one
    is a first run on a fresh install: every kernel is compiled. Figures are included.
    """
    env = {**os.environ, "AUVPLAN_CACHE_DIR": str(cache), "NUMBA_CACHE_DIR": str(cache / "numba")}
    command = [sys.executable, "-m", "auvplan.cli.main", "-q", "demo", "--jobs", str(jobs)]
    with tempfile.TemporaryDirectory() as scratch:
        started = time.perf_counter()
        child = subprocess.Popen(
            [*command, "-o", f"{scratch}/out"],
            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        _, status, usage = os.wait4(child.pid, 0)
        wall = time.perf_counter() - started
    if status != 0:
        raise RuntimeError(f"auvplan demo failed with status {status}")
    return wall, usage.ru_maxrss / 1024


#: Statuses of a solve that reached the optimum (PRONTO's, then IPOPT's and FATROP's).
SOLVED = ("CONVERGED", "IpoptStatus.SOLVED", "IpoptStatus.ACCEPTABLE")


def _row(record: dict[str, Any], label: str, reference: float | None) -> str:
    if "error" in record:
        return f"| {record['case']} | {label} | failed: {record['error']} | | | | |"
    ratio = "" if reference is None else f"{reference / record['wall_s']:.1f}x"
    status = "" if record["status"] in SOLVED else f" ({record['status']}: not the optimum)"
    return (
        f"| {record['case']} | {label} | {record['wall_s']:.1f} | {ratio} | "
        f"{record['iterations']} | {record['cost']:.2f}{status} | {record['peak_mb']:.0f} |"
    )


def comparison(cases: tuple[str, ...], repeats: int = 1) -> str:
    """Table 1: each case with every solver (the ratio is IPOPT's time over each).

    Each case starts from an empty kernel cache (its cold run compiles the kernels). A solve
    alone (auvplan's and the CasADi solvers') is the fastest of ``repeats`` in its process.
    """
    lines = [
        "| case | solver | wall s | IPOPT / this | iterations | final cost | peak MB |",
        "|---|---|---|---|---|---|---|",
    ]
    for case in cases:
        with tempfile.TemporaryDirectory(prefix="auvplan_cold_") as empty:
            cold_cache = Path(empty)
            records = {
                # on two threads, as `auvplan plan` on two cores: it compiles every kernel
                # either thread count calls (the threaded clipping too)
                "auvplan, cold cache, 2 threads": run(case, "kernels-2", cold_cache),
                "auvplan, warm cache": run(case, "kernels", cold_cache),
                "auvplan, solve alone (model and kernels loaded)": run(
                    case, "kernels-solve", cold_cache, repeats=repeats
                ),
                "auvplan, warm cache, 2 threads": run(case, "kernels-2", cold_cache),
                "auvplan, solve alone, 2 threads": run(
                    case, "kernels-solve-2", cold_cache, repeats=repeats
                ),
                "auvplan, solve alone from the CasADi solvers' start": run(
                    case, "kernels-projected", cold_cache, repeats=repeats
                ),
                "auvplan, solve alone from the CasADi solvers' start, 2 threads": run(
                    case, "kernels-projected-2", cold_cache, repeats=repeats
                ),
                "PRONTO on the CasADi VM": run(case, "casadi", cold_cache),
                "CasADi + IPOPT (MX NLP)": run(case, "ipopt-mx", cold_cache, repeats=repeats),
            }
            if case == "demo":  # the SX NLP needs ~15 GB already here: crossing only
                records["CasADi + IPOPT (SX NLP)"] = run(case, "ipopt", cold_cache, repeats=repeats)
            for label, solver in (
                ("CasADi + IPOPT (C-compiled stage)", "ipopt-c"),
                ("CasADi + FATROP (VM)", "fatrop"),
                ("CasADi + FATROP (C-compiled stage)", "fatrop-c"),
            ):
                records[label] = run(case, solver, cold_cache, repeats=repeats)
        solved = [r for label, r in records.items() if "IPOPT" in label and "error" not in r]
        ipopt = min(solved, key=lambda r: r["wall_s"], default=records["CasADi + IPOPT (MX NLP)"])
        reference = ipopt.get("wall_s")  # the faster IPOPT set-up
        for label, record in records.items():
            lines.append(_row(record, label, reference))
        warm = records["auvplan, warm cache"]
        if "error" not in warm and "error" not in ipopt:
            gap = (warm["objective"] - ipopt["cost"]) / abs(ipopt["cost"])
            lines.append(f"| {case} | objective auvplan vs IPOPT | {100 * gap:+.3f} % | | | | |")
        for label, record in records.items():  # auvplan's warm runs and solves alone
            if label.startswith("auvplan") and "cold" not in label and "error" not in record:
                lines.extend(_solve_ratios(case, label, records))
        print(f"compared: {case}", flush=True)
    return "\n".join(lines)


def _solve_ratios(case: str, reference: str, records: dict[str, Any]) -> list[str]:
    """Each CasADi solve alone (no NLP building, no C compilation on their side) against
    auvplan's ``reference`` record: its warm stage 3 (model and kernel loading included) or
    its solve alone (like for like: model and kernels loaded)."""
    lines = []
    ours = records[reference]["wall_s"]
    for label, record in records.items():
        if "solve_s" in record and record["status"] in SOLVED:
            ratio = record["solve_s"] / ours
            built = record["wall_s"] - record["solve_s"]
            lines.append(
                f"| {case} | {label}: solve alone {record['solve_s']:.2f} s (+{built:.1f} s "
                f"building/compiling) | {ratio:.1f}x slower than {reference} | | | | |"
            )
    return lines


def targets(cache: Path) -> str:
    """Table 2: the issue's targets with a warm cache, and the demo end to end."""
    lines = ["| target | measured | goal |", "|---|---|---|"]
    goals = {
        "fleet-4-3600-1": "< 30 s",
        "fleet-8-3600-1": "< 120 s",
        "fleet-16-3600-1": "< 120 s (issue 27)",
        "fleet-32-3600-1": "< 300 s and < 8 GB (issue 27)",
    }
    for case in TARGETS:
        for solver, how in (("kernels", "coupled"), ("decomposed-2", "decomposed, 2 processes")):
            record = run(case, solver, cache)
            measured = record.get("error") or (
                f"{record['wall_s']:.1f} s, {record['iterations']} steps, "
                f"{record['status']}, {record['cost']:.0f} J, {record['peak_mb']:.0f} MB"
            )
            lines.append(f"| {case}, {how} | {measured} | {goals[case]} |")
            print(f"target: {case}, {how}", flush=True)
    for jobs, how in ((2, "two processes (default)"), (1, "one process, `--jobs 1`")):
        with tempfile.TemporaryDirectory() as empty:
            cold, cold_mb = timed_demo(Path(empty), jobs)
            warm, warm_mb = timed_demo(Path(empty), jobs)
        lines.append(f"| `auvplan demo`, cold, {how} | {cold:.1f} s, {cold_mb:.0f} MB | < 60 s |")
        lines.append(f"| `auvplan demo`, warm, {how} | {warm:.1f} s, {warm_mb:.0f} MB | < 10 s |")
        print(f"target: demo, {jobs} jobs", flush=True)
    return "\n".join(lines)


def decomposed_scaling(cache: Path) -> str:
    """Table 4: the decomposed solve (one process) against fleet size, solved to the end.

    Its unit of work is one vehicle's PRONTO iteration (a direction of its own problem): the
    cost per stage is the solve's wall time over the directions of all vehicles and ``N``.
    """
    lines = [
        "| vehicles | wall s | status | vehicle iterations | µs per stage, vehicle iteration "
        "| peak MB |".replace(", vehicle", " and vehicle"),
        "|---|---|---|---|---|---|",
    ]
    for n_vehicles in SCALING_FLEETS:
        record = run(f"fleet-{n_vehicles}-3600-1", "decomposed", cache)
        if "error" in record:
            lines.append(f"| {n_vehicles} | failed: {record['error']} | | | | |")
            continue
        per = 1e6 * record["wall_s"] / (record["directions"] * record["n_steps"])
        lines.append(
            f"| {n_vehicles} | {record['wall_s']:.1f} | {record['status']} | "
            f"{record['directions']} | {per:.0f} | {record['peak_mb']:.0f} |"
        )
        print(f"decomposed scaling: {n_vehicles} vehicles", flush=True)
    return "\n".join(lines)


def scaling(cache: Path) -> str:
    """Table 3: median wall time of one PRONTO iteration against horizon and fleet size."""
    lines = [
        "| vehicles | horizon s | stages N | iteration s | µs per stage and vehicle |",
        "|---|---|---|---|---|",
    ]
    points = [(4, horizon) for horizon in SCALING_HORIZONS]
    points += [(n, 3600) for n in SCALING_FLEETS if n != 4]
    for n_vehicles, horizon in points:
        record = run(f"fleet-{n_vehicles}-{horizon}-1", "kernels", cache, SCALING_ITERATIONS)
        if "error" in record or record.get("iteration_s") is None:
            lines.append(f"| {n_vehicles} | {horizon} | | failed: {record.get('error')} | |")
            continue
        per = 1e6 * record["iteration_s"] / (record["n_steps"] * n_vehicles)
        lines.append(
            f"| {n_vehicles} | {horizon} | {record['n_steps']} | {record['iteration_s']:.2f} | "
            f"{per:.0f} |"
        )
        print(f"scaling: {n_vehicles} vehicles, {horizon} s", flush=True)
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the crossing comparison only")
    parser.add_argument(
        "--repeats", type=int, default=1, help="solves alone: the fastest of R in a process"
    )
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="auvplan_bench_") as cache_dir:
        cache = Path(cache_dir)
        tables = [comparison(COMPARED[:1] if args.quick else COMPARED, args.repeats)]
        run("demo", "kernels", cache)  # fills the cache of the following tables
        if not args.quick:
            tables += [targets(cache), scaling(cache), decomposed_scaling(cache)]
    print()
    print("\n\n".join(tables))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
