"""The stage-3 node kernels: scalar numba code point by point vs the lane kernels auvplan ships.

The sweeps of :mod:`auvplan.optimization.block_kernels` evaluate the vehicle model's node
kernels (``first``, ``hessian``) on :data:`~auvplan.optimization._lane_codegen.LANES` points
at once: every SX instruction is one LLVM instruction on ``<LANES x double>``
(:mod:`auvplan.optimization._lane_codegen`). This benchmark measures what that buys per
kernel, against the scalar numba kernels of the same CasADi Functions
(:func:`~auvplan.optimization._numba_codegen.numba_source` without lanes, as shipped before),
on the node arguments of a real forward sweep along the demo's optimum (states, inputs,
parameters, weights, node derivatives ``D``; a costate of the sweep's scale), each in the
layout its sweep keeps them in (rows for the scalar code, lane-major groups for the lanes).

Reported per kernel: SX instructions, microseconds per point (best of ``--repeat``), the
speed-up and whether every output is equal **to the bit**. Run::

    .venv/bin/python benchmarks/bench_lane_kernels.py [--repeat 30]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import casadi as ca
import numpy as np

from _fleet import build_case
from auvplan.optimization import ModelCache, ProntoOptions, StageBackend, solve_pronto
from auvplan.optimization._kernel_cache import load_kernel_module
from auvplan.optimization._lane_codegen import LANES
from auvplan.optimization._numba_codegen import numba_source
from auvplan.optimization.block_kernels import _symbolic_kernels


def _loop_source(n_args: int, lanes: bool) -> str:
    """A numba loop calling ``kernel`` (rows) or ``kernel_lanes`` (groups) on every point."""
    names = [f"a{k}" for k in range(n_args)]
    kernel = "kernel_lanes" if lanes else "kernel"
    return f"""
@numba.njit(cache=True)
def loop({", ".join(names)}):
    for g in range(a0.shape[0]):
        {kernel}({", ".join(f"{a}[g]" for a in names)})
"""


def _kernel_loop(function: ca.Function, lanes: bool, cache: Path) -> Callable[..., None]:
    """The loop of :func:`_loop_source` over ``function``'s scalar or lane kernel."""
    n_args = function.n_in() + function.n_out()
    source = numba_source(
        {"kernel": function}, "bench_lane_kernels", _loop_source(n_args, lanes),
        batched=(), lanes=("kernel",) if lanes else (),
    )  # fmt: skip
    module, _ = load_kernel_module(source, lambda: source, cache)
    loop: Callable[..., None] = module.loop
    return loop


def _best_us(
    loop: Callable[..., None], arrays: list[np.ndarray], points: int, repeat: int
) -> float:
    """Best of ``repeat`` runs of ``loop(*arrays)`` (after one untimed), in µs per point."""
    loop(*arrays)
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        loop(*arrays)
        times.append(time.perf_counter() - started)
    return min(times) / points * 1e6


def _grouped(rows: np.ndarray) -> np.ndarray:
    """Rows ``(P, n)`` (``P`` a multiple of LANES) as lane-major groups ``(P/LANES, n, LANES)``."""
    return np.ascontiguousarray(rows.reshape(-1, LANES, rows.shape[1]).transpose(0, 2, 1))


def node_arguments() -> tuple[dict[str, ca.Function], list[np.ndarray]]:
    """The demo model's kernel Functions and real node arguments, one node per row.

    Rows: every node of a forward sweep along the demo's optimal trajectory (both vehicles)
    with the point's ``u``, ``p``, ``w``; ``λ`` random on the states' scale; ``ν = 1``. The
    row count is rounded down to a multiple of LANES.
    """
    with tempfile.TemporaryDirectory() as scratch:
        assembled, options, _ = build_case("demo", Path(scratch))
    problem = assembled.problem
    cache = ModelCache()
    discrete = cache.get(problem, StageBackend(stage_kernels=True, n_threads=1)).discrete
    options = ProntoOptions(**{**options.__dict__, "stage_kernels": True, "n_threads": 1})
    optimum = solve_pronto(problem, assembled.guess, options=options, cache=cache).trajectory
    group = discrete.groups[0]
    block = group.blocks[0]
    functions, _ = _symbolic_kernels(block.dynamics, block.running_cost)
    x, u, p, w = discrete._points(group, optimum.states[:-1], optimum.inputs, problem.parameters)
    forward = group.kernels._forward(x, u, p, w, discrete.h, discrete.n_substeps)

    def by_node(stored: np.ndarray) -> np.ndarray:  # (node, group, entry, lane) -> rows
        nodes = np.moveaxis(stored, 3, 2).reshape(stored.shape[0], -1, stored.shape[2])
        return nodes[:, : x.shape[0]].reshape(-1, stored.shape[2])

    y, d = by_node(forward.points), by_node(forward.carried)
    rows = y.shape[0] // LANES * LANES
    n_nodes = forward.points.shape[0]
    # the point's u, p, w at each of its nodes (node-major, as the sweep stores them)
    u, p, w = (np.tile(a, (n_nodes, 1))[:rows] for a in (u, p, w))
    rng = np.random.default_rng(27)
    lam = rng.normal(scale=float(np.std(y)), size=y[:rows].shape)
    nu = np.ones((rows, 1))
    return functions, [y[:rows], u, p, w, d[:rows], lam, nu]


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=30, help="timed runs (best reported)")
    args = parser.parse_args(argv)
    functions, (y, u, p, w, d, lam, nu) = node_arguments()
    inputs = {
        "value": [y, u, p, w],
        "first": [y, u, p, w, d],
        "hessian": [y, u, p, w, lam, nu, d],
    }
    points = y.shape[0]
    print(f"{points} node evaluations per kernel, {LANES} lanes\n")
    print("| kernel | SX instructions | scalar µs/point | lanes µs/point | speed-up "
          "| equal to the bit |")  # fmt: skip
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as scratch:
        for name, function in functions.items():
            outputs = [np.empty((points, function.numel_out(i))) for i in range(function.n_out())]
            rows = [np.ascontiguousarray(a) for a in inputs[name]] + outputs
            groups = [_grouped(a) for a in rows]
            scalar = _kernel_loop(function, False, Path(scratch))
            lanes = _kernel_loop(function, True, Path(scratch))
            scalar_us = _best_us(scalar, rows, points, args.repeat)
            lanes_us = _best_us(lanes, groups, points, args.repeat)
            equal = all(
                np.array_equal(_grouped(out), grouped, equal_nan=True)
                for out, grouped in zip(outputs, groups[function.n_in() :], strict=True)
            )
            print(
                f"| {name} | {function.n_instructions()} | {scalar_us:.3f} | {lanes_us:.3f} "
                f"| {scalar_us / lanes_us:.2f}× | {'yes' if equal else 'NO'} |"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
