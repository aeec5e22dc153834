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
from dataclasses import dataclass
from typing import Final

import casadi as ca

__all__ = [
    "Instruction",
    "UnsupportedOperation",
    "instructions",
    "lane_program",
    "numba_source",
    "scalar_expression",
    "split_stage",
]

#: Version of the generated code; part of every cache key (bump on any change of the output).
GENERATOR_VERSION: Final = 12

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


@dataclass(frozen=True)
class Instruction:
    """One SX instruction of a kernel program.

    ``OP_INPUT``: ``out = (slot,)``, ``operands = (input, entry)``; ``OP_OUTPUT``:
    ``out = (output, entry)``, ``operands = (slot,)``; ``OP_CONST``: ``out = (slot,)`` and
    ``constant``; any other operation: ``out = (slot,)`` and its operand slots.
    """

    op: int
    out: tuple[int, ...]
    operands: tuple[int, ...]
    constant: float = 0.0


def instructions(function: ca.Function) -> list[Instruction]:
    """The program of an SX Function, in order.

    Raises
    ------
    UnsupportedOperation
        If an instruction's operation is not translated.
    """
    program = []
    for k in range(function.n_instructions()):
        op = function.instruction_id(k)
        operands = tuple(int(j) for j in function.instruction_input(k))
        constant = float(function.instruction_constant(k)) if op == ca.OP_CONST else 0.0
        if op not in (ca.OP_INPUT, ca.OP_OUTPUT, ca.OP_CONST):
            try:
                scalar_expression(op, ["x"] * len(operands))
            except UnsupportedOperation as error:
                raise UnsupportedOperation(f"{function.name()}: {error}") from None
        out = tuple(int(j) for j in function.instruction_output(k))
        program.append(Instruction(op, out, operands, constant))
    return program


def split_stage(
    program: list[Instruction], stage_inputs: tuple[int, ...], n_in: int
) -> tuple[list[Instruction], list[Instruction], int]:
    """Hoist what depends on ``stage_inputs`` alone out of ``program``: ``(stage, body, n_s)``.

    An RK4 step evaluates a kernel at its nodes with the same input, parameters and weights
    (e.g. ``tanh`` of every input, a smooth actuator limit): the operations on those alone
    are the same at every node. ``stage`` computes them once and writes the ``n_s`` of them
    the rest reads into its only output; ``body`` reads these from a new last input
    (number ``n_in``) where ``program`` computed them and drops the other hoisted
    operations. Inputs and literals stay where they are (loads). Every value is computed by
    the same operations on the same operands: ``body`` after ``stage`` gives ``program``'s
    results to the bit.
    """
    hoisted: list[bool] = []  # per instruction: an operation on stage inputs alone
    staged: dict[int, bool] = {}  # per slot: its current value depends on stage inputs alone
    writer: dict[int, int] = {}  # per slot: the instruction that wrote its current value
    read_by_body: set[int] = set()  # hoisted instructions whose value the body reads
    for k, instruction in enumerate(program):
        op = instruction.op
        is_hoisted = False
        if op == ca.OP_INPUT:
            staged[instruction.out[0]] = instruction.operands[0] in stage_inputs
        elif op == ca.OP_CONST:
            staged[instruction.out[0]] = True
        elif op == ca.OP_OUTPUT:
            if hoisted[writer[instruction.operands[0]]]:
                read_by_body.add(writer[instruction.operands[0]])
        else:
            is_hoisted = all(staged[j] for j in instruction.operands)
            if not is_hoisted:
                read_by_body.update(writer[j] for j in instruction.operands if hoisted[writer[j]])
            staged[instruction.out[0]] = is_hoisted
        hoisted.append(is_hoisted)
        if op != ca.OP_OUTPUT:
            writer[instruction.out[0]] = k
    stage: list[Instruction] = []
    body: list[Instruction] = []
    entries: dict[int, int] = {}  # hoisted instruction read by the body → its entry
    for k, instruction in enumerate(program):
        op = instruction.op
        is_stage_input = op == ca.OP_INPUT and instruction.operands[0] in stage_inputs
        if hoisted[k] or is_stage_input or op == ca.OP_CONST:
            stage.append(instruction)
        if not hoisted[k]:
            body.append(instruction)
        elif k in read_by_body:
            entries[k] = len(entries)
            slot = instruction.out[0]
            stage.append(Instruction(ca.OP_OUTPUT, (0, entries[k]), (slot,)))
            body.append(Instruction(ca.OP_INPUT, (slot,), (n_in, entries[k])))
    return stage, body, len(entries)


def _literal(value: float) -> str:
    """``value`` as Python source (``math.inf``/``math.nan`` for the non-finite ones)."""
    if math.isnan(value):
        return "math.nan"
    if math.isinf(value):
        return "math.inf" if value > 0 else "-math.inf"
    return repr(value)


def _kernel_lines(program: list[Instruction]) -> list[str]:
    """The body of a scalar kernel: one assignment per instruction."""
    lines = []
    for instruction in program:
        op, out, operands = instruction.op, instruction.out, instruction.operands
        if op == ca.OP_INPUT:
            lines.append(f"    w{out[0]} = i{operands[0]}[{operands[1]}]")
        elif op == ca.OP_OUTPUT:
            lines.append(f"    o{out[0]}[{out[1]}] = w{operands[0]}")
        elif op == ca.OP_CONST:
            lines.append(f"    w{out[0]} = {_literal(instruction.constant)}")
        else:
            lines.append(f"    w{out[0]} = {scalar_expression(op, [f'w{j}' for j in operands])}")
    return lines


def lane_program(program: list[Instruction]) -> list[str]:
    """A program as tuple literals (lines of the generated source).

    The program of :func:`~auvplan.optimization._lane_codegen.lane_typing`.
    """
    lines = []
    for instruction in program:
        op, out, operands = instruction.op, instruction.out, instruction.operands
        fields: list[object]
        if op == ca.OP_INPUT:
            fields = [out[0], *operands]
        elif op == ca.OP_OUTPUT:
            fields = [*out, operands[0]]
        elif op == ca.OP_CONST:
            fields = [out[0], _literal(instruction.constant)]
        else:
            fields = [out[0], *operands]
        lines.append(f"    ({op}, {', '.join(str(f) for f in fields)}),")
    return lines


_NJIT: Final = "@numba.njit(cache=True, error_model='numpy', nogil=True)"


def _scalar_kernel(name: str, program: list[Instruction], n_in: int, n_out: int) -> list[str]:
    """A numba function ``name(i0, …, o0, …)`` running ``program``."""
    arguments = [f"i{i}" for i in range(n_in)] + [f"o{i}" for i in range(n_out)]
    return ["", _NJIT, f"def {name}({', '.join(arguments)}):", *_kernel_lines(program), ""]


def _lane_kernel(
    name: str, label: str, program: list[Instruction], n_in: int, n_out: int
) -> list[str]:
    """A lane intrinsic ``name_lanes(i0, …, o0, …)`` running ``program`` (``label``: errors)."""
    arguments = [f"i{i}" for i in range(n_in)] + [f"o{i}" for i in range(n_out)]
    return [
        "",
        f"_{name}_program = (",
        *lane_program(program),
        ")",
        "",
        "",
        "@intrinsic",
        f"def {name}_lanes(typingctx, {', '.join(arguments)}):",
        (f"    return lane_typing({label!r}, {n_in}, _{name}_program, ({', '.join(arguments)},))"),
        "",
    ]


def numba_source(
    functions: dict[str, ca.Function],
    header: str,
    appendix: str = "",
    batched: tuple[str, ...] | None = None,
    lanes: tuple[str, ...] = (),
    stage_inputs: tuple[int, ...] = (),
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
    stage_inputs : tuple of int, optional
        Inputs that are the same at every node of a step (e.g. input, parameters, weights).
        When given, every kernel is split (:func:`split_stage`): ``name_stage(i0, …, s)``
        (``name_stage_lanes``) computes what depends on these alone into ``s`` of
        ``NAME_STAGE_SIZE`` entries (a module constant), and ``name`` (``name_lanes``)
        takes ``s`` as its last input, ``name(i0, …, s, o0, …)``. A ``name_batch`` loop
        keeps the signature of the unsplit kernel.

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
        n_in, n_out, label = function.n_in(), function.n_out(), function.name()
        program = instructions(function)
        kernels = [(name, program, n_in, n_out)]
        if stage_inputs:
            stage, body, size = split_stage(program, stage_inputs, n_in)
            lines += ["", f"{name.upper()}_STAGE_SIZE = {size}", ""]
            kernels = [(f"{name}_stage", stage, n_in, 1), (name, body, n_in + 1, n_out)]
        for kernel, code, n_args, n_results in kernels:
            if name in lanes:
                lines += _lane_kernel(kernel, label, code, n_args, n_results)
            else:
                lines += _scalar_kernel(kernel, code, n_args, n_results)
        if name not in lanes and (batched is None or name in batched):
            inputs = [f"i{i}[b]" for i in range(n_in)]
            outputs = [f"o{i}[b]" for i in range(n_out)]
            arguments = [f"i{i}" for i in range(n_in)] + [f"o{i}" for i in range(n_out)]
            loop = ["    for b in range(i0.shape[0]):"]
            if stage_inputs:
                loop = [
                    f"    s = np.empty({name.upper()}_STAGE_SIZE)",
                    *loop,
                    f"        {name}_stage({', '.join(inputs)}, s)",
                ]
                inputs.append("s")
            lines += [
                "",
                _NJIT,
                f"def {name}_batch({', '.join(arguments)}):",
                *loop,
                f"        {name}({', '.join(inputs + outputs)})",
                "",
            ]
    return "\n".join([*lines, appendix])
