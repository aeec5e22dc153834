"""Terminal cost ``m(x_N)`` with its exact gradient and Hessian."""

from __future__ import annotations

from dataclasses import dataclass, field

import casadi as ca

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.optimization._casadi import (
    dense_function,
    evaluate,
    signature_sizes,
    symbols,
    with_symbol_fallback,
)

__all__ = ["TerminalCost", "make_terminal_cost"]


@dataclass(frozen=True, eq=False)
class TerminalCost:
    """Terminal cost ``m(x_N)`` with exact gradient and Hessian (one CasADi call).

    Both Functions have dense outputs and are evaluated on numpy buffers
    (:func:`~auvplan.optimization._casadi.evaluate`: no conversion to CasADi matrices).
    """

    n_x: int
    function: ca.Function
    _derivatives: ca.Function = field(repr=False)

    def evaluate(self, state: FloatArray) -> tuple[float, FloatArray, FloatArray]:
        """Return ``m(x)``, ``m_x`` of shape ``(n_x,)`` and ``m_xx`` of shape ``(n_x, n_x)``."""
        value, gradient, hessian = evaluate(self._derivatives, [state])
        # CasADi's dense outputs are column-major: m_xx is symmetric, so its transpose is it
        return float(value[0]), gradient, hessian.reshape(self.n_x, self.n_x).T.copy()

    def value(self, state: FloatArray) -> float:
        """``m(x)``."""
        return float(evaluate(self.function, [state])[0][0])


def make_terminal_cost(terminal_cost: ca.Function, n_x: int) -> TerminalCost:
    """Wrap ``m(x[n_x]) -> scalar`` with its exact derivatives.

    Raises
    ------
    InputError
        If the function has the wrong arity or input size.
    """
    sizes = signature_sizes(terminal_cost, "terminal_cost", 1, 1)
    if sizes != [n_x] or terminal_cost.numel_out(0) != 1:
        raise InputError(f"terminal_cost must map ({n_x},) to a scalar, got inputs {sizes}")

    def build(use_sx: bool) -> TerminalCost:
        (x,) = symbols([n_x], ["x"], use_sx)
        value = terminal_cost(x)
        hess, grad = ca.hessian(value, x)
        derivatives = dense_function(
            "terminal", [x], [value, grad, hess], ["x"], ["m", "m_x", "m_xx"]
        )
        value_function = dense_function("terminal_value", [x], [value], ["x"], ["m"])
        return TerminalCost(n_x, value_function, derivatives)

    return with_symbol_fallback(build)
