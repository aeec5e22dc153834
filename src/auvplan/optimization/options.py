"""Options of :func:`~auvplan.optimization.pronto.solve_pronto` and their named choices."""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Literal, TypeVar

from auvplan.errors import InputError

__all__ = ["FallbackModel", "ProntoOptions", "StageBackend", "TerminalRegulator", "named_choice"]

_Choice = TypeVar("_Choice", bound=enum.StrEnum)


class TerminalRegulator(enum.StrEnum):
    """Terminal matrix ``P_N`` of the projection regulator's Riccati recursion."""

    DARE = "dare"
    """Discrete algebraic Riccati equation at the last stage (``Q_r`` when it fails)."""
    WEIGHT = "weight"
    """The regulator state weight ``Q_r``."""


class FallbackModel(enum.StrEnum):
    """Which weights the convexified fallback of the direction ladder clips."""

    NEWTON = "newton"
    """The exact Newton weights (no extra evaluation)."""
    COST = "cost"
    """The cost Hessians only (quasi-Newton; one more Hessian pass)."""


def named_choice(choice_type: type[_Choice], value: str, name: str) -> _Choice:
    """``choice_type(value)`` for an enum member or its string value.

    Raises
    ------
    InputError
        Naming ``name`` and the allowed values, for any other value.
    """
    try:
        return choice_type(value)
    except ValueError:
        allowed = ", ".join(repr(item.value) for item in choice_type)
        raise InputError(f"{name} must be one of {allowed}, got {value!r}") from None


@dataclass(frozen=True)
class StageBackend:
    """How the stage model is evaluated (see :class:`~auvplan.optimization.ProntoOptions`).

    ``stage_kernels``: compiled per-block kernels when the problem is separable;
    ``compile_c``: C-compiled CasADi functions otherwise; ``n_threads``: threads of the stage
    evaluations.
    """

    stage_kernels: bool = True
    compile_c: bool = False
    n_threads: int = 1


@dataclass(frozen=True)
class ProntoOptions:
    """Options of :func:`~auvplan.optimization.pronto.solve_pronto`.

    Attributes
    ----------
    tol, rtol : float
        Stop when ``−Dh·ζ < max(tol, rtol |h|)`` at the final barrier level (``tol`` in cost
        units; ``−Dh·ζ ≈ 2 (h − h*)`` near a minimiser, so ``rtol`` bounds the relative
        error of the objective by about ``rtol / 2``).
    inner_tol, inner_rtol : float
        Same test at intermediate barrier levels, whose minimisers only start the next level.
    max_iter : int
        Maximum number of PRONTO iterations (directions computed) over all levels.
    alpha, beta : float
        Armijo sufficient-decrease and backtracking factors.
    max_backtracks : int
        Maximum number of step reductions per line search.
    eps_initial, eps_final, eps_factor : float
        Barrier weight continuation ``ε ← eps_factor · ε`` from ``eps_initial`` down to
        ``eps_final`` (the last level is exactly ``eps_final``).
    delta_initial : float
        Initial barrier switching point ``δ`` (keep it larger than the worst initial
        violation of the scaled slacks).
    delta_feasible_factor : float
        Once strictly feasible: ``δ ← min(δ, delta_feasible_factor · min z, delta_feasible_max)``
        with ``z`` the barrier arguments.
    delta_feasible_max : float
        Cap on ``δ`` once feasible.
    max_infeasible_restarts : int
        How often a barrier level is re-solved with a smaller ``δ`` when it ends infeasible.
    eigenvalue_floor : float
        Smallest eigenvalue kept by the convexified model (per stage, relative to ``dt``).
    terminal_regulator : TerminalRegulator or {"dare", "weight"}
        Terminal matrix of the projection regulator: discrete ARE at the last stage (falls
        back to ``Q_r`` when it fails), or ``Q_r``. Strings are converted to the enum.
    n_threads : int
        Threads for the batched stage evaluations; 1 = serial. The compiled kernels split
        their points (vehicle-stages) over them, the convexified model's stages are clipped
        and independent vehicles' regulators designed on them, with the same results for any
        number; CasADi evaluates with ``map(N, "thread", n)``.
    stage_kernels : bool
        Evaluate a separable problem (``TrajectoryProblem.blocks``) with compiled per-block
        kernels (numba; compiled once per vehicle model and cached on disk, 10–25x faster
        than CasADi's virtual machine); False evaluates the stacked CasADi functions.
    compile_c : bool
        Without stage kernels: evaluate C-compiled CasADi stage functions (compiled once per
        model and cached on disk; needs a C compiler, else the CasADi VM is used).
    fallback_model : FallbackModel or {"newton", "cost"}
        Which weights the convexified fallback clips: the exact Newton weights (default; no
        extra evaluation) or the cost Hessians only (quasi-Newton, one more Hessian pass).
    """

    tol: float = 1e-6
    rtol: float = 1e-6
    inner_tol: float = 1e-4
    inner_rtol: float = 1e-6
    max_iter: int = 200
    alpha: float = 0.4
    beta: float = 0.7
    max_backtracks: int = 30
    eps_initial: float = 1.0
    eps_final: float = 1e-4
    eps_factor: float = 0.1
    delta_initial: float = 0.5
    delta_feasible_factor: float = 0.1
    delta_feasible_max: float = 1e-3
    max_infeasible_restarts: int = 10
    eigenvalue_floor: float = 1e-2
    terminal_regulator: TerminalRegulator | Literal["dare", "weight"] = TerminalRegulator.DARE
    n_threads: int = 1
    stage_kernels: bool = True
    compile_c: bool = False
    fallback_model: FallbackModel | Literal["newton", "cost"] = FallbackModel.NEWTON

    def __post_init__(self) -> None:
        checks = {
            "tol": self.tol > 0,
            "inner_tol": self.inner_tol > 0,
            "rtol": self.rtol >= 0,
            "inner_rtol": self.inner_rtol >= 0,
            "max_iter": self.max_iter >= 1,
            "alpha": 0 < self.alpha < 1,
            "beta": 0 < self.beta < 1,
            "max_backtracks": self.max_backtracks >= 1,
            "eps_initial": self.eps_initial > 0,
            "eps_final": 0 < self.eps_final <= self.eps_initial,
            "eps_factor": 0 < self.eps_factor < 1,
            "delta_initial": self.delta_initial > 0,
            "delta_feasible_factor": 0 < self.delta_feasible_factor < 1,
            "delta_feasible_max": self.delta_feasible_max > 0,
            "eigenvalue_floor": self.eigenvalue_floor > 0,
            "n_threads": self.n_threads >= 1,
        }
        for name, ok in checks.items():
            if not ok:
                raise InputError(f"ProntoOptions.{name} is out of range: {getattr(self, name)!r}")
        terminal = named_choice(
            TerminalRegulator, self.terminal_regulator, "ProntoOptions.terminal_regulator"
        )
        fallback = named_choice(FallbackModel, self.fallback_model, "ProntoOptions.fallback_model")
        object.__setattr__(self, "terminal_regulator", terminal)
        object.__setattr__(self, "fallback_model", fallback)

    @property
    def backend(self) -> StageBackend:
        """How the stage model is evaluated (``stage_kernels``, ``compile_c``, ``n_threads``)."""
        return StageBackend(self.stage_kernels, self.compile_c, self.n_threads)

    def epsilon_levels(self) -> tuple[float, ...]:
        """The barrier weights visited by the continuation, largest first."""
        levels = [self.eps_initial]
        while levels[-1] * self.eps_factor > self.eps_final * (1.0 + 1e-12):
            levels.append(levels[-1] * self.eps_factor)
        if levels[-1] != self.eps_final:
            levels.append(self.eps_final)
        return tuple(levels)
