r"""Approximate log barrier ``β_δ`` (k = 2), hockey stick ``σ`` and their composition.

The only place where these functions and their derivatives are written (STYLE B2).

Approximate log barrier (Hauser & Saccon 2006), ``k = 2``:

.. math::

    β_δ(z) = \begin{cases} -\log z & z > δ \\
             \tfrac12\left(\left(\tfrac{z - 2δ}{δ}\right)^2 - 1\right) - \log δ & z \le δ
             \end{cases}

It is C² and convex (value, ``β' = -1/δ`` and ``β'' = 1/δ²`` agree at ``z = δ``) and finite
for infeasible arguments ``z ≤ 0``, so an infeasible trajectory has a finite penalty.

Hockey stick: ``σ(s) = tanh(s)`` for ``s > 0`` and ``σ(s) = s`` for ``s ≤ 0``. It is C² at 0,
so ``β_δ ∘ σ`` is C²; ``-log(tanh s) → 0`` as ``s → ∞``, so the barrier vanishes far from a
non-convex constraint instead of rewarding distance.

References
----------
J. Hauser, A. Saccon, "A barrier function method for the optimization of trajectory
functionals with constraints", IEEE CDC 2006. See also ``reference/pronto.md`` §7.
"""

from __future__ import annotations

import enum
from typing import Any

import casadi as ca
import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError

__all__ = [
    "BarrierKind",
    "barrier_and_argument",
    "barrier_expression",
    "composed_barrier",
    "hockey_stick",
    "log_barrier",
]


class BarrierKind(enum.StrEnum):
    """How a path constraint's scaled slack ``s`` enters the barrier."""

    PLAIN = "plain"
    """``β_δ(s)``: convex constraints such as input bounds."""
    HOCKEY = "hockey"
    """``β_δ(σ(s))``: non-convex constraints (separations); vanishes far from the boundary."""


def _check_delta(delta: float) -> None:
    if not delta > 0.0:
        raise InputError(f"barrier delta must be > 0, got {delta!r}")


def log_barrier(z: FloatArray, delta: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Approximate log barrier ``β_δ(z)`` and its first and second derivatives.

    Parameters
    ----------
    z : ndarray
        Barrier argument (any shape); feasible when ``z > 0``.
    delta : float
        Switching point ``δ > 0`` between ``-log z`` and the quadratic extension.

    Returns
    -------
    value, first, second : ndarray
        ``β_δ(z)``, ``β'_δ(z)``, ``β''_δ(z)``, same shape as ``z``.

    Raises
    ------
    InputError
        If ``delta <= 0``.

    Examples
    --------
    >>> import numpy as np
    >>> value, first, second = log_barrier(np.array([2.0, 0.5]), 0.5)
    >>> np.round(value, 6).tolist(), first.tolist(), second.tolist()
    ([-0.693147, 0.693147], [-0.5, -2.0], [0.25, 4.0])
    """
    _check_delta(delta)
    z = np.asarray(z, dtype=np.float64)
    is_log = z > delta
    z_log = np.where(is_log, z, 1.0)  # avoids log of non-positive numbers in the masked branch
    w = (z - 2.0 * delta) / delta
    value = np.where(is_log, -np.log(z_log), 0.5 * (w * w - 1.0) - np.log(delta))
    first = np.where(is_log, -1.0 / z_log, w / delta)
    second = np.where(is_log, 1.0 / (z_log * z_log), 1.0 / (delta * delta))
    return value, first, second


def hockey_stick(slack: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Hockey stick ``σ(s)`` (``tanh s`` above 0, identity below) and its derivatives.

    Examples
    --------
    >>> import numpy as np
    >>> [v.tolist() for v in hockey_stick(np.array([-1.0, 0.0]))]
    [[-1.0, 0.0], [1.0, 1.0], [0.0, 0.0]]
    """
    s = np.asarray(slack, dtype=np.float64)
    t = np.tanh(np.maximum(s, 0.0))
    positive = s > 0.0
    value = np.where(positive, t, s)
    first = np.where(positive, 1.0 - t * t, 1.0)
    second = np.where(positive, -2.0 * t * (1.0 - t * t), 0.0)
    return value, first, second


def composed_barrier(
    slack: FloatArray, delta: float, *, is_hockey: bool
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Barrier of a slack, ``b(s) = β_δ(σ(s))`` (or ``β_δ(s)``), with ``b'`` and ``b''``.

    Chain rule: ``b' = β'(σ) σ'``, ``b'' = β''(σ) σ'² + β'(σ) σ''``.

    Parameters
    ----------
    slack : ndarray
        Scaled constraint values ``s = c / scale`` (feasible when ``s > 0``).
    delta : float
        Barrier switching point.
    is_hockey : bool
        Compose with the hockey stick (non-convex constraints) or use ``s`` directly.

    Returns
    -------
    value, first, second : ndarray
        ``b(s)``, ``db/ds``, ``d²b/ds²``.

    Examples
    --------
    >>> import numpy as np
    >>> value, _, _ = composed_barrier(np.array([30.0]), 1e-3, is_hockey=True)
    >>> bool(abs(value[0]) < 1e-12)
    True
    """
    value, first, second, _ = barrier_and_argument(slack, delta, is_hockey=is_hockey)
    return value, first, second


def barrier_and_argument(
    slack: FloatArray, delta: float, *, is_hockey: bool
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """:func:`composed_barrier` and the log barrier's argument ``z`` (``σ(s)`` or ``s``)."""
    if not is_hockey:
        return (*log_barrier(slack, delta), np.asarray(slack, dtype=np.float64))
    z, dz, ddz = hockey_stick(slack)
    value, first, second = log_barrier(z, delta)
    return value, first * dz, second * dz * dz + first * ddz, z


def barrier_expression(slack: Any, delta: float, *, is_hockey: bool) -> Any:
    """The same ``β_δ(σ(s))`` as a CasADi expression (SX or MX), for the IPOPT bridge.

    Parameters
    ----------
    slack : casadi.SX or casadi.MX
        Symbolic scaled slack (any shape; the barrier is applied element-wise).
    delta : float
        Barrier switching point.
    is_hockey : bool
        Compose with the hockey stick.

    Returns
    -------
    casadi.SX or casadi.MX
        Element-wise barrier values, same shape as ``slack``.
    """
    _check_delta(delta)
    z = ca.if_else(slack > 0, ca.tanh(slack), slack) if is_hockey else slack
    w = (z - 2.0 * delta) / delta
    quadratic = 0.5 * (w * w - 1.0) - np.log(delta)
    return ca.if_else(z > delta, -ca.log(ca.fmax(z, delta)), quadratic)
