"""Generic actuator layout of a planar vehicle: thrusters and control surfaces, with positions.

A vehicle type is its hull plus a list of actuators (:class:`ActuatedVehicleParams`), so a new
type is a new vehicle file, not new code. Each actuator adds one state and one input:

- a **thruster** ``name`` has the propeller speed ``n_<name>`` [rev/s] as state and the
  dimensionless command ``c_<name>`` as input, ``ṅ = w_c tanh(c)``;
- a **control surface** ``name`` (a vertical fin: rudder) has its deflection ``delta_<name>``
  [rad] as state and ``c_<name>`` as input, ``δ̇ = w_δ tanh(c)``.

The twin-thruster shorthand :class:`auvplan.vehicle.params.VehicleParams` (MEDUSA) expands to
two thrusters ``ps`` and ``sb`` at ``y = ∓l`` (:func:`actuated_vehicle`).

Body frame (Fossen 2021): x forward, y to starboard; a thruster at ``(x, y)`` pushes along the
axis at angle ``α`` from the body x axis (positive to starboard), its yaw moment per unit
force is ``x sin α - y cos α``.

References
----------
.. [1] T. I. Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed.,
   Wiley 2021, ch. 9 (propellers, rudders and control surfaces).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Final

from auvplan.errors import InputError
from auvplan.vehicle.params import (
    DEFAULT_EPS_ABS_RATE,
    DEFAULT_EPS_ABS_SPEED,
    DEFAULT_EPS_INFLOW,
    DEFAULT_EPS_SIGN_N,
    HullParams,
    MotorParams,
    Propeller,
    VehicleParams,
    check_common_fields,
)
from auvplan.vehicle.vertical import DepthLimits

#: Actuator names become parts of state and input names: lowercase letters, digits, ``_``.
ACTUATOR_NAME: Final = re.compile(r"[a-z][a-z0-9_]*")


def _check_name(kind: str, name: str) -> None:
    if not isinstance(name, str) or not ACTUATOR_NAME.fullmatch(name):
        raise InputError(
            f"{kind} name must be lowercase letters, digits and '_' (starting with a letter), "
            f"got {name!r}"
        )


def _check(name: str, value: float, *, low: float, high: float) -> None:
    if not (math.isfinite(value) and low <= value <= high):
        raise InputError(f"vehicle parameter {name} must be in [{low:g}, {high:g}], got {value!r}")


@dataclass(frozen=True, eq=False)
class ThrusterParams:
    """One propeller driven by a DC motor, at ``(x, y)``, pushing along the axis ``α``.

    The propeller sees the advance speed ``v_a = (1 - w) (cos α (u - y r) + sin α (v + x r))``
    and its thrust ``T`` acts on the hull as ``(1 - t) T (cos α, sin α)`` with yaw moment
    ``(1 - t) T (x sin α - y cos α)`` (``w`` wake fraction, ``t`` thrust deduction).
    """

    name: str
    """Identifier; the state is ``n_<name>``, the input ``c_<name>`` [-]."""
    x: float
    """Longitudinal position of the propeller, forward positive [m]."""
    y: float
    """Lateral position of the propeller, starboard positive [m]."""
    axis: float
    """Angle of the thrust axis from the body x axis, to starboard positive [rad]."""
    propeller: Propeller
    """Propeller model [units per field of the propeller class]."""
    motor: MotorParams
    """Motor driving the propeller [units per field of MotorParams]."""
    n_max: float
    """Maximum propeller speed ``|n| ≤ n_max`` [rev/s]."""
    w_c: float
    """Maximum propeller acceleration of ``ṅ = w_c tanh(c)`` [rev/s²]."""
    wake_fraction: float = 0.0
    """Wake fraction ``w`` of the advance speed ``v_a = (1 - w) v_axial`` [-]."""
    thrust_deduction: float = 0.0
    """Thrust deduction ``t``: the hull feels ``(1 - t) T`` [-]."""

    def __post_init__(self) -> None:
        _check_name("thruster", self.name)
        _check(f"thruster {self.name}.x", self.x, low=-1e3, high=1e3)
        _check(f"thruster {self.name}.y", self.y, low=-1e3, high=1e3)
        _check(f"thruster {self.name}.axis", self.axis, low=-math.pi, high=math.pi)
        _check(f"thruster {self.name}.n_max", self.n_max, low=1e-6, high=math.inf)
        _check(f"thruster {self.name}.w_c", self.w_c, low=1e-6, high=math.inf)
        _check(f"thruster {self.name}.wake_fraction", self.wake_fraction, low=0.0, high=0.9)
        _check(f"thruster {self.name}.thrust_deduction", self.thrust_deduction, low=0.0, high=0.9)

    @property
    def state_name(self) -> str:
        """Name of the propeller-speed state [-]."""
        return f"n_{self.name}"

    @property
    def input_name(self) -> str:
        """Name of the command input [-]."""
        return f"c_{self.name}"

    @property
    def surge_share(self) -> float:
        """``cos α``: share of the thrust along the body x axis [-]."""
        return math.cos(self.axis)

    @property
    def sway_share(self) -> float:
        """``sin α``: share of the thrust along the body y axis [-]."""
        return math.sin(self.axis)

    @property
    def yaw_arm(self) -> float:
        """``x sin α - y cos α``: yaw moment per newton of thrust [m]."""
        return self.x * math.sin(self.axis) - self.y * math.cos(self.axis)


@dataclass(frozen=True, eq=False)
class ControlSurfaceParams:
    """A vertical control surface (rudder) at ``(x, y)`` deflected by ``δ``.

    With ``q = ½ ρ (u² + v²) A`` (Fossen 2021, eq. 9.255 and the ``remus100`` model): lift
    ``Y = -q C_Lδ δ``, drag ``X = -q C_Dδ δ²``, yaw moment ``N = x Y - y X``; a positive
    deflection of a stern rudder (``x < 0``) turns the bow to starboard.
    """

    name: str
    """Identifier; the state is ``delta_<name>``, the input ``c_<name>`` [-]."""
    x: float
    """Longitudinal position of the centre of pressure, forward positive [m]."""
    y: float
    """Lateral position of the centre of pressure, starboard positive [m]."""
    area: float
    """Planform area ``A`` (all fins deflected together) [m²]."""
    lift_slope: float
    """Lift coefficient per radian of deflection ``C_Lδ`` [1/rad]."""
    drag_slope: float
    """Drag coefficient per radian squared ``C_Dδ`` [1/rad²]."""
    delta_max: float
    """Maximum deflection ``|δ| ≤ δ_max`` [rad]."""
    rate_max: float
    """Maximum deflection rate ``w_δ`` of ``δ̇ = w_δ tanh(c)`` [rad/s]."""

    def __post_init__(self) -> None:
        _check_name("control surface", self.name)
        _check(f"control surface {self.name}.x", self.x, low=-1e3, high=1e3)
        _check(f"control surface {self.name}.y", self.y, low=-1e3, high=1e3)
        _check(f"control surface {self.name}.area", self.area, low=1e-9, high=1e4)
        _check(f"control surface {self.name}.lift_slope", self.lift_slope, low=1e-6, high=100.0)
        _check(f"control surface {self.name}.drag_slope", self.drag_slope, low=0.0, high=100.0)
        _check(f"control surface {self.name}.delta_max", self.delta_max, low=1e-6, high=math.pi / 2)
        _check(f"control surface {self.name}.rate_max", self.rate_max, low=1e-6, high=math.inf)

    @property
    def state_name(self) -> str:
        """Name of the deflection state [-]."""
        return f"delta_{self.name}"

    @property
    def input_name(self) -> str:
        """Name of the command input [-]."""
        return f"c_{self.name}"

    @property
    def yaw_arm(self) -> float:
        """Yaw moment per newton of (negative) lift at zero deflection, ``-x`` [m]."""
        return -self.x


@dataclass(frozen=True, eq=False)
class ActuatedVehicleParams:
    """A vehicle type described by its hull and its list of actuators.

    States ``(north, east, ψ, u, v, r, n_<thruster>…, delta_<surface>…)``, inputs
    ``(c_<thruster>…, c_<surface>…)``, both in the order of the lists.
    """

    name: str
    """Vehicle type name [-]."""
    hull: HullParams
    """Hull parameters [units per field of HullParams]."""
    thrusters: tuple[ThrusterParams, ...]
    """Thrusters, at least one [units per field of ThrusterParams]."""
    hotel_power: float
    """Hotel load ``P_b`` (computers, sensors, radios) [W]."""
    surfaces: tuple[ControlSurfaceParams, ...] = ()
    """Control surfaces [units per field of ControlSurfaceParams]."""
    eps_inflow: float = DEFAULT_EPS_INFLOW
    """Smoothing speed ``ε_V`` of four-quadrant propellers' inflow [m/s]."""
    eps_abs_speed: float = DEFAULT_EPS_ABS_SPEED
    """Smoothing of ``|u| ≈ sqrt(u² + ε²)``, also for ``|v|`` and the cross-flow [m/s]."""
    eps_abs_rate: float = DEFAULT_EPS_ABS_RATE
    """Smoothing of ``|r| ≈ sqrt(r² + ε²)`` [rad/s]."""
    eps_sign_n: float = DEFAULT_EPS_SIGN_N
    """Smoothing of ``sgn(n)`` and ``|n|`` (motor current, open-water propellers) [rev/s]."""
    battery_capacity: float | None = None
    """Energy of a full battery, None when unknown (no reserve check) [J]."""
    depth_limits: DepthLimits = field(default_factory=DepthLimits)
    """Climb and dive rates [m/s] and minimum altitude [m] of the depth profile."""
    description: str = ""
    """Free text (origin of the parameter set) [-]."""
    metadata: dict[str, str] = field(default_factory=dict)
    """Source notes per parameter [-]."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "thrusters", tuple(self.thrusters))
        object.__setattr__(self, "surfaces", tuple(self.surfaces))
        if not self.thrusters:
            raise InputError(f"vehicle {self.name!r} needs at least one thruster")
        names = [thruster.name for thruster in self.thrusters]
        names += [surface.name for surface in self.surfaces]
        repeated = sorted({name for name in names if names.count(name) > 1})
        if repeated:
            raise InputError(f"actuator names must be unique, repeated: {', '.join(repeated)}")
        check_common_fields(self)

    @property
    def propeller(self) -> Propeller:
        """The first thruster's propeller (what code asking for "the" propeller gets) [-]."""
        return self.thrusters[0].propeller


def actuated_vehicle(params: VehicleParams | ActuatedVehicleParams) -> ActuatedVehicleParams:
    """The generic actuator description of a vehicle (the twin shorthand expanded).

    A :class:`VehicleParams` becomes thrusters ``ps`` at ``y = -l`` and ``sb`` at ``y = +l``
    (axis along x, no wake or thrust deduction, so ``v_a = u ∓ (-l) r``); an
    :class:`ActuatedVehicleParams` is returned unchanged.

    Examples
    --------
    >>> from auvplan.io.vehicles import load_vehicle
    >>> [t.state_name for t in actuated_vehicle(load_vehicle("medusa")).thrusters]
    ['n_ps', 'n_sb']
    """
    if isinstance(params, ActuatedVehicleParams):
        return params
    thrusters = tuple(
        ThrusterParams(
            name=name,
            x=0.0,
            y=side * params.l,
            axis=0.0,
            propeller=params.propeller,
            motor=params.motor,
            n_max=params.n_max,
            w_c=params.w_c,
        )
        for name, side in (("ps", -1.0), ("sb", 1.0))
    )
    return ActuatedVehicleParams(
        name=params.name,
        hull=params.hull,
        thrusters=thrusters,
        hotel_power=params.hotel_power,
        eps_inflow=params.eps_inflow,
        eps_abs_speed=params.eps_abs_speed,
        eps_abs_rate=params.eps_abs_rate,
        eps_sign_n=params.eps_sign_n,
        battery_capacity=params.battery_capacity,
        depth_limits=params.depth_limits,
        description=params.description,
        metadata=params.metadata,
    )


__all__ = [
    "ACTUATOR_NAME",
    "ActuatedVehicleParams",
    "ControlSurfaceParams",
    "ThrusterParams",
    "actuated_vehicle",
]
