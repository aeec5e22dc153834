r"""RK4 discretisation of a continuous-time model with exact, batched derivatives.

A continuous model ``ẋ = f(x, u, p)`` with running-cost rate ``l(x, u, p)`` becomes the
discrete-time map of classical Runge–Kutta steps over one control interval ``dt`` with the
input ``u`` and the stage parameter ``p`` held constant (zero-order hold). The running cost is
integrated **as an extra RK4 quadrature state** that does not feed back into the dynamics, so
the discrete stage cost is the RK4 quadrature of ``l`` along the same stages:

.. math::

    k_1 &= f(x, u, p), & q_1 &= l(x, u, p) \
    k_2 &= f(x + \tfrac{dt}{2} k_1, u, p), & q_2 &= l(x + \tfrac{dt}{2} k_1, u, p) \
    k_3 &= f(x + \tfrac{dt}{2} k_2, u, p), & q_3 &= l(x + \tfrac{dt}{2} k_2, u, p) \
    k_4 &= f(x + dt\, k_3, u, p),       & q_4 &= l(x + dt\, k_3, u, p) \
    F(x, u, p) &= x + \tfrac{dt}{6}(k_1 + 2k_2 + 2k_3 + k_4), &
    L(x, u, p) &= \tfrac{dt}{6}(q_1 + 2q_2 + 2q_3 + q_4).

(one substep; :mod:`auvplan.optimization.integration` composes several). All derivatives
(``F_x``, ``F_u``, the costate-weighted Hessians ``Σ_i λ_i ∇²F^i`` and the cost derivatives)
are exact: CasADi differentiates the RK4 expression graph itself. Batched evaluation over a
horizon of ``N`` stages uses ``casadi.Function.map(N, "serial")`` (one call into CasADi's virtual
machine, no Python loop per stage); the mapped functions are built once per ``N`` and kept.
Every method takes and returns time-major arrays (layout: :mod:`auvplan.optimization._casadi`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

import casadi as ca
import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.optimization._casadi import (
    Parallelization,
    StageEvaluator,
    check_rollout,
    evaluate,
    hessian_shapes,
    signature_sizes,
    symbols,
    with_symbol_fallback,
)
from auvplan.optimization.integration import check_substeps, rk4_step
from auvplan.optimization.stage_functions import StageFunctions

__all__ = ["DiscreteModel", "discretize_rk4"]


class StepModel(Protocol):
    """What the solver needs of a discrete model ``x_{k+1} = F(x_k, u_k, p_k)`` and its cost.

    Implemented by :class:`DiscreteModel` (stacked CasADi functions) and
    :class:`~auvplan.optimization.separable.BlockDiscreteModel` (compiled per-block kernels).
    Arrays are time-major: ``states`` ``(N, n_x)``, ``inputs`` ``(N, n_u)``, ``parameters``
    ``(N, n_p)`` for the ``N`` stages.
    """

    @property
    def n_x(self) -> int:
        """State dimension."""
        ...

    @property
    def n_u(self) -> int:
        """Input dimension."""
        ...

    def step(self, states: FloatArray, inputs: FloatArray, parameters: FloatArray) -> FloatArray:
        """Next states ``F(x_k, u_k, p_k)``, shape ``(N, n_x)``."""
        ...

    def cost(self, states: FloatArray, inputs: FloatArray, parameters: FloatArray) -> FloatArray:
        """Stage costs ``L(x_k, u_k, p_k)``, shape ``(N,)``."""
        ...

    def first_order(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
        """``(F_x, F_u, L, L_x, L_u)``."""
        ...

    def jacobians(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """``F_x (N, n_x, n_x)`` and ``F_u (N, n_x, n_u)``."""
        ...

    def cost_hessians(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Hessian blocks ``L_xx``, ``L_xu``, ``L_uu`` of the stage cost."""
        ...

    def lagrangian_hessians(
        self,
        states: FloatArray,
        inputs: FloatArray,
        parameters: FloatArray,
        costate_next: FloatArray,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Hessian blocks of ``L + λ_{k+1}ᵀ F``."""
        ...

    def rollout(
        self,
        initial_state: FloatArray,
        reference_states: FloatArray,
        reference_inputs: FloatArray,
        gains: FloatArray,
        parameters: FloatArray,
    ) -> tuple[FloatArray, FloatArray]:
        """Closed-loop simulation ``u_k = μ_k + K_k (α_k − x_k)``: states and inputs."""
        ...


@dataclass(frozen=True, eq=False)
class DiscreteModel:
    """The step ``x_{k+1} = F(x_k, u_k, p_k)`` and its stage cost, batched over stages.

    Build it with :func:`discretize_rk4`. Every method takes time-major arrays
    ``X (N, n_x)``, ``U (N, n_u)``, ``P (N, n_p)`` (one row per stage ``k = 0..N-1``; ``P``
    may have zero columns) and evaluates all ``N`` stages in one CasADi call.

    Attributes
    ----------
    n_x, n_u, n_p : int
        State, input and stage-parameter dimensions.
    dt : float
        Control interval [s] (the length of one step of ``F``).
    n_substeps : int
        RK4 substeps per step (each ``dt / n_substeps`` long).
    functions : StageFunctions
        The single-stage Functions.
    parallelization : {"serial", "thread"}
        How CasADi's ``map`` evaluates the stages.
    n_threads : int
        Number of threads when ``parallelization == "thread"``.
    """

    n_x: int
    n_u: int
    n_p: int
    dt: float
    n_substeps: int
    functions: StageFunctions = field(repr=False)
    parallelization: Parallelization = "serial"
    n_threads: int = 2
    _stages: StageEvaluator = field(init=False, repr=False)

    def __post_init__(self) -> None:
        evaluator = StageEvaluator(
            self.n_x, self.n_u, self.n_p, self.parallelization, self.n_threads
        )
        object.__setattr__(self, "_stages", evaluator)

    @property
    def step_function(self) -> ca.Function:
        """``F(x, u, p) -> x_next`` for one stage."""
        return self.functions.step

    @property
    def cost_function(self) -> ca.Function:
        """``L(x, u, p) -> scalar``: the RK4 quadrature of the running-cost rate over a step."""
        return self.functions.cost

    def _hessians(
        self,
        function: ca.Function,
        states: FloatArray,
        inputs: FloatArray,
        parameters: FloatArray,
        costate_next: FloatArray | None,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        weights = None if costate_next is None else ("costate_next", costate_next, self.n_x)
        h_xx, h_xu, h_uu = self._stages(
            function, states, inputs, parameters, hessian_shapes(self.n_x, self.n_u), weights
        )
        return h_xx, h_xu, h_uu

    def step(self, states: FloatArray, inputs: FloatArray, parameters: FloatArray) -> FloatArray:
        """Next states ``F(x_k, u_k, p_k)``, shape ``(N, n_x)``.

        Examples
        --------
        >>> import casadi as ca, numpy as np
        >>> x, u, p = ca.SX.sym("x"), ca.SX.sym("u"), ca.SX.sym("p", 0)
        >>> f = ca.Function("f", [x, u, p], [-x + u])
        >>> l = ca.Function("l", [x, u, p], [x**2 + u**2])
        >>> model = discretize_rk4(f, l, 0.1)
        >>> model.step(np.ones((2, 1)), np.zeros((2, 1)), np.zeros((2, 0))).round(7)
        array([[0.9048375],
               [0.9048375]])
        """
        (out,) = self._stages(self.functions.step, states, inputs, parameters, [(self.n_x,)])
        return out

    def jacobians(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """Exact ``F_x`` of shape ``(N, n_x, n_x)`` and ``F_u`` of shape ``(N, n_x, n_u)``."""
        f_x, f_u = self._stages(
            self.functions.jacobians,
            states,
            inputs,
            parameters,
            [(self.n_x, self.n_x), (self.n_x, self.n_u)],
        )
        return f_x, f_u

    def weighted_hessians(
        self,
        states: FloatArray,
        inputs: FloatArray,
        parameters: FloatArray,
        costate_next: FloatArray,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Costate-weighted Hessians of the step, ``Σ_i λ_{k+1,i} ∇²F^i_k``.

        Parameters
        ----------
        states, inputs, parameters : ndarray of shape (N, n_x), (N, n_u), (N, n_p)
            Stage points.
        costate_next : ndarray of shape (N, n_x)
            Weights ``λ_{k+1}`` (the costate one stage ahead).

        Returns
        -------
        H_xx, H_xu, H_uu : ndarray of shape (N, n_x, n_x), (N, n_x, n_u), (N, n_u, n_u)
            Blocks of the Hessian of ``λ_{k+1}ᵀ F(x, u, p)`` with respect to ``(x, u)``.
        """
        return self._hessians(self.functions.dyn_hessian, states, inputs, parameters, costate_next)

    def cost(self, states: FloatArray, inputs: FloatArray, parameters: FloatArray) -> FloatArray:
        """Stage costs ``L(x_k, u_k, p_k)``, shape ``(N,)``."""
        (out,) = self._stages(self.functions.cost, states, inputs, parameters, [()])
        return out

    def cost_gradients(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """Stage-cost gradients ``L_x`` of shape ``(N, n_x)`` and ``L_u`` of shape ``(N, n_u)``."""
        l_x, l_u = self._stages(
            self.functions.cost_gradient, states, inputs, parameters, [(self.n_x,), (self.n_u,)]
        )
        return l_x, l_u

    def cost_hessians(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Stage-cost Hessian blocks ``L_xx (N, n_x, n_x)``, ``L_xu (N, n_x, n_u)``, ``L_uu``."""
        return self._hessians(self.functions.cost_hessian, states, inputs, parameters, None)

    def first_order(
        self, states: FloatArray, inputs: FloatArray, parameters: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
        """All first-order data in one call: ``(F_x, F_u, L, L_x, L_u)`` (shapes as above)."""
        n_x, n_u = self.n_x, self.n_u
        f_x, f_u, cost, l_x, l_u = self._stages(
            self.functions.first_order,
            states,
            inputs,
            parameters,
            [(n_x, n_x), (n_x, n_u), (), (n_x,), (n_u,)],
        )
        return f_x, f_u, cost, l_x, l_u

    def lagrangian_hessians(
        self,
        states: FloatArray,
        inputs: FloatArray,
        parameters: FloatArray,
        costate_next: FloatArray,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Hessian blocks of ``L(x,u,p) + λ_{k+1}ᵀ F(x,u,p)`` in one call (Q, S, R of PRONTO)."""
        return self._hessians(
            self.functions.lagrangian_hessian, states, inputs, parameters, costate_next
        )

    def rollout(
        self,
        initial_state: FloatArray,
        reference_states: FloatArray,
        reference_inputs: FloatArray,
        gains: FloatArray,
        parameters: FloatArray,
    ) -> tuple[FloatArray, FloatArray]:
        """Closed-loop simulation ``u_k = μ_k + K_k (α_k − x_k)``, ``x_{k+1} = F(x_k, u_k, p_k)``.

        One ``casadi.Function.mapaccum`` call runs the whole recursion.

        Parameters
        ----------
        initial_state : ndarray of shape (n_x,)
            ``x_0``.
        reference_states : ndarray of shape (N, n_x) or (N + 1, n_x)
            ``α_k`` (rows beyond ``N`` are ignored).
        reference_inputs : ndarray of shape (N, n_u)
            ``μ_k``.
        gains : ndarray of shape (N, n_u, n_x)
            ``K_k`` (zeros give an open-loop simulation).
        parameters : ndarray of shape (N, n_p)
            Stage parameters.

        Returns
        -------
        states : ndarray of shape (N + 1, n_x)
            Simulated states (may contain inf/NaN if the simulation diverges).
        inputs : ndarray of shape (N, n_u)
            Applied inputs.

        Raises
        ------
        InputError
            If the arrays do not describe the same ``N`` stages.
        """
        x0, alpha, mu, gains, params = check_rollout(
            (self.n_x, self.n_u, self.n_p),
            initial_state, reference_states, reference_inputs, gains, parameters,
        )  # fmt: skip
        n_stages = mu.shape[0]
        accumulated = self._stages.accumulated(self.functions.closed_loop_step, n_stages)
        (out,) = evaluate(accumulated, [x0, alpha, mu, gains.reshape(n_stages, -1), params])
        states = np.empty((n_stages + 1, self.n_x))
        states[0] = x0
        states[1:] = out.reshape(n_stages, self.n_x)
        inputs = mu + np.einsum("kij,kj->ki", gains, alpha - states[:-1])
        return states, inputs


def _stage_functions(
    dynamics: ca.Function,
    running_cost: ca.Function,
    sizes: list[int],
    dt: float,
    n_substeps: int,
    use_sx: bool,
) -> StageFunctions:
    """The stage Functions of the RK4 map on SX or MX symbols."""
    x, u, p = symbols(sizes, ["x", "u", "p"], use_sx)
    x_next, stage_cost = rk4_step(dynamics, running_cost, x, u, p, dt, n_substeps)
    return StageFunctions(x, u, p, x_next, stage_cost, use_sx)


def discretize_rk4(
    dynamics: ca.Function,
    running_cost: ca.Function,
    dt: float,
    *,
    n_substeps: int = 1,
    parallelization: Parallelization = "serial",
    n_threads: int = 2,
    compile_c: bool = False,
    cache_dir: Path | None = None,
) -> DiscreteModel:
    """Discretise ``ẋ = f(x, u, p)`` and the cost rate ``l`` by RK4 steps (zero-order hold).

    Parameters
    ----------
    dynamics : casadi.Function
        ``f(x[n_x], u[n_u], p[n_p]) -> xdot[n_x]`` (continuous time, SI units per second).
    running_cost : casadi.Function
        ``l(x, u, p) -> scalar``: running-cost *rate* (cost per second).
    dt : float
        Control interval [s], > 0: the length of one step of ``F``.
    n_substeps : int, optional
        RK4 substeps of length ``dt / n_substeps`` per step (``u`` and ``p`` held); see
        :func:`~auvplan.optimization.integration.choose_substeps`.
    parallelization : {"serial", "thread"}, optional
        Evaluation mode of the batched (``map``) functions.
    n_threads : int, optional
        Threads for ``parallelization="thread"``.
    compile_c : bool, optional
        Generate C code for the stage functions, compile it once (cached on disk, see
        :mod:`auvplan.optimization._compile`) and evaluate the compiled code: about 10x faster
        Hessians for vehicle models; falls back to the CasADi VM without a C compiler.
    cache_dir : Path, optional
        Cache folder of the compiled libraries (default ``~/.cache/auvplan/casadi``).

    Returns
    -------
    DiscreteModel
        The stage map ``F`` and the stage cost ``L`` (RK4 quadrature of ``l``; module notes).

    Raises
    ------
    InputError
        If the functions have the wrong arity or sizes, ``dt`` is not positive or
        ``n_substeps`` not a positive integer.

    Notes
    -----
    The stage functions are built with SX symbols when the user functions can be evaluated
    symbolically on SX (fast virtual machine); otherwise with MX.

    Examples
    --------
    >>> import casadi as ca
    >>> x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p", 0)
    >>> f = ca.Function("f", [x, u, p], [ca.vertcat(x[1], u)])
    >>> l = ca.Function("l", [x, u, p], [u**2])
    >>> model = discretize_rk4(f, l, 0.5)
    >>> (model.n_x, model.n_u, model.n_p)
    (2, 1, 0)
    """
    if not np.isfinite(dt) or dt <= 0.0:
        raise InputError(f"dt must be a positive number of seconds, got {dt!r}")
    check_substeps(n_substeps)
    sizes = signature_sizes(dynamics, "dynamics", 3, 1)
    cost_sizes = signature_sizes(running_cost, "running_cost", 3, 1)
    if cost_sizes != sizes:
        raise InputError(f"running_cost input sizes {cost_sizes} differ from dynamics {sizes}")
    if dynamics.size_out(0) != (sizes[0], 1) and not (sizes[0] == 1 and dynamics.numel_out(0) == 1):
        raise InputError(f"dynamics output must be ({sizes[0]}, 1), got {dynamics.size_out(0)}")
    if running_cost.numel_out(0) != 1:
        raise InputError(f"running_cost must return a scalar, got {running_cost.size_out(0)}")
    functions = with_symbol_fallback(
        lambda use_sx: _stage_functions(
            dynamics, running_cost, sizes, float(dt), int(n_substeps), use_sx
        )
    )
    if compile_c:
        functions = functions.compiled(cache_dir)
    return DiscreteModel(
        n_x=sizes[0],
        n_u=sizes[1],
        n_p=sizes[2],
        dt=float(dt),
        n_substeps=int(n_substeps),
        functions=functions,
        parallelization=parallelization,
        n_threads=n_threads,
    )
