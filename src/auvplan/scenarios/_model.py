r"""An independent plain-numpy MEDUSA model, to check plans against (not ``auvplan.vehicle``).

Written from ``reference/vehicle.md`` §1 and §3 and the vehicle file's numbers, with the same
smoothing the vehicle file declares (SPEC §3), so that it agrees with the planner's model to
rounding when the planner is right::

    ṅorth = u cos ψ − v sin ψ,   ėast = u sin ψ + v cos ψ,   ψ̇ = r
    m_u u̇ = m_v v r + (X_u + X_|u|u |u|_ε) u + T_ps + T_sb
    m_v v̇ = −m_u u r + (Y_v + Y_|v|v |v|_ε) v
    m_r ṙ = (m_u − m_v) u v + (N_r + N_|r|r |r|_ε) r + l (T_ps − T_sb)
    ṅ_ps = w_c tanh(c_ps),       ṅ_sb = w_c tanh(c_sb)

with ``m_u = m − X_u̇``, ``m_v = m − Y_v̇``, ``m_r = I_z − N_ṙ``, ``|s|_ε = sqrt(s² + ε²)``,
advance speeds ``v_a = u ± l r`` (port +, starboard −), and the four-quadrant thrust in its
smoothed form, evaluated with ``atan2`` (the planner uses an angle-addition recurrence)::

    v_p = 0.7 π n D,   S = v_a² + v_p²,   V² = S + ε_V²,   ρ = sqrt(S) / V,   β = atan2(v_a, v_p)
    T = c_T ½ ρ_w π R² [A_T[0] S + V² Σ_{k=1}^{K} ρ^k (A_T[k] cos kβ + B_T[k] sin kβ)]
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any, Final

import numpy as np
from scipy.integrate import solve_ivp

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.ocean import CurrentField
from auvplan.vehicle.params import (
    DEFAULT_EPS_ABS_RATE,
    DEFAULT_EPS_ABS_SPEED,
    DEFAULT_EPS_INFLOW,
)

#: Integration tolerances of the reference flow (relative and absolute).
INTEGRATION_TOLERANCE: Final = 1e-10
#: Steps integrated together in one ``solve_ivp`` call.
BATCH_STEPS: Final = 50

#: Keys read from the vehicle file: (section, key, unit).
_KEYS: Final = (
    ("hull", "m", "kg"), ("hull", "I_z", "kg m^2"), ("hull", "X_udot", "kg"),
    ("hull", "Y_vdot", "kg"), ("hull", "N_rdot", "kg m^2"), ("hull", "X_u", "kg/s"),
    ("hull", "Y_v", "kg/s"), ("hull", "N_r", "kg m^2/s"), ("hull", "X_uu", "kg/m"),
    ("hull", "Y_vv", "kg/m"), ("hull", "N_rr", "kg m^2"), ("hull", "rho", "kg/m^3"),
    ("propulsion", "l", "m"), ("propulsion", "w_c", "rev/s^2"),
    ("propeller", "diameter", "m"), ("propeller", "c_T", "1"),
)  # fmt: skip
#: Smoothing keys, units and the values used when the vehicle file omits them.
_SMOOTHING: Final = {
    "inflow": ("m/s", DEFAULT_EPS_INFLOW),
    "abs_speed": ("m/s", DEFAULT_EPS_ABS_SPEED),
    "abs_rate": ("rad/s", DEFAULT_EPS_ABS_RATE),
}


@dataclass(frozen=True)
class MedusaModel:
    """Parameters of the independent model (SI units, propeller speeds in rev/s)."""

    m_u: float
    m_v: float
    m_r: float
    X_u: float
    Y_v: float
    N_r: float
    X_uu: float
    Y_vv: float
    N_rr: float
    l: float  # noqa: E741  (the paper's symbol)
    w_c: float
    diameter: float
    thrust_scale: float
    """``c_T ½ ρ_w π R²`` [kg/m]."""
    A_T: FloatArray
    B_T: FloatArray
    eps_inflow: float
    eps_abs_speed: float
    eps_abs_rate: float

    def thrust(self, advance_speed: FloatArray, n: FloatArray) -> FloatArray:
        """Smoothed four-quadrant thrust [N] of one propeller (module docstring)."""
        v_p = 0.7 * math.pi * n * self.diameter
        speed_sq = advance_speed**2 + v_p**2
        inflow_sq = speed_sq + self.eps_inflow**2
        ratio = np.sqrt(speed_sq / inflow_sq)
        beta = np.arctan2(advance_speed, v_p)
        series = self.A_T[0] * speed_sq
        for k in range(1, self.A_T.size):
            series = series + inflow_sq * ratio**k * (
                self.A_T[k] * np.cos(k * beta) + self.B_T[k] * np.sin(k * beta)
            )
        return np.asarray(self.thrust_scale * series, dtype=np.float64)

    def derivative(self, states: FloatArray, inputs: FloatArray) -> FloatArray:
        """``ẋ = f(x, c)`` for states ``(..., 8)`` and inputs ``(..., 2)``; shape ``(..., 8)``."""
        psi, u, v, r, n_ps, n_sb = (states[..., k] for k in range(2, 8))
        thrust_ps = self.thrust(u + self.l * r, n_ps)
        thrust_sb = self.thrust(u - self.l * r, n_sb)
        abs_u = np.sqrt(u**2 + self.eps_abs_speed**2)
        abs_v = np.sqrt(v**2 + self.eps_abs_speed**2)
        abs_r = np.sqrt(r**2 + self.eps_abs_rate**2)
        u_dot = (
            self.m_v * v * r + (self.X_u + self.X_uu * abs_u) * u + thrust_ps + thrust_sb
        ) / self.m_u
        v_dot = (-self.m_u * u * r + (self.Y_v + self.Y_vv * abs_v) * v) / self.m_v
        r_dot = (
            (self.m_u - self.m_v) * u * v
            + (self.N_r + self.N_rr * abs_r) * r
            + self.l * (thrust_ps - thrust_sb)
        ) / self.m_r
        return np.stack(
            [
                u * np.cos(psi) - v * np.sin(psi),
                u * np.sin(psi) + v * np.cos(psi),
                r,
                u_dot,
                v_dot,
                r_dot,
                self.w_c * np.tanh(inputs[..., 0]),
                self.w_c * np.tanh(inputs[..., 1]),
            ],
            axis=-1,
        )


def _quantity(document: Mapping[str, Any], section: str, key: str, unit: str) -> float:
    entry = document.get(section, {}).get(key)
    if not isinstance(entry, Mapping) or "value" not in entry:
        raise DataFormatError(f"vehicle file: missing {section}.{key} = {{ value, unit }}")
    if entry.get("unit") != unit:
        raise DataFormatError(
            f"vehicle file: {section}.{key} must be in {unit!r} for the check, "
            f"got {entry.get('unit')!r}"
        )
    return float(entry["value"])


def _read_text(name: str, kind: str, suffix: str, base_dirs: tuple[Path, ...]) -> tuple[str, Path]:
    """Text of a packaged data file ``data/<kind>/<name><suffix>`` or of a file ``name``."""
    packaged = resources.files("auvplan").joinpath("data", kind, f"{name}{suffix}")
    if "/" not in name and packaged.is_file():
        return packaged.read_text(encoding="utf-8"), Path()
    for base in base_dirs:
        path = base / name
        if path.is_file():
            return path.read_text(encoding="utf-8"), path.parent
    raise InputError(f"{kind[:-1]} {name!r} is neither packaged nor a file")


def read_medusa_model(
    vehicle_type: str, *, propeller_order: int | None, base_dirs: tuple[Path, ...] = (Path(),)
) -> MedusaModel:
    """The independent model of a vehicle type (packaged name or vehicle-file path).

    ``propeller_order`` is the solver's setting (capped at the table's order); None uses the
    vehicle file's ``propeller.order`` or the whole table, as the planner does. File paths
    are tried relative to each of ``base_dirs``.
    """
    text, vehicle_dir = _read_text(vehicle_type, "vehicles", ".toml", base_dirs)
    document = tomllib.loads(text)
    values = {f"{s}.{k}": _quantity(document, s, k, unit) for s, k, unit in _KEYS}
    smoothing = {
        key: _quantity(document, "smoothing", key, unit)
        if key in document.get("smoothing", {})
        else default
        for key, (unit, default) in _SMOOTHING.items()
    }
    propeller = document["propeller"]
    table_text, _ = _read_text(str(propeller["table"]), "propellers", ".csv", (vehicle_dir,))
    rows = [line for line in table_text.splitlines() if line.strip() and not line.startswith("#")]
    table = np.array([[float(v) for v in row.split(",")] for row in rows[1:]])
    max_order = table.shape[0] - 1
    order = propeller_order if propeller_order is not None else propeller.get("order", max_order)
    order = min(int(order), max_order)
    radius = 0.5 * values["propeller.diameter"]
    return MedusaModel(
        m_u=values["hull.m"] - values["hull.X_udot"],
        m_v=values["hull.m"] - values["hull.Y_vdot"],
        m_r=values["hull.I_z"] - values["hull.N_rdot"],
        X_u=values["hull.X_u"],
        Y_v=values["hull.Y_v"],
        N_r=values["hull.N_r"],
        X_uu=values["hull.X_uu"],
        Y_vv=values["hull.Y_vv"],
        N_rr=values["hull.N_rr"],
        l=values["propulsion.l"],
        w_c=values["propulsion.w_c"],
        diameter=values["propeller.diameter"],
        thrust_scale=values["propeller.c_T"] * 0.5 * values["hull.rho"] * math.pi * radius**2,
        A_T=table[: order + 1, 1].copy(),
        B_T=table[: order + 1, 2].copy(),
        eps_inflow=smoothing["inflow"],
        eps_abs_speed=smoothing["abs_speed"],
        eps_abs_rate=smoothing["abs_rate"],
    )


def _scaled_derivative(
    s: float,
    y: FloatArray,
    model: MedusaModel,
    duration: FloatArray,
    held: FloatArray,
    start: FloatArray,
    current: CurrentField | None,
) -> FloatArray:
    """``dx/ds = h_k f(x, c_k)``: each step's time normalised to ``s`` in [0, 1].

    In a current the position also moves with the water: ``(ṅ, ė) += v_c(n, e, t_k + s h_k)``.
    """
    states = y.reshape(-1, 8)
    rates = model.derivative(states, held)
    if current is not None:
        time = start[:, 0] + s * duration[:, 0]
        v_n, v_e = current.velocity(states[:, 0], states[:, 1], time)
        rates[:, 0] += v_n
        rates[:, 1] += v_e
    return (duration * rates).ravel()


def step_defects(
    model: MedusaModel,
    time: FloatArray,
    states: FloatArray,
    inputs: FloatArray,
    current: CurrentField | None = None,
) -> FloatArray:
    """Per-step defect of a sampled trajectory against the model's exact flow.

    Step ``k`` integrates ``ẋ = f(x, c_k)`` from ``states[k]`` over ``[time[k], time[k+1]]``
    with the input held (``solve_ivp``, DOP853, rtol = atol = :data:`INTEGRATION_TOLERANCE`)
    and returns ``states[k + 1] − x(time[k + 1])`` (heading wrapped to ``(−π, π]``).

    Parameters
    ----------
    model : MedusaModel
    time : ndarray of shape (n_t,)
        Sample times [s].
    states : ndarray of shape (n_t, 8)
        Planned states.
    inputs : ndarray of shape (n_t - 1, 2)
        Inputs held over each step.
    current : CurrentField, optional
        The true current field (not the optimiser's linearisation); ``u, v`` are then speeds
        through the water.

    Returns
    -------
    ndarray of shape (n_t - 1, 8)
        Defects in the states' units.
    """
    steps = np.diff(time)
    defects = np.empty((steps.size, 8))
    for first in range(0, steps.size, BATCH_STEPS):
        batch = slice(first, min(first + BATCH_STEPS, steps.size))

        solution = solve_ivp(
            _scaled_derivative,
            (0.0, 1.0),
            states[batch].ravel(),
            method="DOP853",
            rtol=INTEGRATION_TOLERANCE,
            atol=INTEGRATION_TOLERANCE,
            args=(model, steps[batch, None], inputs[batch], time[batch, None], current),
        )
        if not solution.success:
            raise RuntimeError(f"reference integration failed: {solution.message}")
        defects[batch] = states[batch.start + 1 : batch.stop + 1] - solution.y[:, -1].reshape(-1, 8)
    defects[:, 2] = np.angle(np.exp(1j * defects[:, 2]))
    return defects
