r"""Trajectory-optimisation problem definition: dynamics, costs, constraints, trajectories.

The discrete problem solved by :func:`~auvplan.optimization.pronto.solve_pronto` and by the
IPOPT bridge is

.. math::

    \min_{x, u}\; \sum_{k=0}^{N-1} \Big[ L(x_k, u_k, p_k)
        + ε\, dt \sum_j b_j\big(c_j(x_k, u_k, p_k) / \text{scale}_j\big) \Big] + m(x_N)
        + ε\, dt \sum_{j \in \mathcal{F}} b_j\big(c_j(x_N, u_{N-1}, p_{N-1}) / \text{scale}_j\big)
    \quad \text{s.t.}\quad x_{k+1} = F(x_k, u_k, p_k),\; x_0 = x0,

with ``F`` the flow of the dynamics over the control interval ``dt``, approximated by
``n_substeps`` RK4 substeps (``u_k``, ``p_k`` held), and ``L`` the RK4 quadrature of the
running-cost rate along the same substeps (see :mod:`auvplan.optimization.integration`),
``b_j`` the approximate log barrier composed with the hockey stick (``kind="hockey"``) or not
(``kind="plain"``), see :mod:`auvplan.optimization.barrier`. Path constraints are imposed at
the nodes ``k = 0..N-1`` and, for their components free of ``u``, at the final node ``x_N``
too (the set ``F``, with ``u_{N-1}``, ``p_{N-1}`` held; :attr:`PathConstraint.at_final_node`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, Protocol, runtime_checkable

import casadi as ca
import numpy as np

from auvplan._typing import BoolArray, FloatArray
from auvplan.errors import InputError
from auvplan.optimization.barrier import BarrierKind
from auvplan.optimization.integration import check_substeps
from auvplan.optimization.options import named_choice
from auvplan.optimization.separable import StageBlock, check_tiling

__all__ = ["NodeCost", "PathConstraint", "Trajectory", "TrajectoryProblem"]


@runtime_checkable
class NodeCost(Protocol):
    """A cost rate ``r(x)`` [cost/s] charged at the nodes: ``dt Σ_{k<N} r(x_k)``.

    For terms that are not CasADi expressions (e.g. a spline surface of a terrain map),
    evaluated with exact derivatives by the implementation.
    """

    def values(self, states: FloatArray) -> FloatArray:
        """``r(x_k)`` at states ``(N, n_x)``, shape ``(N,)``."""
        ...

    def derivatives(self, states: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``r`` ``(N,)``, ``∇r`` ``(N, n_x)`` and ``∇²r`` ``(N, n_x, n_x)``."""
        ...


@dataclass(frozen=True)
class PathConstraint:
    """A path constraint ``c(x, u, p) >= 0`` (component-wise) handled by a barrier.

    Attributes
    ----------
    function : casadi.Function
        ``c(x[n_x], u[n_u], p[n_p]) -> (n_c,)``; feasible when every component is ``>= 0``.
    kind : BarrierKind or {"plain", "hockey"}
        ``"hockey"`` composes the barrier with the hockey stick ``σ`` so it vanishes far
        from the constraint (use for non-convex constraints such as separations);
        ``"plain"`` uses ``β_δ(s)`` directly (convex constraints such as input bounds).
        Strings are converted to :class:`BarrierKind`.
    scale : float
        Slack scale: the barrier sees ``s = c / scale``; choose it so that ``s ≈ 1`` is a
        meaningful margin (unit of ``c``).
    name : str
        Label used in logs and results.
    """

    function: ca.Function
    kind: BarrierKind | Literal["plain", "hockey"] = BarrierKind.HOCKEY
    scale: float = 1.0
    name: str = "constraint"

    def __post_init__(self) -> None:
        if not isinstance(self.function, ca.Function):
            raise InputError(
                f"PathConstraint.function must be a casadi.Function, got {self.function!r}"
            )
        object.__setattr__(
            self, "kind", named_choice(BarrierKind, self.kind, "PathConstraint.kind")
        )
        if not (np.isfinite(self.scale) and self.scale > 0.0):
            raise InputError(f"PathConstraint.scale must be positive, got {self.scale!r}")

    @property
    def n_components(self) -> int:
        """Number of constraint components ``n_c``."""
        return int(self.function.numel_out(0))

    @property
    def at_final_node(self) -> BoolArray:
        """Which components are also imposed at the final node ``x_N``: those free of ``u``.

        The final state has no input of its own; a component that depends only on ``x`` (and
        ``p``) is evaluated there with the last stage's parameters.
        """
        depends = np.zeros(self.n_components, dtype=np.bool_)
        depends[np.asarray(self.function.sparsity_jac(1, 0).row(), dtype=np.int64)] = True
        return ~depends


def _as_matrix(value: FloatArray, size: int, name: str) -> FloatArray:
    array = np.asarray(value, dtype=np.float64)
    if array.shape == (size,):
        array = np.diag(array)
    if array.shape != (size, size) or not np.all(np.isfinite(array)):
        raise InputError(f"{name} must be ({size},) or ({size}, {size}) finite, got {array.shape}")
    array = 0.5 * (array + array.T)
    if np.min(np.linalg.eigvalsh(array)) <= 0.0:
        raise InputError(f"{name} must be positive definite")
    return array


@dataclass(frozen=True)
class TrajectoryProblem:
    """Fixed-horizon optimal-control problem on a uniform grid of control intervals.

    Attributes
    ----------
    dynamics : casadi.Function
        ``f(x[n_x], u[n_u], p[n_p]) -> xdot[n_x]`` (continuous time).
    running_cost : casadi.Function
        ``l(x, u, p) -> scalar``: cost rate (cost unit per second).
    terminal_cost : casadi.Function
        ``m(x[n_x]) -> scalar``.
    initial_state : ndarray of shape (n_x,)
        ``x0``.
    dt : float
        Control interval [s]: inputs and stage parameters are held over it, and the states
        and inputs of a :class:`Trajectory` are sampled at this interval.
    n_steps : int
        Number of stages ``N`` (horizon ``T = N dt``).
    stage_parameters : ndarray of shape (n_steps, n_p)
        Per-stage parameters ``p_k`` (held over the step); default: no parameters.
    constraints : tuple of PathConstraint
        Path constraints, imposed at nodes ``k = 0..N-1`` (and at ``N``, see module notes).
    regulator_Q : ndarray of shape (n_x, n_x) or (n_x,)
        State weight of the projection regulator (diagonal when 1-D); default identity.
    regulator_R : ndarray of shape (n_u, n_u) or (n_u,)
        Input weight of the projection regulator; default identity.
    n_substeps : int
        RK4 substeps of length ``dt / n_substeps`` per control interval (default 1); see
        :func:`~auvplan.optimization.integration.choose_substeps`.
    regulator_floor : ndarray of shape (n_x,), optional
        The projection regulator is designed on the linearisation at states whose magnitudes
        are raised to at least these values, ``x̃_i = sign(x_i) max(|x_i|, floor_i)``
        (0: unchanged). A model whose input authority vanishes at rest (thrust ∝ n|n| has
        ``∂T/∂n = 0`` at ``n = 0``) stays controllable in the design; the Newton model keeps the
        exact linearisation. Default: the exact linearisation.
    node_costs : tuple of NodeCost
        Cost rates charged at the nodes ``k = 0..N-1`` (rectangle rule, ``dt Σ_k r(x_k)``),
        added to the running cost. Default: none.
    blocks : tuple of StageBlock
        The separable structure of ``dynamics`` and ``running_cost`` when they were stacked
        from independent subsystems by :func:`~auvplan.optimization.separable.stack_blocks`:
        the solver then evaluates the step with compiled per-block kernels. Default: none
        (the stacked functions are evaluated by CasADi).
    """

    dynamics: ca.Function
    running_cost: ca.Function
    terminal_cost: ca.Function
    initial_state: FloatArray
    dt: float
    n_steps: int
    stage_parameters: FloatArray | None = None
    constraints: tuple[PathConstraint, ...] = ()
    regulator_Q: FloatArray | None = field(default=None)
    regulator_R: FloatArray | None = field(default=None)
    n_substeps: int = 1
    regulator_floor: FloatArray | None = None
    node_costs: tuple[NodeCost, ...] = ()
    blocks: tuple[StageBlock, ...] = ()

    def __post_init__(self) -> None:
        for name in ("dynamics", "running_cost", "terminal_cost"):
            if not isinstance(getattr(self, name), ca.Function):
                raise InputError(f"{name} must be a casadi.Function")
        n_x = int(self.dynamics.numel_in(0))
        n_u = int(self.dynamics.numel_in(1))
        n_p = int(self.dynamics.numel_in(2)) if self.dynamics.n_in() > 2 else -1
        if self.dynamics.n_in() != 3 or n_p < 0:
            raise InputError("dynamics must take exactly three inputs (x, u, p)")
        if not (isinstance(self.n_steps, int | np.integer) and self.n_steps >= 1):
            raise InputError(f"n_steps must be a positive integer, got {self.n_steps!r}")
        if not (np.isfinite(self.dt) and self.dt > 0.0):
            raise InputError(f"dt must be a positive number of seconds, got {self.dt!r}")
        check_substeps(self.n_substeps)
        x0 = np.asarray(self.initial_state, dtype=np.float64).reshape(-1)
        if x0.shape != (n_x,) or not np.all(np.isfinite(x0)):
            raise InputError(f"initial_state must be finite with shape ({n_x},), got {x0.shape}")
        object.__setattr__(self, "initial_state", x0)
        params = (
            np.zeros((self.n_steps, n_p))
            if self.stage_parameters is None
            else np.asarray(self.stage_parameters, dtype=np.float64)
        )
        if params.shape != (self.n_steps, n_p):
            raise InputError(
                f"stage_parameters must have shape ({self.n_steps}, {n_p}), got {params.shape}"
            )
        object.__setattr__(self, "stage_parameters", np.ascontiguousarray(params))
        q_r = np.ones(n_x) if self.regulator_Q is None else self.regulator_Q
        r_r = np.ones(n_u) if self.regulator_R is None else self.regulator_R
        object.__setattr__(self, "regulator_Q", _as_matrix(q_r, n_x, "regulator_Q"))
        object.__setattr__(self, "regulator_R", _as_matrix(r_r, n_u, "regulator_R"))
        if self.regulator_floor is not None:
            floor = np.asarray(self.regulator_floor, dtype=np.float64).reshape(-1)
            if floor.shape != (n_x,) or not np.all(np.isfinite(floor)) or np.any(floor < 0):
                raise InputError(f"regulator_floor must be finite, >= 0, with shape ({n_x},)")
            object.__setattr__(self, "regulator_floor", floor)
        object.__setattr__(self, "blocks", tuple(self.blocks))
        object.__setattr__(self, "node_costs", tuple(self.node_costs))
        for term in self.node_costs:
            if not isinstance(term, NodeCost):
                raise InputError(f"node_costs must implement NodeCost, got {term!r}")
        if self.blocks:
            check_tiling(self.blocks, (n_x, n_u, n_p))
        object.__setattr__(self, "constraints", tuple(self.constraints))
        for constraint in self.constraints:
            if not isinstance(constraint, PathConstraint):
                raise InputError(f"constraints must be PathConstraint objects, got {constraint!r}")

    @property
    def n_states(self) -> int:
        """State dimension ``n_x``."""
        return int(self.dynamics.numel_in(0))

    @property
    def n_inputs(self) -> int:
        """Input dimension ``n_u``."""
        return int(self.dynamics.numel_in(1))

    @property
    def n_parameters(self) -> int:
        """Stage-parameter dimension ``n_p``."""
        return int(self.dynamics.numel_in(2))

    @property
    def parameters(self) -> FloatArray:
        """Stage parameters as an array of shape ``(n_steps, n_p)``."""
        assert self.stage_parameters is not None  # set in __post_init__
        return self.stage_parameters

    @property
    def state_weight(self) -> FloatArray:
        """Regulator state weight ``Q_r`` of shape ``(n_x, n_x)``."""
        assert self.regulator_Q is not None
        return self.regulator_Q

    @property
    def input_weight(self) -> FloatArray:
        """Regulator input weight ``R_r`` of shape ``(n_u, n_u)``."""
        assert self.regulator_R is not None
        return self.regulator_R

    @property
    def time(self) -> FloatArray:
        """Node times ``t_k = k dt`` [s], shape ``(n_steps + 1,)``."""
        return np.arange(self.n_steps + 1, dtype=np.float64) * self.dt


@dataclass(frozen=True)
class Trajectory:
    """States and inputs on the grid (zero-order-hold inputs).

    Attributes
    ----------
    states : ndarray of shape (N + 1, n_x)
        ``x_0 .. x_N``.
    inputs : ndarray of shape (N, n_u)
        ``u_0 .. u_{N-1}``.
    """

    states: FloatArray
    inputs: FloatArray

    def __post_init__(self) -> None:
        states = np.ascontiguousarray(self.states, dtype=np.float64)
        inputs = np.ascontiguousarray(self.inputs, dtype=np.float64)
        if states.ndim != 2 or inputs.ndim != 2 or states.shape[0] != inputs.shape[0] + 1:
            raise InputError(
                f"Trajectory needs states (N+1, n_x) and inputs (N, n_u), got "
                f"{states.shape} and {inputs.shape}"
            )
        object.__setattr__(self, "states", states)
        object.__setattr__(self, "inputs", inputs)

    @property
    def n_steps(self) -> int:
        """Number of stages ``N``."""
        return int(self.inputs.shape[0])
