"""Typed, immutable parameter sets of a planar vehicle: hull, propellers, motors.

A vehicle type is data (a TOML file read by :func:`auvplan.io.load_vehicle`); this module
only holds the validated numbers. Every field states its unit; signs follow Fossen (2021):
added-mass and damping derivatives are negative. :class:`VehicleParams` is the twin-thruster
shorthand (MEDUSA class); any other layout of thrusters and control surfaces is an
:class:`auvplan.vehicle.actuators.ActuatedVehicleParams`.

References
----------
.. [1] T. I. Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed.,
   Wiley 2021, ch. 6 (eqs. 6.2, 6.43-6.46) and ch. 9 (propellers).
.. [2] R. F. Roddy, D. E. Hess, W. Faller, "Neural network predictions of the 4-quadrant
   Wageningen propeller series", NSWCCD-50-TR-2006/004, 2006.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Final, Literal, Protocol

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.vehicle.vertical import DepthLimits

#: Default smoothing speed of the propeller inflow ``V_r = sqrt(v_a² + v_p² + ε_V²)`` [m/s].
DEFAULT_EPS_INFLOW: Final = 0.02
#: Default smoothing of ``|u|`` and ``|v|`` in the quadratic damping [m/s].
DEFAULT_EPS_ABS_SPEED: Final = 0.01
#: Default smoothing of ``|r|`` in the quadratic yaw damping [rad/s].
DEFAULT_EPS_ABS_RATE: Final = 0.01
#: Default smoothing of ``sign(n)`` (no-load current, measured current curve) [rev/s].
DEFAULT_EPS_SIGN_N: Final = 0.5

CurrentModel = Literal["torque", "measured"]


def _finite(name: str, value: float, *, positive: bool = False, nonnegative: bool = False) -> None:
    if not math.isfinite(value):
        raise InputError(f"vehicle parameter {name} must be finite, got {value!r}")
    if positive and value <= 0.0:
        raise InputError(f"vehicle parameter {name} must be > 0, got {value!r}")
    if nonnegative and value < 0.0:
        raise InputError(f"vehicle parameter {name} must be >= 0, got {value!r}")


def _frozen_vector(name: str, values: FloatArray | list[float] | tuple[float, ...]) -> FloatArray:
    array = np.array(values, dtype=np.float64)
    if array.ndim != 1 or array.size == 0 or not np.all(np.isfinite(array)):
        raise InputError(f"vehicle parameter {name} must be a non-empty finite 1-D array")
    array.setflags(write=False)
    return array


@dataclass(frozen=True)
class CrossFlowParams:
    """Cross-flow drag of a slender hull by strip theory (Fossen 2021, sec. 6.7).

    ``Y = -½ρ H C_d Δx Σ_k |v + x_k r| (v + x_k r)``, ``N = -½ρ H C_d Δx Σ_k x_k |…| (…)``
    over the stations ``x_k = -L/2 + k Δx``, ``k = 0..n``, ``Δx = L/n``: the ``n + 1``
    stations of width ``Δx`` of Fossen's ``crossFlowDrag`` (the end stations count in full,
    as in the calibration of the models that use it).
    """

    length: float
    """Hull length ``L`` [m]."""
    height: float
    """Projected height (draft) ``H`` of the hull seen from the side [m]."""
    drag_coefficient: float
    """Two-dimensional cross-flow drag coefficient ``C_d`` (Hoerner's curve) [-]."""
    strips: int
    """Number of strips ``n`` (``n + 1`` stations) [-]."""

    def __post_init__(self) -> None:
        for name in ("length", "height", "drag_coefficient"):
            _finite(f"crossflow.{name}", getattr(self, name), positive=True)
        if isinstance(self.strips, bool) or not isinstance(self.strips, int) or self.strips < 1:
            raise InputError(
                f"vehicle parameter crossflow.strips must be an integer >= 1, got {self.strips!r}"
            )

    @property
    def stations(self) -> FloatArray:
        """Station positions ``x_k`` along the hull, shape ``(n + 1,)`` [m]."""
        return np.asarray(
            -0.5 * self.length + self.length / self.strips * np.arange(self.strips + 1),
            dtype=np.float64,
        )


@dataclass(frozen=True)
class HullParams:
    """Rigid-body, added-mass and damping coefficients of the planar (surge, sway, yaw) model.

    Fossen's notation: ``M = diag(m - X_udot, m - Y_vdot, I_z - N_rdot)``,
    ``D = -diag(X_u f(U), Y_v f(U), N_r)`` with ``f(U) = exp(-κ U)`` (``κ = 0``: constant),
    ``D_n(ν) = -diag(X_uu |u|, Y_vv |v|, N_rr |r|)``, plus the optional strip-theory
    cross-flow drag. The centre of gravity is at the body origin (``x_g = 0``).
    """

    m: float
    """Mass [kg]."""
    I_z: float
    """Yaw moment of inertia about the body origin [kg m²]."""
    X_udot: float
    """Surge added-mass derivative [kg] (negative: ``-X_udot`` kg are added)."""
    Y_vdot: float
    """Sway added-mass derivative [kg] (negative)."""
    N_rdot: float
    """Yaw added-inertia derivative [kg m²] (negative)."""
    X_u: float
    """Linear surge damping derivative [kg/s] (≤ 0)."""
    Y_v: float
    """Linear sway damping derivative [kg/s] (≤ 0)."""
    N_r: float
    """Linear yaw damping derivative [kg m²/s] (≤ 0)."""
    X_uu: float
    """Quadratic surge damping ``X_|u|u`` [kg/m] (≤ 0)."""
    Y_vv: float
    """Quadratic sway damping ``Y_|v|v`` [kg/m] (≤ 0)."""
    N_rr: float
    """Quadratic yaw damping ``N_|r|r`` [kg m²] (≤ 0)."""
    rho: float
    """Water density [kg/m³]."""
    linear_damping_fade: float = 0.0
    """``κ`` of ``exp(-κ U)`` scaling ``X_u`` and ``Y_v`` with the speed ``U`` [s/m]."""
    added_mass_coriolis: bool = True
    """Whether ``C_A(ν)`` (with the Munk moment) is in the model; else ``C = C_RB`` [-]."""
    crossflow: CrossFlowParams | None = None
    """Strip-theory cross-flow drag, added to the diagonal damping [units per field]."""

    def __post_init__(self) -> None:
        for name in ("m", "I_z", "rho"):
            _finite(name, getattr(self, name), positive=True)
        _finite("linear_damping_fade", self.linear_damping_fade, nonnegative=True)
        for name in ("X_udot", "Y_vdot", "N_rdot", "X_u", "Y_v", "N_r", "X_uu", "Y_vv", "N_rr"):
            value = getattr(self, name)
            _finite(name, value)
            if value > 0.0:
                raise InputError(
                    f"vehicle parameter {name} must be <= 0 (Fossen sign convention), got {value}"
                )

    @property
    def m_u(self) -> float:
        """Surge inertia ``m - X_udot`` [kg]."""
        return self.m - self.X_udot

    @property
    def m_v(self) -> float:
        """Sway inertia ``m - Y_vdot`` [kg]."""
        return self.m - self.Y_vdot

    @property
    def m_r(self) -> float:
        """Yaw inertia ``I_z - N_rdot`` [kg m²]."""
        return self.I_z - self.N_rdot

    @property
    def coriolis_masses(self) -> tuple[float, float]:
        """Surge and sway masses in ``C(ν)``: ``(m_u, m_v)``, or ``(m, m)`` without ``C_A`` [kg]."""
        if self.added_mass_coriolis:
            return self.m_u, self.m_v
        return self.m, self.m


@dataclass(frozen=True, eq=False)
class PropellerParams:
    """Four-quadrant propeller: Fourier series of ``C_T*(β)``, ``C_Q*(β)`` and the scaling.

    ``C_T*(β) = Σ_k A_T[k] cos kβ + B_T[k] sin kβ`` (likewise ``C_Q*``), ``k = 0..K``;
    ``T = c_T ½ρ C_T* V_r² πR²``, ``Q = c_Q ½ρ C_Q* V_r² πR² D`` with ``R = D/2`` [2]_.
    Positive ``C_T*``, ``C_Q*`` at bollard (β = 0, ahead).
    """

    name: str
    """Short identifier of the series, e.g. ``"wageningen_b4-70_pd1.4"`` [-]."""
    source: str
    """Citation of the coefficients [-]."""
    diameter: float
    """Propeller diameter ``D`` [m]."""
    c_T: float
    """Thrust correction factor [-]."""
    c_Q: float
    """Torque correction factor [-]."""
    A_T: FloatArray
    """Cosine coefficients of ``C_T*``, shape ``(K + 1,)`` [-]."""
    B_T: FloatArray
    """Sine coefficients of ``C_T*``, shape ``(K + 1,)`` [-] (``B_T[0]`` unused)."""
    A_Q: FloatArray
    """Cosine coefficients of ``C_Q*``, shape ``(K + 1,)`` [-]."""
    B_Q: FloatArray
    """Sine coefficients of ``C_Q*``, shape ``(K + 1,)`` [-]."""
    order: int | None = None
    """Number of harmonics used by default (``None``: all ``K``) [-]."""

    def __post_init__(self) -> None:
        _finite("propeller.diameter", self.diameter, positive=True)
        _finite("propeller.c_T", self.c_T, positive=True)
        _finite("propeller.c_Q", self.c_Q, positive=True)
        arrays = {}
        for name in ("A_T", "B_T", "A_Q", "B_Q"):
            arrays[name] = _frozen_vector(f"propeller.{name}", getattr(self, name))
            object.__setattr__(self, name, arrays[name])
        sizes = {array.size for array in arrays.values()}
        if len(sizes) != 1:
            raise InputError(f"propeller coefficient arrays differ in length: {sorted(sizes)}")
        if self.order is not None and not 0 <= self.order <= self.max_order:
            raise InputError(
                f"propeller order must be in [0, {self.max_order}], got {self.order!r}"
            )

    @property
    def max_order(self) -> int:
        """Highest harmonic ``K`` available in the tables [-]."""
        return int(self.A_T.size - 1)

    @property
    def radius(self) -> float:
        """Propeller radius ``R = D/2`` [m]."""
        return 0.5 * self.diameter

    @property
    def disc_area(self) -> float:
        """Propeller disc area ``πR²`` [m²]."""
        return math.pi * self.radius**2


@dataclass(frozen=True, eq=False)
class LinearPropellerParams:
    """Propeller whose open-water K_T, K_Q are linear in the advance ratio (Fossen 2021, 9.3).

    ``K_T(J) = K_T0 + (K_T(J_max) - K_T0) J / J_max`` (``K_Q`` likewise), ``J = v_a/(nD)``,
    so that ``T = ρ D⁴ (K_T0 n |n| + K_T' (v_a/D) |n|)`` and
    ``Q = ρ D⁵ (K_Q0 n |n| + K_Q' (v_a/D) |n|)`` with the slopes ``K_T' = dK_T/dJ``.
    """

    name: str
    """Short identifier of the propeller [-]."""
    source: str
    """Citation of the coefficients [-]."""
    diameter: float
    """Propeller diameter ``D`` [m]."""
    K_T0: float
    """Thrust coefficient at ``J = 0`` (bollard) [-]."""
    K_Q0: float
    """Torque coefficient at ``J = 0`` [-]."""
    J_max: float
    """Advance ratio of the second point of the linear fit [-]."""
    K_T_at_J_max: float
    """Thrust coefficient at ``J_max`` [-]."""
    K_Q_at_J_max: float
    """Torque coefficient at ``J_max`` [-]."""

    def __post_init__(self) -> None:
        for name in ("diameter", "K_T0", "K_Q0", "J_max", "K_Q_at_J_max"):
            _finite(f"propeller.{name}", getattr(self, name), positive=True)
        _finite("propeller.K_T_at_J_max", self.K_T_at_J_max)

    @property
    def thrust_slope(self) -> float:
        """``dK_T/dJ`` [-]."""
        return (self.K_T_at_J_max - self.K_T0) / self.J_max

    @property
    def torque_slope(self) -> float:
        """``dK_Q/dJ`` [-]."""
        return (self.K_Q_at_J_max - self.K_Q0) / self.J_max

    @property
    def order(self) -> None:
        """No Fourier harmonics (kept so that every propeller answers ``order``) [-]."""
        return None

    @property
    def max_order(self) -> int:
        """Highest harmonic available: 0, the model has no Fourier series [-]."""
        return 0


#: Any propeller model a thruster can carry.
Propeller = PropellerParams | LinearPropellerParams


@dataclass(frozen=True, eq=False)
class MotorParams:
    """Brushed DC motor driving one propeller (inductance neglected).

    ``V = R_a I + K_e ω``, ``ω = 2πn``, shaft torque ``Q = K_e I`` (``K_t = K_e`` in SI).
    The current is either ``I = Q/K_e + I_0 sgn(n)`` (``current_model="torque"``) or a smooth
    fit of a measured curve ``I(n)`` (``current_model="measured"``).
    """

    R_a: float
    """Armature resistance [Ω]."""
    K_e: float
    """Back-EMF constant, equal to the torque constant ``K_t`` [V s/rad] = [N m/A]."""
    V_bus: float
    """Supply (battery bus) voltage [V]; informative, used for checks and reports."""
    I_0: float = 0.0
    """No-load current [A], added with the (smoothed) sign of the shaft speed."""
    current_model: CurrentModel = "torque"
    """``"torque"`` (I = Q/K_t + I_0 sgn n) or ``"measured"`` (fit of the I(n) table) [-]."""
    current_curve_n: FloatArray | None = None
    """Shaft speeds of the measured current curve, ``n ≥ 0``, shape ``(n_points,)`` [rev/s]."""
    current_curve_amps: FloatArray | None = None
    """Measured current at ``current_curve_n``, shape ``(n_points,)`` [A]."""

    def __post_init__(self) -> None:
        _finite("motor.R_a", self.R_a, nonnegative=True)
        _finite("motor.K_e", self.K_e, positive=True)
        _finite("motor.V_bus", self.V_bus, positive=True)
        _finite("motor.I_0", self.I_0, nonnegative=True)
        if self.current_model not in ("torque", "measured"):
            raise InputError(
                f"motor.current_model must be 'torque' or 'measured', got {self.current_model!r}"
            )
        has_n = self.current_curve_n is not None
        has_i = self.current_curve_amps is not None
        if has_n != has_i:
            raise InputError("motor current curve needs both n [rev/s] and current [A]")
        if self.current_curve_n is not None and self.current_curve_amps is not None:
            n = _frozen_vector("motor.current_curve_n", self.current_curve_n)
            amps = _frozen_vector("motor.current_curve_amps", self.current_curve_amps)
            if n.shape != amps.shape or n.size < 2:
                raise InputError(
                    "motor current curve needs >= 2 points and equal lengths, got "
                    f"{n.size} speeds and {amps.size} currents"
                )
            if np.any(n < 0.0) or np.any(np.diff(n) <= 0.0):
                raise InputError("motor current curve speeds must be >= 0 and increasing")
            object.__setattr__(self, "current_curve_n", n)
            object.__setattr__(self, "current_curve_amps", amps)
        elif self.current_model == "measured":
            raise InputError("motor.current_model = 'measured' needs a current curve I(n)")


@dataclass(frozen=True, eq=False)
class VehicleParams:
    """A twin-thruster vehicle type (MEDUSA class): hull, propellers, motors, limits, smoothing.

    The shorthand of a vehicle whose two identical thrusters sit at lateral positions
    ``y = ∓l`` (port negative) and push along the body x axis; the model expands it to the
    generic actuator list (:func:`auvplan.vehicle.actuators.actuated_vehicle`). Smoothing
    constants make the model twice continuously differentiable everywhere (see
    :mod:`auvplan.vehicle.dynamics`); their effect on thrust and power is below 0.1 % at
    cruise (quantified in the tests).
    """

    name: str
    """Vehicle type name [-]."""
    hull: HullParams
    """Hull parameters [units per field of HullParams]."""
    propeller: Propeller
    """Propeller of both thrusters [units per field of its class]."""
    motor: MotorParams
    """Motor of both thrusters [units per field of MotorParams]."""
    l: float  # noqa: E741  (the paper's symbol)
    """Half the lateral spacing of the two thrusters [m]."""
    hotel_power: float
    """Hotel load ``P_b`` (computers, sensors, radios) [W]."""
    n_max: float
    """Maximum propeller speed ``|n| ≤ n_max`` [rev/s]."""
    w_c: float
    """Maximum propeller acceleration of ``ṅ = w_c tanh(c)`` [rev/s²]."""
    eps_inflow: float = DEFAULT_EPS_INFLOW
    """Smoothing speed ``ε_V`` in ``V_r = sqrt(v_a² + v_p² + ε_V²)`` [m/s]."""
    eps_abs_speed: float = DEFAULT_EPS_ABS_SPEED
    """Smoothing of ``|u| ≈ sqrt(u² + ε²)``, also for ``|v|`` [m/s]."""
    eps_abs_rate: float = DEFAULT_EPS_ABS_RATE
    """Smoothing of ``|r| ≈ sqrt(r² + ε²)`` [rad/s]."""
    eps_sign_n: float = DEFAULT_EPS_SIGN_N
    """Smoothing of ``sgn(n) ≈ n / sqrt(n² + ε²)`` in the motor current, and of ``|n|`` [rev/s]."""
    battery_capacity: float | None = None
    """Energy of a full battery, None when unknown (no reserve check) [J]."""
    depth_limits: DepthLimits = field(default_factory=DepthLimits)
    """Climb and dive rates [m/s] and minimum altitude [m] of the depth profile."""
    description: str = ""
    """Free text (origin of the parameter set) [-]."""
    metadata: dict[str, str] = field(default_factory=dict)
    """Source notes per parameter, e.g. ``{"hull.m": "DSOR farol sim.yaml"}`` [-]."""

    def __post_init__(self) -> None:
        _finite("l", self.l, positive=True)
        _finite("n_max", self.n_max, positive=True)
        _finite("w_c", self.w_c, positive=True)
        check_common_fields(self)


class CommonVehicleFields(Protocol):
    """The fields every vehicle parameter set has, whatever its actuator layout."""

    @property
    def name(self) -> str:
        """Vehicle type name [-]."""

    @property
    def hotel_power(self) -> float:
        """Hotel load [W]."""

    @property
    def eps_inflow(self) -> float:
        """Propeller inflow smoothing [m/s]."""

    @property
    def eps_abs_speed(self) -> float:
        """Smoothing of ``|u|``, ``|v|`` [m/s]."""

    @property
    def eps_abs_rate(self) -> float:
        """Smoothing of ``|r|`` [rad/s]."""

    @property
    def eps_sign_n(self) -> float:
        """Smoothing of ``sgn(n)``, ``|n|`` [rev/s]."""

    @property
    def battery_capacity(self) -> float | None:
        """Energy of a full battery, None when unknown [J]."""


def check_common_fields(params: CommonVehicleFields) -> None:
    """Validate the name, hotel load, battery and smoothing constants of a parameter set.

    Raises
    ------
    InputError
        Naming the first offending field.
    """
    _finite("hotel_power", params.hotel_power, nonnegative=True)
    if params.battery_capacity is not None:
        _finite("battery_capacity", params.battery_capacity, positive=True)
    for name in ("eps_inflow", "eps_abs_speed", "eps_abs_rate", "eps_sign_n"):
        _finite(name, getattr(params, name), positive=True)
    if not params.name:
        raise InputError("vehicle name must not be empty")


__all__ = [
    "DEFAULT_EPS_ABS_RATE",
    "DEFAULT_EPS_ABS_SPEED",
    "DEFAULT_EPS_INFLOW",
    "DEFAULT_EPS_SIGN_N",
    "CommonVehicleFields",
    "CrossFlowParams",
    "CurrentModel",
    "HullParams",
    "LinearPropellerParams",
    "MotorParams",
    "Propeller",
    "PropellerParams",
    "VehicleParams",
    "check_common_fields",
]
