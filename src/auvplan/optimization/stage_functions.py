"""Single-stage CasADi Functions of the discrete map, each built on first use.

From the symbolic step ``F(x, u, p)`` and stage cost ``L(x, u, p)``
(:func:`~auvplan.optimization.integration.rk4_step`) every derivative the solver needs is a
dense CasADi Function of one stage (matrices flattened row-major). Building a Function costs
graph differentiation and common-subexpression elimination (seconds for vehicle fleets with
several substeps), so each one is built when first used: a solve never builds
``dyn_hessian``, ``cost_gradient`` or (without the quasi-Newton fallback) ``cost_hessian``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import casadi as ca

from auvplan.optimization._casadi import Symbol, dense_function, hessian_blocks, row_major, symbols
from auvplan.optimization._compile import compile_functions

__all__ = ["SOLVER_FUNCTIONS", "StageFunctions"]

#: The Functions a PRONTO solve evaluates (compiled together by :meth:`StageFunctions.compiled`).
SOLVER_FUNCTIONS = (
    "step",
    "cost",
    "jacobians",
    "first_order",
    "lagrangian_hessian",
    "closed_loop_step",
)
_ARGS = ["x", "u", "p"]
_HESSIANS = ["h_xx", "h_xu", "h_uu"]


@dataclass(frozen=True, eq=False)
class StageFunctions:
    """The discrete map's single-stage Functions (attributes, built on first access).

    Every Function takes ``(x, u, p)``; the Hessians also the weights ``λ``, and
    ``closed_loop_step`` takes ``(x, α, μ, K, p)`` (``K`` flattened row-major).

    Attributes
    ----------
    x, u, p : casadi.SX or casadi.MX
        State, input and stage-parameter symbols.
    x_next, stage_cost : casadi.SX or casadi.MX
        ``F(x, u, p)`` and ``L(x, u, p)``.
    use_sx : bool
        Whether the symbols are SX (else MX).
    compiled : mapping of str to casadi.Function
        C-compiled replacements by attribute name (see :meth:`compiled`).
    """

    x: Symbol
    u: Symbol
    p: Symbol
    x_next: Symbol
    stage_cost: Symbol
    use_sx: bool
    compiled_functions: Mapping[str, ca.Function] = field(default_factory=dict)

    def _function(
        self, name: str, outputs: list[Symbol], out_names: list[str], weighted: bool = False
    ) -> ca.Function:
        """``name(x, u, p[, λ]) -> outputs`` (the compiled one when there is one)."""
        if name in self.compiled_functions:
            return self.compiled_functions[name]
        args, arg_names = [self.x, self.u, self.p], list(_ARGS)
        if weighted:
            args, arg_names = [*args, self._costate], [*arg_names, "lam"]
        return dense_function(f"rk4_{name}", args, outputs, arg_names, out_names)

    @cached_property
    def _costate(self) -> Symbol:
        (lam,) = symbols([int(self.x.numel())], ["lam"], self.use_sx)
        return lam

    @cached_property
    def _f_x(self) -> Symbol:
        return row_major(ca.jacobian(self.x_next, self.x))

    @cached_property
    def _f_u(self) -> Symbol:
        return row_major(ca.jacobian(self.x_next, self.u))

    @cached_property
    def _cost_gradients(self) -> list[Symbol]:
        return [ca.gradient(self.stage_cost, self.x), ca.gradient(self.stage_cost, self.u)]

    @cached_property
    def step(self) -> ca.Function:
        """``F(x, u, p) -> x_next``."""
        return self._function("step", [self.x_next], ["x_next"])

    @cached_property
    def cost(self) -> ca.Function:
        """``L(x, u, p) -> l``: the stage cost."""
        return self._function("cost", [self.stage_cost], ["l"])

    @cached_property
    def jacobians(self) -> ca.Function:
        """``(x, u, p) -> (F_x, F_u)``."""
        return self._function("jac", [self._f_x, self._f_u], ["f_x", "f_u"])

    @cached_property
    def first_order(self) -> ca.Function:
        """``(x, u, p) -> (F_x, F_u, L, L_x, L_u)``."""
        return self._function(
            "first",
            [self._f_x, self._f_u, self.stage_cost, *self._cost_gradients],
            ["f_x", "f_u", "l", "l_x", "l_u"],
        )

    @cached_property
    def cost_gradient(self) -> ca.Function:
        """``(x, u, p) -> (L_x, L_u)``."""
        return self._function("cost_grad", self._cost_gradients, ["l_x", "l_u"])

    @cached_property
    def dyn_hessian(self) -> ca.Function:
        """``(x, u, p, λ) ->`` Hessian blocks of ``λᵀ F``."""
        expression = ca.dot(self._costate, self.x_next)
        return self._function(
            "dyn_hess", hessian_blocks(expression, self.x, self.u), _HESSIANS, weighted=True
        )

    @cached_property
    def cost_hessian(self) -> ca.Function:
        """``(x, u, p) ->`` Hessian blocks of ``L``."""
        return self._function(
            "cost_hess", hessian_blocks(self.stage_cost, self.x, self.u), _HESSIANS
        )

    @cached_property
    def lagrangian_hessian(self) -> ca.Function:
        """``(x, u, p, λ) ->`` Hessian blocks of ``L + λᵀ F``."""
        expression = self.stage_cost + ca.dot(self._costate, self.x_next)
        return self._function(
            "lag_hess", hessian_blocks(expression, self.x, self.u), _HESSIANS, weighted=True
        )

    @cached_property
    def closed_loop_step(self) -> ca.Function:
        """``(x, α, μ, K, p) -> F(x, μ + K (α − x), p)``."""
        if "closed_loop_step" in self.compiled_functions:
            return self.compiled_functions["closed_loop_step"]
        n_x, n_u = int(self.x.numel()), int(self.u.numel())
        alpha, mu, gains = symbols([n_x, n_u, n_u * n_x], ["alpha", "mu", "k"], self.use_sx)
        closed_u = mu + ca.reshape(gains, n_x, n_u).T @ (alpha - self.x)
        return dense_function(
            "rk4_closed_loop",
            [self.x, alpha, mu, gains, self.p],
            [self.step(self.x, closed_u, self.p)],
            ["x", "alpha", "mu", "k", "p"],
            ["x_next"],
        )

    def compiled(self, cache_dir: Path | None) -> StageFunctions:
        """The same Functions, the :data:`SOLVER_FUNCTIONS` compiled to C in one library.

        See :func:`~auvplan.optimization._compile.compile_functions` (cached on disk; the
        virtual-machine Functions are kept when no C compiler works).
        """
        functions = {name: getattr(self, name) for name in SOLVER_FUNCTIONS}
        return dataclasses.replace(self, compiled_functions=compile_functions(functions, cache_dir))
