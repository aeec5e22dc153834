"""The stage-3 node kernels point by point (numba, as shipped) vs several points per vector op.

Issue 27 asks stage 3 to run ≥ 10× faster than CasADi+FATROP's C-compiled solve; the
sweeps that evaluate the vehicle model's node kernels (``value``, ``first``, ``hessian``,
:mod:`auvplan.optimization.block_kernels`) are about half of a solve, in scalar code:
LLVM does not vectorise numba's loop over points around a body of thousands of
instructions (nor does numba enable its SLP vectoriser). This benchmark measures what
evaluating ``W`` points per instruction would give, before anything is built on it:

- the node kernels of the demo's MEDUSA model, each SX instruction of the same CasADi
  Functions written as one LLVM instruction on ``<W x double>`` (``W`` = 4, 8), compiled
  by llvmlite (numba's own LLVM) for this machine's CPU;
- evaluated on the node arguments of a real forward sweep along the demo's optimum
  (states, inputs, parameters, weights, node derivatives ``D``; a costate of the sweep's
  scale), against the shipped numba kernels on the same arguments.

Reported per kernel: instructions, microseconds per point (best of ``--repeat``), the
speed-up, whether every output is equal **to the bit** (the same IEEE operations in the
same order, lane by lane; ``sin``/``cos``/``tanh`` are the C library's per lane) and the
LLVM compile time. Run::

    .venv/bin/python benchmarks/bench_lane_kernels.py [--repeat 30]
"""

from __future__ import annotations

import argparse
import ctypes
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import casadi as ca
import llvmlite.binding as llvm
import numba
import numpy as np

from _fleet import build_case
from auvplan.optimization import ModelCache, ProntoOptions, StageBackend, solve_pronto
from auvplan.optimization.block_kernels import _symbolic_kernels

#: SX operations written as one LLVM instruction on two vector operands.
_BINARY = {ca.OP_ADD: "fadd", ca.OP_SUB: "fsub", ca.OP_MUL: "fmul", ca.OP_DIV: "fdiv"}
#: SX operations with an LLVM vector intrinsic (lowered per lane to the C library's
#: function where the CPU has no instruction for it).
_INTRINSIC = {ca.OP_SQRT: "sqrt", ca.OP_SIN: "sin", ca.OP_COS: "cos", ca.OP_EXP: "exp",
              ca.OP_LOG: "log", ca.OP_FABS: "fabs"}  # fmt: skip
#: SX operations without one: the C library's scalar function, lane by lane.
_LIBM = {ca.OP_TANH: "tanh", ca.OP_TAN: "tan", ca.OP_ATAN: "atan", ca.OP_ASIN: "asin",
         ca.OP_ACOS: "acos", ca.OP_SINH: "sinh", ca.OP_COSH: "cosh", ca.OP_ERF: "erf"}  # fmt: skip


class _Emitter:
    """LLVM IR of one SX Function on ``W`` lanes: ``void name(double* i…, double* o…, i64
    stride…)``, argument ``k``'s lane ``l`` at ``pointer_k + l · stride_k`` (rows of points)."""

    def __init__(self, function: ca.Function, lanes: int) -> None:
        self.function, self.lanes = function, lanes
        self.vector = f"<{lanes} x double>"
        self.lines: list[str] = []
        self.declarations: set[str] = set()
        self.values: dict[int, str] = {}  # work-vector slot -> current SSA value
        self.count = 0

    def _new(self) -> str:
        self.count += 1
        return f"%t{self.count}"

    def _splat(self, value: float) -> str:
        scalar = f"0x{np.float64(value).view(np.uint64):016X}"  # exact, inf and nan included
        return "<" + ", ".join(f"double {scalar}" for _ in range(self.lanes)) + ">"

    def _lane_pointer(self, argument: int, lane: int, entry: int) -> str:
        row, offset, pointer = self._new(), self._new(), self._new()
        self.lines.append(f"{row} = mul i64 {lane}, %s{argument}")
        self.lines.append(f"{offset} = add i64 {row}, {entry}")
        self.lines.append(f"{pointer} = getelementptr double, double* %p{argument}, i64 {offset}")
        return pointer

    def _per_lane(self, name: str, operand: str) -> str:
        self.declarations.add(f"declare double @{name}(double)")
        vector = "undef"
        for lane in range(self.lanes):
            scalar, result, merged = self._new(), self._new(), self._new()
            self.lines.append(f"{scalar} = extractelement {self.vector} {operand}, i32 {lane}")
            self.lines.append(f"{result} = call double @{name}(double {scalar})")
            self.lines.append(
                f"{merged} = insertelement {self.vector} {vector}, double {result}, i32 {lane}"
            )
            vector = merged
        return vector

    def _instruction(self, k: int) -> None:
        f, vector = self.function, self.vector
        op, out = f.instruction_id(k), f.instruction_output(k)
        if op == ca.OP_INPUT:
            source, entry = f.instruction_input(k)
            value = "undef"
            for lane in range(self.lanes):
                pointer = self._lane_pointer(source, lane, entry)
                scalar, merged = self._new(), self._new()
                self.lines.append(f"{scalar} = load double, double* {pointer}")
                self.lines.append(
                    f"{merged} = insertelement {vector} {value}, double {scalar}, i32 {lane}"
                )
                value = merged
            self.values[out[0]] = value
            return
        if op == ca.OP_OUTPUT:
            argument = f.n_in() + out[0]
            for lane in range(self.lanes):
                pointer, scalar = self._lane_pointer(argument, lane, out[1]), self._new()
                operand = self.values[f.instruction_input(k)[0]]
                self.lines.append(f"{scalar} = extractelement {vector} {operand}, i32 {lane}")
                self.lines.append(f"store double {scalar}, double* {pointer}")
            return
        if op == ca.OP_CONST:
            self.values[out[0]] = self._splat(float(f.instruction_constant(k)))
            return
        args = [self.values[j] for j in f.instruction_input(k)]
        result = self._new()
        if op in _BINARY:
            self.lines.append(f"{result} = {_BINARY[op]} {vector} {args[0]}, {args[1]}")
        elif op == ca.OP_ASSIGN:
            result = args[0]
        elif op == ca.OP_NEG:
            self.lines.append(f"{result} = fneg {vector} {args[0]}")
        elif op == ca.OP_SQ:
            self.lines.append(f"{result} = fmul {vector} {args[0]}, {args[0]}")
        elif op == ca.OP_TWICE:
            self.lines.append(f"{result} = fmul {vector} {self._splat(2.0)}, {args[0]}")
        elif op == ca.OP_INV:
            self.lines.append(f"{result} = fdiv {vector} {self._splat(1.0)}, {args[0]}")
        elif op in _INTRINSIC:
            name = f"llvm.{_INTRINSIC[op]}.v{self.lanes}f64"
            self.declarations.add(f"declare {vector} @{name}({vector})")
            self.lines.append(f"{result} = call {vector} @{name}({vector} {args[0]})")
        elif op in _LIBM:
            result = self._per_lane(_LIBM[op], args[0])
        else:
            raise ValueError(f"{f.name()}: operation {op} is not in this benchmark's emitter")
        self.values[out[0]] = result

    def module(self, name: str) -> str:
        """The LLVM IR module text of the kernel."""
        for k in range(self.function.n_instructions()):
            self._instruction(k)
        n_args = self.function.n_in() + self.function.n_out()
        parameters = ", ".join(
            [f"double* noalias %p{k}" for k in range(n_args)]
            + [f"i64 %s{k}" for k in range(n_args)]
        )
        body = "\n  ".join(self.lines)
        return (
            "\n".join(sorted(self.declarations))
            + f"\ndefine void @{name}({parameters}) {{\nentry:\n  {body}\n  ret void\n}}\n"
        )


def compile_lanes(function: ca.Function, lanes: int) -> tuple[Callable[..., None], float, Any]:
    """The ``lanes``-wide kernel as a ctypes function, its compile time [s] and its engine."""
    started = time.perf_counter()
    module = llvm.parse_assembly(_Emitter(function, lanes).module("kernel"))
    module.verify()
    machine = llvm.Target.from_default_triple().create_target_machine(
        cpu=llvm.get_host_cpu_name(), features=llvm.get_host_cpu_features().flatten(), opt=3
    )
    builder = llvm.create_pass_builder(machine, llvm.create_pipeline_tuning_options(speed_level=3))
    builder.getModulePassManager().run(module, builder)
    engine = llvm.create_mcjit_compiler(module, machine)
    engine.finalize_object()
    n_args = function.n_in() + function.n_out()
    prototype = ctypes.CFUNCTYPE(None, *([ctypes.c_void_p] * n_args + [ctypes.c_int64] * n_args))
    kernel = prototype(engine.get_function_address("kernel"))
    return kernel, time.perf_counter() - started, engine


def _row_loop(kernel: Any, n_args: int, rows: int) -> Any:
    """A numba loop over the rows of 2-D arrays calling ``kernel`` on ``rows`` rows at a time.

    ``rows == 0``: a numba kernel called on each row as 1-D arrays; otherwise a lane kernel
    (:func:`compile_lanes`) called with each argument's address and row stride.
    """
    names = [f"a{k}" for k in range(n_args)]
    if rows == 0:
        step, call = 1, f"kernel({', '.join(f'{a}[b]' for a in names)})"
    else:
        pointers = ", ".join(f"{a}[b:].ctypes.data" for a in names)
        strides = ", ".join(f"{a}.shape[1]" for a in names)
        step, call = rows, f"kernel({pointers}, {strides})"
    source = f"""
@numba.njit
def loop({", ".join(names)}):
    for b in range(0, a0.shape[0], {step}):
        {call}
"""
    scope = {"numba": numba, "kernel": kernel}
    exec(compile(source, "bench_lane_kernels", "exec"), scope)  # noqa: S102 - generated loop
    return scope["loop"]


def _best_us(loop: Callable[..., None], arrays: list[np.ndarray], repeat: int) -> float:
    """Best of ``repeat`` runs of ``loop(*arrays)`` (after one untimed), in µs per row."""
    loop(*arrays)
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        loop(*arrays)
        times.append(time.perf_counter() - started)
    return min(times) / arrays[0].shape[0] * 1e6


def node_arguments(multiple: int = 8) -> tuple[dict[str, ca.Function], Any, list[np.ndarray]]:
    """The demo model's kernel Functions, its numba module and real node arguments.

    Rows: every node of a forward sweep along the demo's optimal trajectory (both vehicles), in
    the sweep's own arrays (``y``, ``D``) with the point's ``u``, ``p``, ``w``; ``λ`` random on the
    states' scale; ``ν = 1``. The row count is rounded down to a multiple of ``multiple``.
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
    functions = _symbolic_kernels(block.dynamics, block.running_cost)
    x, u, p, w = discrete._points(group, optimum.states[:-1], optimum.inputs, problem.parameters)
    forward = group.kernels._forward(x, u, p, w, discrete.h, discrete.n_substeps)
    n_nodes = forward.points.shape[0]
    rows = (n_nodes * x.shape[0]) // multiple * multiple
    y = forward.points.reshape(-1, forward.points.shape[2])[:rows]
    d = forward.carried.reshape(-1, forward.carried.shape[2])[:rows]
    # the point's u, p, w at each of its nodes (node-major, as the sweep stores them)
    u, p, w = (np.tile(a, (n_nodes, 1))[:rows] for a in (u, p, w))
    rng = np.random.default_rng(27)
    lam = rng.normal(scale=float(np.std(y)), size=y.shape)
    nu = np.ones((rows, 1))
    return functions, group.kernels.module, [y, u, p, w, d, lam, nu]


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=30, help="timed runs (best reported)")
    args = parser.parse_args(argv)
    llvm.initialize_native_target()
    llvm.initialize_native_asmprinter()
    functions, module, (y, u, p, w, d, lam, nu) = node_arguments()
    inputs = {
        "value": [y, u, p, w],
        "first": [y, u, p, w, d],
        "hessian": [y, u, p, w, lam, nu, d],
    }
    print(f"CPU {llvm.get_host_cpu_name()}; {y.shape[0]} node evaluations per kernel\n")
    print("| kernel | SX instructions | numba µs/point | lanes | µs/point | speed-up "
          "| equal to the bit | LLVM compile s |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    for name, function in functions.items():
        outputs = [np.empty((y.shape[0], function.numel_out(i))) for i in range(function.n_out())]
        arguments = [np.ascontiguousarray(a) for a in inputs[name]] + outputs
        reference = [o.copy() for o in outputs]
        shipped = _row_loop(getattr(module, name), len(arguments), 0)
        scalar_us = _best_us(shipped, arguments[: function.n_in()] + reference, args.repeat)
        for lanes in (4, 8):
            kernel, compile_s, _engine = compile_lanes(function, lanes)  # engine kept alive
            by_lanes = _row_loop(kernel, len(arguments), lanes)
            lanes_us = _best_us(by_lanes, arguments, args.repeat)
            equal = all(
                np.array_equal(a, b, equal_nan=True)
                for a, b in zip(outputs, reference, strict=True)
            )
            print(
                f"| {name} | {function.n_instructions()} | {scalar_us:.3f} | {lanes} | "
                f"{lanes_us:.3f} | {scalar_us / lanes_us:.2f}× | {'yes' if equal else 'NO'} "
                f"| {compile_s:.2f} |"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
