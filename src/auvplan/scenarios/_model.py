r"""An independent plain-numpy vehicle model, to check plans against (not ``auvplan.vehicle``).

Written from ``reference/vehicle.md`` §1 and §3, Fossen (2021) and the vehicle file's numbers
(read by :mod:`auvplan.scenarios._vehicle_file`), with the same smoothing the vehicle file
declares (SPEC §3), so that it agrees with the planner's model to rounding when the planner is
right. State ``(north, east, ψ, u, v, r, n_<thruster>…, delta_<surface>…)``, input
``(c_<thruster>…, c_<surface>…)``::

    ṅorth = u cos ψ − v sin ψ,   ėast = u sin ψ + v cos ψ,   ψ̇ = r
    m_u u̇ = m'_v v r − d_u u + Σ X
    m_v v̇ = −m'_u u r − d_v v + Σ Y
    m_r ṙ = (m'_u − m'_v) u v − d_r r + Σ N
    ṅ_i = w_c,i tanh(c_i),       δ̇_j = w_δ,j tanh(c_j)

with ``m_u = m − X_u̇`` (likewise ``m_v``, ``m_r``), the Coriolis masses ``m'_u, m'_v`` equal to
``m_u, m_v`` (or ``m`` when the file leaves the added-mass Coriolis out), damping
``d_u = −X_u f − X_|u|u |u|_ε``, ``d_v = −Y_v f − Y_|v|v |v|_ε``, ``d_r = −N_r − N_|r|r |r|_ε``,
``f = exp(−κ sqrt(u² + v² + ε²))`` and ``|s|_ε = sqrt(s² + ε²)``. The forces ``(X, Y, N)``:

- thruster at ``(x, y)``, axis ``α``: advance speed ``v_a = (1 − w)(cα (u − y r) + sα (v + x r))``,
  force ``(1 − t) T (cα, sα, x sα − y cα)``. Four-quadrant thrust, evaluated with ``atan2``
  (the planner uses an angle-addition recurrence): ``v_p = 0.7 π n D``, ``S = v_a² + v_p²``,
  ``V² = S + ε_V²``, ``ρ = sqrt(S)/V``, ``β = atan2(v_a, v_p)``,
  ``T = c_T ½ ρ_w π R² [A_T[0] S + V² Σ_k ρ^k (A_T[k] cos kβ + B_T[k] sin kβ)]``; linear
  open-water thrust ``T = ρ_w D⁴ (K_T0 n |n|_ε + K_T' (v_a/D) |n|_ε)``;
- control surface at ``(x, y)``: ``q = ½ ρ_w (u² + v²) A``, lift ``Y = −q C_Lδ δ``, drag
  ``X = −q C_Dδ δ²``, ``N = x Y − y X``;
- cross-flow strips ``x_k``: ``Y = −½ρ_w H C_d (L/n) Σ_k |v + x_k r|_ε (v + x_k r)``, ``N`` the
  same sum weighted by ``x_k``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

import numpy as np
from scipy.integrate import solve_ivp

from auvplan._typing import FloatArray
from auvplan.ocean import CurrentField

#: Integration tolerances of the reference flow (relative and absolute).
INTEGRATION_TOLERANCE: Final = 1e-10
#: Steps integrated together in one ``solve_ivp`` call.
BATCH_STEPS: Final = 50
#: The pose and body-velocity states every vehicle starts with.
BODY_STATES: Final = ("north", "east", "psi", "u", "v", "r")


@dataclass(frozen=True)
class FourQuadrantPropeller:
    """Smoothed four-quadrant propeller: ``thrust_scale = c_T ½ ρ_w π R²`` [kg/m]."""

    diameter: float
    thrust_scale: float
    A_T: FloatArray
    B_T: FloatArray
    eps_inflow: float

    def thrust(self, advance_speed: FloatArray, n: FloatArray) -> FloatArray:
        """Thrust [N] at advance speed [m/s] and propeller speed [rev/s] (module notes)."""
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


@dataclass(frozen=True)
class LinearPropeller:
    """Open-water propeller with ``K_T`` linear in ``J`` (``slope = dK_T/dJ``)."""

    rho: float
    diameter: float
    K_T0: float
    slope: float
    eps_n: float

    def thrust(self, advance_speed: FloatArray, n: FloatArray) -> FloatArray:
        """Thrust [N] at advance speed [m/s] and propeller speed [rev/s] (module notes)."""
        abs_n = np.sqrt(n**2 + self.eps_n**2)
        inflow = advance_speed / self.diameter * abs_n
        return np.asarray(
            self.rho * self.diameter**4 * (self.K_T0 * n * abs_n + self.slope * inflow),
            dtype=np.float64,
        )


@dataclass(frozen=True)
class Thruster:
    """A propeller at ``(x, y)`` [m] pushing along ``axis`` [rad]; ``n_max`` [rev/s]."""

    name: str
    x: float
    y: float
    axis: float
    wake_fraction: float
    thrust_deduction: float
    n_max: float
    w_c: float
    propeller: FourQuadrantPropeller | LinearPropeller


@dataclass(frozen=True)
class Surface:
    """A rudder at ``(x, y)`` [m]: area [m²], slopes [1/rad, 1/rad²], limits [rad, rad/s]."""

    name: str
    x: float
    y: float
    area: float
    lift_slope: float
    drag_slope: float
    delta_max: float
    rate_max: float


@dataclass(frozen=True)
class ReferenceModel:
    """Parameters of the independent model (SI units, propeller speeds in rev/s).

    ``crossflow_scale`` is ``−½ ρ_w H C_d L / n`` [kg/m²] over the ``stations`` [m] (none
    without cross-flow drag); ``damping_fade`` is ``κ`` [s/m].
    """

    m_u: float
    m_v: float
    m_r: float
    coriolis_u: float
    coriolis_v: float
    X_u: float
    Y_v: float
    N_r: float
    X_uu: float
    Y_vv: float
    N_rr: float
    rho: float
    damping_fade: float
    crossflow_scale: float
    stations: FloatArray
    thrusters: tuple[Thruster, ...]
    surfaces: tuple[Surface, ...]
    eps_abs_speed: float
    eps_abs_rate: float

    @property
    def state_names(self) -> tuple[str, ...]:
        """``north, east, psi, u, v, r``, ``n_<thruster>``…, ``delta_<surface>``…."""
        return (
            *BODY_STATES,
            *(f"n_{thruster.name}" for thruster in self.thrusters),
            *(f"delta_{surface.name}" for surface in self.surfaces),
        )

    @property
    def input_names(self) -> tuple[str, ...]:
        """``c_<thruster>``…, ``c_<surface>``…."""
        names = [thruster.name for thruster in self.thrusters]
        return tuple(f"c_{name}" for name in names + [surface.name for surface in self.surfaces])

    @property
    def limits(self) -> dict[str, float]:
        """``|x| <= limit`` by state name: ``n_max`` [rev/s] and ``delta_max`` [rad]."""
        return {
            **{f"n_{t.name}": t.n_max for t in self.thrusters},
            **{f"delta_{s.name}": s.delta_max for s in self.surfaces},
        }

    def derivative(self, states: FloatArray, inputs: FloatArray) -> FloatArray:
        """``ẋ = f(x, c)`` for states ``(..., n_x)`` and inputs ``(..., n_u)`` (module notes)."""
        psi, u, v, r = (states[..., k] for k in range(2, 6))
        forces = [np.zeros_like(u), np.zeros_like(u), np.zeros_like(u)]
        for k, thruster in enumerate(self.thrusters):
            cos_a, sin_a = math.cos(thruster.axis), math.sin(thruster.axis)
            axial = cos_a * (u - thruster.y * r) + sin_a * (v + thruster.x * r)
            advance = (1.0 - thruster.wake_fraction) * axial
            thrust = (1.0 - thruster.thrust_deduction) * thruster.propeller.thrust(
                advance, states[..., 6 + k]
            )
            forces[0] = forces[0] + cos_a * thrust
            forces[1] = forces[1] + sin_a * thrust
            forces[2] = forces[2] + (thruster.x * sin_a - thruster.y * cos_a) * thrust
        for j, surface in enumerate(self.surfaces):
            delta = states[..., 6 + len(self.thrusters) + j]
            pressure = 0.5 * self.rho * (u**2 + v**2) * surface.area
            lift = -pressure * surface.lift_slope * delta
            drag = -pressure * surface.drag_slope * delta**2
            forces[0] = forces[0] + drag
            forces[1] = forces[1] + lift
            forces[2] = forces[2] + surface.x * lift - surface.y * drag
        for station in self.stations:
            local = v + station * r
            drag = self.crossflow_scale * np.sqrt(local**2 + self.eps_abs_speed**2) * local
            forces[1] = forces[1] + drag
            forces[2] = forces[2] + station * drag
        fade = np.exp(-self.damping_fade * np.sqrt(u**2 + v**2 + self.eps_abs_speed**2))
        d_u = -self.X_u * fade - self.X_uu * np.sqrt(u**2 + self.eps_abs_speed**2)
        d_v = -self.Y_v * fade - self.Y_vv * np.sqrt(v**2 + self.eps_abs_speed**2)
        d_r = -self.N_r - self.N_rr * np.sqrt(r**2 + self.eps_abs_rate**2)
        u_dot = (self.coriolis_v * v * r - d_u * u + forces[0]) / self.m_u
        v_dot = (-self.coriolis_u * u * r - d_v * v + forces[1]) / self.m_v
        r_dot = ((self.coriolis_u - self.coriolis_v) * u * v - d_r * r + forces[2]) / self.m_r
        rates = [t.w_c for t in self.thrusters] + [s.rate_max for s in self.surfaces]
        return np.stack(
            [
                u * np.cos(psi) - v * np.sin(psi),
                u * np.sin(psi) + v * np.cos(psi),
                r,
                u_dot,
                v_dot,
                r_dot,
                *(rate * np.tanh(inputs[..., k]) for k, rate in enumerate(rates)),
            ],
            axis=-1,
        )


def _scaled_derivative(
    s: float,
    y: FloatArray,
    model: ReferenceModel,
    duration: FloatArray,
    held: FloatArray,
    start: FloatArray,
    current: CurrentField | None,
) -> FloatArray:
    """``dx/ds = h_k f(x, c_k)``: each step's time normalised to ``s`` in [0, 1].

    In a current the position also moves with the water: ``(ṅ, ė) += v_c(n, e, t_k + s h_k)``.
    """
    states = y.reshape(held.shape[0], -1)
    rates = model.derivative(states, held)
    if current is not None:
        time = start[:, 0] + s * duration[:, 0]
        v_n, v_e = current.velocity(states[:, 0], states[:, 1], time)
        rates[:, 0] += v_n
        rates[:, 1] += v_e
    return (duration * rates).ravel()


def step_defects(
    model: ReferenceModel,
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
    model : ReferenceModel
    time : ndarray of shape (n_t,)
        Sample times [s].
    states : ndarray of shape (n_t, n_x)
        Planned states, in the order of ``model.state_names``.
    inputs : ndarray of shape (n_t - 1, n_u)
        Inputs held over each step.
    current : CurrentField, optional
        The true current field (not the optimiser's linearisation); ``u, v`` are then speeds
        through the water.

    Returns
    -------
    ndarray of shape (n_t - 1, n_x)
        Defects in the states' units.
    """
    steps = np.diff(time)
    n_x = states.shape[1]
    defects = np.empty((steps.size, n_x))
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
        flown = solution.y[:, -1].reshape(-1, n_x)
        defects[batch] = states[batch.start + 1 : batch.stop + 1] - flown
    defects[:, 2] = np.angle(np.exp(1j * defects[:, 2]))
    return defects
