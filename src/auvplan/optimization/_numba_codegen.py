"""CasADi SX Functions translated to numba source code (straight-line scalar kernels).

An SX Function is a sequence of scalar instructions on a work vector
(``casadi.Function.instruction_id/input/output/constant``). :func:`numba_source` writes each
instruction as one Python assignment, so the Function becomes a plain function
``name(i0, i1, …, o0, o1, …)`` on 1-D float64 arrays (inputs read, dense outputs written), and
adds ``name_batch`` which applies it to every row of 2-D arrays. numba compiles the result to
machine code through LLVM: the stage derivatives of the vehicle models then evaluate 10–25
times faster than in CasADi's virtual machine, without a C compiler. A kernel can instead be
written as its instruction list (:func:`lane_program`) for a lane kernel that evaluates four
points per instruction (:mod:`~auvplan.optimization._lane_codegen`).

Only the scalar operations that smooth models use are translated; any other operation raises
:class:`UnsupportedOperation`, and the caller keeps the CasADi evaluation.
"""

from __future__ import annotations

import math
from typing import Final

import casadi as ca

__all__ = ["UnsupportedOperation", "lane_program", "numba_source", "scalar_expression"]

#: Version of the generated code; part of every cache key (bump on any change of the output).
GENERATOR_VERSION: Final = 11

_BINARY: Final = {ca.OP_ADD: "+", ca.OP_SUB: "-", ca.OP_MUL: "*", ca.OP_DIV: "/"}
_UNARY: Final = {
    ca.OP_SQRT: "math.sqrt", ca.OP_SIN: "math.sin", ca.OP_COS: "math.cos",
    ca.OP_TAN: "math.tan", ca.OP_EXP: "math.exp", ca.OP_LOG: "math.log",
    ca.OP_ASIN: "math.asin", ca.OP_ACOS: "math.acos", ca.OP_ATAN: "math.atan",
    ca.OP_SINH: "math.sinh", ca.OP_COSH: "math.cosh", ca.OP_TANH: "math.tanh",
    ca.OP_ASINH: "math.asinh", ca.OP_ACOSH: "math.acosh", ca.OP_ATANH: "math.atanh",
    ca.OP_ERF: "math.erf", ca.OP_FABS: "abs", ca.OP_FLOOR: "np.floor",
    ca.OP_CEIL: "np.ceil",
}  # fmt: skip
_TEMPLATES: Final = {
    ca.OP_ASSIGN: "{0}",
    ca.OP_NEG: "-{0}",
    ca.OP_SQ: "{0} * {0}",
    ca.OP_TWICE: "2.0 * {0}",
    ca.OP_INV: "1.0 / {0}",
    ca.OP_POW: "{0} ** {1}",
    ca.OP_CONSTPOW: "{0} ** {1}",
    ca.OP_ATAN2: "math.atan2({0}, {1})",
    ca.OP_FMIN: "min({0}, {1})",
    ca.OP_FMAX: "max({0}, {1})",
    ca.OP_COPYSIGN: "math.copysign({0}, {1})",
    ca.OP_FMOD: "np.fmod({0}, {1})",
    ca.OP_SIGN: "(1.0 if {0} > 0.0 else (-1.0 if {0} < 0.0 else 0.0))",
    ca.OP_LT: "(1.0 if {0} < {1} else 0.0)",
    ca.OP_LE: "(1.0 if {0} <= {1} else 0.0)",
    ca.OP_EQ: "(1.0 if {0} == {1} else 0.0)",
    ca.OP_NE: "(1.0 if {0} != {1} else 0.0)",
    ca.OP_NOT: "(1.0 if {0} == 0.0 else 0.0)",
    ca.OP_AND: "(1.0 if {0} != 0.0 and {1} != 0.0 else 0.0)",
    ca.OP_OR: "(1.0 if {0} != 0.0 or {1} != 0.0 else 0.0)",
    ca.OP_IF_ELSE_ZERO: "({1} if {0} != 0.0 else 0.0)",
}


class UnsupportedOperation(ValueError):
    """An SX instruction that :func:`numba_source` cannot translate."""


def scalar_expression(op: int, args: list[str]) -> str:
    """Python source of CasADi operation ``op`` on the operands named ``args``.

    Raises
    ------
    UnsupportedOperation
        If ``op`` is not translated.
    """
    if op in _BINARY:
        return f"{args[0]} {_BINARY[op]} {args[1]}"
    if op in _UNARY:
        return f"{_UNARY[op]}({args[0]})"
    if op in _TEMPLATES:
        return _TEMPLATES[op].format(*args)
    raise UnsupportedOperation(f"CasADi operation {op} is not translated")


def _expression(function: ca.Function, k: int) -> str:
    args = [f"w{j}" for j in function.instruction_input(k)]
    try:
        return scalar_expression(function.instruction_id(k), args)
    except UnsupportedOperation as error:
        raise UnsupportedOperation(f"{function.name()}: {error}") from None


def _literal(value: float) -> str:
    """``value`` as Python source (``math.inf``/``math.nan`` for the non-finite ones)."""
    if math.isnan(value):
        return "math.nan"
    if math.isinf(value):
        return "math.inf" if value > 0 else "-math.inf"
    return repr(value)


def _kernel_lines(function: ca.Function) -> list[str]:
    """The body of ``function`` as one assignment per SX instruction."""
    lines = []
    for k in range(function.n_instructions()):
        op = function.instruction_id(k)
        out = function.instruction_output(k)
        if op == ca.OP_INPUT:
            source, entry = function.instruction_input(k)
            lines.append(f"    w{out[0]} = i{source}[{entry}]")
        elif op == ca.OP_OUTPUT:
            lines.append(f"    o{out[0]}[{out[1]}] = w{function.instruction_input(k)[0]}")
        elif op == ca.OP_CONST:
            lines.append(f"    w{out[0]} = {_literal(float(function.instruction_constant(k)))}")
        else:
            lines.append(f"    w{out[0]} = {_expression(function, k)}")
    return lines


def lane_program(function: ca.Function) -> list[str]:
    """The instructions of ``function`` as tuple literals (lines of the generated source).

    The program of :func:`~auvplan.optimization._lane_codegen.lane_typing`.

    Raises
    ------
    UnsupportedOperation
        If an instruction's operation is not translated.
    """
    lines = []
    for k in range(function.n_instructions()):
        op = function.instruction_id(k)
        out = function.instruction_output(k)
        fields: list[object]
        if op == ca.OP_INPUT:
            fields = [out[0], *function.instruction_input(k)]
        elif op == ca.OP_OUTPUT:
            fields = [*out, function.instruction_input(k)[0]]
        elif op == ca.OP_CONST:
            fields = [out[0], _literal(float(function.instruction_constant(k)))]
        else:
            operands = function.instruction_input(k)
            scalar_expression(op, ["x"] * len(operands))  # refuses what is not translated
            fields = [out[0], *operands]
        lines.append(f"    ({op}, {', '.join(str(f) for f in fields)}),")
    return lines


def numba_source(
    functions: dict[str, ca.Function],
    header: str,
    appendix: str = "",
    batched: tuple[str, ...] | None = None,
    lanes: tuple[str, ...] = (),
) -> str:
    """Python source of a module with one numba kernel (and its batch loop) per Function.

    Parameters
    ----------
    functions : dict of str to casadi.Function
        SX Functions with dense outputs, by kernel name (a Python identifier).
    header : str
        First-line comment of the module (what it was generated from).
    appendix : str, optional
        Source appended verbatim (functions calling the kernels; ``numpy`` is imported as
        ``np``).
    batched : tuple of str, optional
        The kernels that get a ``name_batch`` loop (all when not given; the others are
        called from ``appendix`` only).
    lanes : tuple of str, optional
        The kernels written as ``name_lanes`` instead, evaluating
        :data:`~auvplan.optimization._lane_codegen.LANES` points at once on arrays of shape
        ``(n_entries, LANES)`` (:func:`~auvplan.optimization._lane_codegen.lane_typing`;
        from numba code only, never batched).

    Returns
    -------
    str
        Module source: ``name(i0, …, o0, …)`` on 1-D arrays and, for the ``batched`` ones,
        ``name_batch`` on 2-D arrays (one point per row), all
        ``numba.njit(cache=True, nogil=True)`` (they run on worker threads side by side), and
        the ``name_lanes`` kernels.

    Raises
    ------
    UnsupportedOperation
        If a Function is not an SX Function or uses an operation that is not translated.
    """
    lines = [f"# {header}", f"# auvplan numba generator version {GENERATOR_VERSION}", ""]
    lines += ["import math", "", "import numba", "import numpy as np", ""]
    if lanes:
        lines += ["from numba.extending import intrinsic", ""]
        lines += ["from auvplan.optimization._lane_codegen import LANES, lane_typing", ""]
    for name, function in functions.items():
        if not function.is_a("SXFunction"):
            raise UnsupportedOperation(f"{function.name()} is not an SX Function")
        for i in range(function.n_out()):
            if function.nnz_out(i) != function.numel_out(i):
                raise UnsupportedOperation(f"{function.name()} output {i} is not dense")
        inputs = [f"i{i}" for i in range(function.n_in())]
        outputs = [f"o{i}" for i in range(function.n_out())]
        if name in lanes:
            lines += [
                "",
                f"_{name}_program = (",
                *lane_program(function),
                ")",
                "",
                "",
                "@intrinsic",
                f"def {name}_lanes(typingctx, {', '.join(inputs + outputs)}):",
                (
                    f"    return lane_typing({function.name()!r}, {function.n_in()}, "
                    f"_{name}_program, ({', '.join(inputs + outputs)},))"
                ),
                "",
            ]
            continue
        rows = [f"{arg}[b]" for arg in inputs + outputs]
        lines += [
            "",
            "@numba.njit(cache=True, error_model='numpy', nogil=True)",
            f"def {name}({', '.join(inputs + outputs)}):",
            *_kernel_lines(function),
            "",
        ]
        if batched is None or name in batched:
            lines += [
                "",
                "@numba.njit(cache=True, error_model='numpy', nogil=True)",
                f"def {name}_batch({', '.join(inputs + outputs)}):",
                "    for b in range(i0.shape[0]):",
                f"        {name}({', '.join(rows)})",
                "",
            ]
    return "\n".join([*lines, appendix])
