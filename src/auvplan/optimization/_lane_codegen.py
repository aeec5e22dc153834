"""CasADi SX instruction lists as numba intrinsics that evaluate :data:`LANES` points at once.

numba compiles the straight-line kernels of :mod:`~auvplan.optimization._numba_codegen` to
scalar code: LLVM does not vectorise a loop over points around a body of thousands of
instructions. The kernels of :func:`lane_typing` instead write every SX instruction as one LLVM
instruction on ``<LANES x double>`` — one value per point — inside the numba function that
calls it (a numba *intrinsic*, so numba's cache keeps its machine code like any other).
Arithmetic (``+ − × ÷``, negation, square, doubling, inverse, square root, absolute value) is a
vector instruction; every other operation is numba's own lowering of the scalar kernel's
expression (:func:`~auvplan.optimization._numba_codegen.scalar_expression`), lane by lane. Each
lane therefore runs the IEEE operations of the scalar kernel in the same order: the results are
those of the scalar kernel, to the bit.

The kernel's arguments are 2-D C-contiguous float64 arrays of ``LANES`` columns, one per
point: entry ``e`` of an input or output is row ``e`` (``(n_entries, LANES)``).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from typing import Any, Final

import casadi as ca
import numpy as np
from llvmlite import ir
from numba.core import cgutils, compiler, types

from auvplan.optimization._numba_codegen import scalar_expression

__all__ = ["LANES", "VECTOR", "lane_typing", "splat", "vector_intrinsic", "vector_pointer"]

#: Points per evaluation (four doubles: one AVX2 register).
LANES: Final = 4

#: ``<LANES x double>``, one value per point.
VECTOR: Final = ir.VectorType(ir.DoubleType(), LANES)
_ARITHMETIC: Final[dict[int, Callable[..., Any]]] = {
    ca.OP_ADD: lambda b, x, y: b.fadd(x, y),
    ca.OP_SUB: lambda b, x, y: b.fsub(x, y),
    ca.OP_MUL: lambda b, x, y: b.fmul(x, y),
    ca.OP_DIV: lambda b, x, y: b.fdiv(x, y),
    ca.OP_NEG: lambda b, x: b.fneg(x),
    ca.OP_SQ: lambda b, x: b.fmul(x, x),
    ca.OP_TWICE: lambda b, x: b.fmul(splat(2.0), x),
    ca.OP_INV: lambda b, x: b.fdiv(splat(1.0), x),
}
#: Operations that are one LLVM vector intrinsic with the scalar code's exact result: IEEE 754
#: rounds a square root correctly (the scalar ``math.sqrt`` is the C library's), ``abs`` is
#: ``llvm.fabs`` in both.
_EXACT_INTRINSICS: Final = {ca.OP_SQRT: "llvm.sqrt", ca.OP_FABS: "llvm.fabs"}


def splat(value: float) -> ir.Constant:
    """``value`` in every lane."""
    return ir.Constant(VECTOR, [value] * LANES)


def vector_intrinsic(builder: ir.IRBuilder, name: str, *operands: Any) -> Any:
    """The LLVM intrinsic ``name`` (e.g. ``llvm.sqrt``) on :data:`VECTOR` operands."""
    kind = ir.FunctionType(VECTOR, [VECTOR] * len(operands))
    function = cgutils.get_or_insert_function(  # type: ignore[no-untyped-call]
        builder.module, kind, f"{name}.v{LANES}f64"
    )
    return builder.call(function, operands)


def vector_pointer(context: Any, builder: ir.IRBuilder, kind: Any, array: Any) -> Any:
    """The data of a float64 array (numba type ``kind``, value ``array``) as ``VECTOR*``."""
    data = context.make_array(kind)(context, builder, array).data
    return builder.bitcast(data, VECTOR.as_pointer())


@functools.cache
def _scalar_function(op: int, arity: int) -> Callable[..., float]:
    """The scalar kernel's expression of ``op`` as a Python function (numba compiles it)."""
    names = ["a", "b"][:arity]
    source = f"lambda {', '.join(names)}: {scalar_expression(op, names)}"
    function: Callable[..., float] = eval(source, {"math": math, "np": np})
    return function


def _per_lane(context: Any, builder: ir.IRBuilder, op: int, operands: list[Any]) -> Any:
    """``op`` on each lane through numba's lowering of the scalar expression (numpy errors)."""
    signature = types.float64(*([types.float64] * len(operands)))
    flags = compiler.Flags()  # type: ignore[no-untyped-call]
    flags.error_model = "numpy"  # type: ignore[misc,assignment]
    compiled = context.compile_subroutine(
        builder, _scalar_function(op, len(operands)), signature, flags=flags
    )
    vector = ir.Constant(VECTOR, None)
    for lane in range(LANES):
        scalars = [builder.extract_element(x, ir.Constant(ir.IntType(32), lane)) for x in operands]
        value = context.call_internal(builder, compiled.fndesc, signature, scalars)
        vector = builder.insert_element(vector, value, ir.Constant(ir.IntType(32), lane))
    return vector


def lane_typing(
    name: str, n_in: int, program: tuple[tuple[float, ...], ...], arrays: tuple[Any, ...]
) -> tuple[Any, Callable[..., Any]]:
    """Signature and code of a numba intrinsic ``kernel(i0, …, o0, …)`` that runs ``program``.

    The generated modules define each lane kernel as ``@intrinsic def name_lanes(typingctx,
    i0, …, o0, …): return lane_typing(…)``.

    Parameters
    ----------
    name : str
        The Function's name (for error messages).
    n_in : int
        Its number of inputs (the arguments after them are its outputs).
    program : tuple of tuple
        Its instructions in order: ``(OP_INPUT, slot, input, entry)``,
        ``(OP_OUTPUT, output, entry, slot)``, ``(OP_CONST, slot, value)`` and
        ``(op, slot, operand_slot, …)`` (:func:`~auvplan.optimization._numba_codegen.lane_program`).
    arrays : tuple of numba types
        The argument types: C-contiguous float64 arrays of shape ``(n_entries, LANES)``.

    Raises
    ------
    TypeError
        If an argument is not such an array (when a caller is compiled).
    """
    if not all(
        isinstance(a, types.Array) and a.dtype == types.float64 and a.layout == "C" for a in arrays
    ):
        raise TypeError(f"{name}: lane kernels take C-contiguous float64 arrays")

    def codegen(context: Any, builder: ir.IRBuilder, signature: Any, args: Any) -> Any:
        pointers = [
            vector_pointer(context, builder, kind, value)
            for kind, value in zip(signature.args, args, strict=True)
        ]
        slots: dict[int, Any] = {}
        for instruction in program:
            op, slot = int(instruction[0]), int(instruction[1])
            if op == ca.OP_INPUT:
                row = ir.Constant(ir.IntType(64), int(instruction[3]))
                slots[slot] = builder.load(
                    builder.gep(pointers[int(instruction[2])], [row]), align=8
                )
            elif op == ca.OP_OUTPUT:
                row = ir.Constant(ir.IntType(64), int(instruction[2]))
                address = builder.gep(pointers[n_in + slot], [row])
                builder.store(slots[int(instruction[3])], address, align=8)
            elif op == ca.OP_CONST:
                slots[slot] = splat(float(instruction[2]))
            else:
                operands = [slots[int(j)] for j in instruction[2:]]
                if op in _ARITHMETIC:
                    slots[slot] = _ARITHMETIC[op](builder, *operands)
                elif op in _EXACT_INTRINSICS:
                    slots[slot] = vector_intrinsic(builder, _EXACT_INTRINSICS[op], *operands)
                else:
                    slots[slot] = _per_lane(context, builder, op, operands)
        return context.get_dummy_value()

    return types.void(*arrays), codegen
