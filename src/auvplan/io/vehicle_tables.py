"""The tables of a vehicle file as pydantic models (:func:`auvplan.io.vehicles.load_vehicle`).

Each key has one home here: its type, default, physical range and canonical unit. Every number
is written ``{ value = ..., unit = "..." }``; the unit is checked (a few conversions are
accepted at this edge: rpm, mm, deg, ...) and the value converted to the key's canonical unit
(``json_schema_extra={"unit": ...}``) before its range is checked. The ranges span every
marine vehicle from a 0.1 kg model to a 10,000 t ship; they reject typos and unit slips
(``n_max = 1e-9 rev/s``, a density of 1.025 kg/m³), not unusual designs.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Final, Literal, Self, get_origin

from pydantic import (
    BeforeValidator,
    Discriminator,
    Field,
    Strict,
    Tag,
    ValidationInfo,
    field_validator,
    model_validator,
)

from auvplan.io.tables import Flag, Integer, TableModel, Text
from auvplan.vehicle.params import (
    DEFAULT_EPS_ABS_RATE,
    DEFAULT_EPS_ABS_SPEED,
    DEFAULT_EPS_INFLOW,
    DEFAULT_EPS_SIGN_N,
    CurrentModel,
)
from auvplan.vehicle.vertical import DEFAULT_MIN_ALTITUDE, DEFAULT_VERTICAL_RATE

#: Canonical unit -> accepted spellings and the factor to the canonical unit.
UNITS: Final[dict[str, dict[str, float]]] = {
    "kg": {"kg": 1.0},
    "kg m^2": {"kg m^2": 1.0, "kg m2": 1.0},
    "kg/s": {"kg/s": 1.0},
    "kg m^2/s": {"kg m^2/s": 1.0, "kg m2/s": 1.0},
    "kg/m": {"kg/m": 1.0},
    "kg/m^3": {"kg/m^3": 1.0, "kg/m3": 1.0},
    "m": {"m": 1.0, "cm": 1e-2, "mm": 1e-3},
    "rev/s": {"rev/s": 1.0, "rps": 1.0, "rpm": 1.0 / 60.0, "rev/min": 1.0 / 60.0},
    "rev/s^2": {"rev/s^2": 1.0, "rev/s2": 1.0},
    "1": {"1": 1.0, "-": 1.0, "": 1.0},
    "ohm": {"ohm": 1.0, "Ω": 1.0},
    "V s/rad": {"V s/rad": 1.0, "N m/A": 1.0},
    "V": {"V": 1.0},
    "A": {"A": 1.0},
    "W": {"W": 1.0},
    "J": {"J": 1.0, "kJ": 1e3, "MJ": 1e6, "Wh": 3600.0, "kWh": 3.6e6},
    "m/s": {"m/s": 1.0},
    "rad/s": {"rad/s": 1.0, "deg/s": math.pi / 180.0},
    "rad": {"rad": 1.0, "deg": math.pi / 180.0},
    "m^2": {"m^2": 1.0, "m2": 1.0, "cm^2": 1e-4},
    "1/rad": {"1/rad": 1.0},
    "1/rad^2": {"1/rad^2": 1.0, "1/rad2": 1.0},
    "s/m": {"s/m": 1.0},
}

Name = Annotated[str, Strict(), Field(min_length=1)]
#: Bound of a propeller's ``order`` (its table checks the harmonics it has) [-].
_MAX_ORDER: Final = 2**31


def _normalise_unit(unit: str) -> str:
    return " ".join(unit.replace("*", " ").replace("·", " ").split())


class _Measured(float):
    """A number converted to its key's canonical unit, shown with the unit in messages."""

    unit: str

    def __new__(cls, value: float, unit: str) -> Self:
        measured = super().__new__(cls, value)
        measured.unit = unit
        return measured

    def __repr__(self) -> str:
        return repr(float(self)) if self.unit == "1" else f"{float(self)!r} {self.unit}"


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _measured(entry: Any, unit: str, *, array: bool) -> _Measured | tuple[_Measured, ...]:
    """The value of ``{ value = ..., unit = "..." }`` in ``unit`` (a number or a tuple of them)."""
    if not isinstance(entry, dict) or set(entry) != {"value", "unit"}:
        raise ValueError(f'must be a table {{ value = ..., unit = "{unit}" }}, got {entry!r}')
    accepted = {_normalise_unit(k): factor for k, factor in UNITS[unit].items()}
    given = entry["unit"]
    if not isinstance(given, str) or _normalise_unit(given) not in accepted:
        spellings = ", ".join(repr(k) for k in UNITS[unit])
        raise ValueError(f"unit {given!r} is not {unit!r} (accepted: {spellings})")
    factor = accepted[_normalise_unit(given)]
    value = entry["value"]
    if array:
        if not isinstance(value, list) or not all(_is_number(v) for v in value):
            raise ValueError(f"value must be a list of numbers, got {value!r}")
        return tuple(_Measured(float(v) * factor, unit) for v in value)
    if not _is_number(value):
        raise ValueError(f"value must be a number, got {value!r}")
    return _Measured(float(value) * factor, unit)


def _quantity(unit: str, low: float, high: float, description: str, default: Any = ...) -> Any:
    """A number key: required unless ``default`` is given, in ``[low, high]`` ``unit``."""
    return Field(
        default, ge=low, le=high, description=description, json_schema_extra={"unit": unit}
    )


class VehicleTable(TableModel):
    """A table of a vehicle file: its number keys are read in their canonical unit."""

    @field_validator("*", mode="before")
    @classmethod
    def _in_unit(cls, entry: Any, info: ValidationInfo) -> Any:
        field = cls.model_fields[str(info.field_name)]
        extra = field.json_schema_extra
        if not isinstance(extra, dict) or "unit" not in extra:
            return entry
        return _measured(entry, str(extra["unit"]), array=get_origin(field.annotation) is tuple)


class CrossflowTable(VehicleTable):
    """Strip-theory cross-flow drag of a slender hull (Fossen 2021, sec. 6.7)."""

    length: float = _quantity("m", 0.01, 1e3, "hull length L")
    height: float = _quantity("m", 1e-3, 1e2, "projected height (draft) H seen from the side")
    drag_coefficient: float = _quantity("1", 0.05, 5.0, "2-D cross-flow drag coefficient C_d")
    strips: Integer = Field(ge=1, le=1000, description="number of strips (strips + 1 stations)")


class HullTable(VehicleTable):
    """Rigid-body, added-mass and damping coefficients of the planar model."""

    m: float = _quantity("kg", 0.1, 1e7, "mass")
    I_z: float = _quantity("kg m^2", 1e-4, 1e12, "yaw moment of inertia")
    X_udot: float = _quantity("kg", -1e7, 0.0, "surge added-mass derivative")
    Y_vdot: float = _quantity("kg", -1e7, 0.0, "sway added-mass derivative")
    N_rdot: float = _quantity("kg m^2", -1e12, 0.0, "yaw added-inertia derivative")
    X_u: float = _quantity("kg/s", -1e7, 0.0, "linear surge damping")
    Y_v: float = _quantity("kg/s", -1e7, 0.0, "linear sway damping")
    N_r: float = _quantity("kg m^2/s", -1e12, 0.0, "linear yaw damping")
    X_uu: float = _quantity("kg/m", -1e7, 0.0, "quadratic surge damping X_|u|u")
    Y_vv: float = _quantity("kg/m", -1e7, 0.0, "quadratic sway damping Y_|v|v")
    N_rr: float = _quantity("kg m^2", -1e12, 0.0, "quadratic yaw damping N_|r|r")
    rho: float = _quantity("kg/m^3", 950.0, 1100.0, "water density")
    linear_damping_fade: float = _quantity(
        "s/m", 0.0, 100.0, "kappa of exp(-kappa U) scaling X_u and Y_v with the speed U", 0.0
    )
    added_mass_coriolis: Flag = Field(True, description="C_A (with the Munk moment) in the model")
    crossflow: CrossflowTable | None = Field(None, description="cross-flow drag (absent: none)")


class PropulsionTable(VehicleTable):
    """The twin-thruster shorthand: two identical thrusters at ``y = -/+ l``."""

    l: float = _quantity("m", 0.005, 50.0, "half the lateral spacing of the thrusters")  # noqa: E741
    n_max: float = _quantity("rev/s", 0.5, 1000.0, "maximum propeller speed")
    w_c: float = _quantity("rev/s^2", 0.01, 1e5, "maximum propeller acceleration")


_DIAMETER: Final = ("m", 0.005, 15.0, "propeller diameter D")


class FourQuadrantPropellerTable(VehicleTable):
    """A four-quadrant Fourier table (packaged or a CSV next to the file), scaled."""

    model: Literal["four_quadrant"] = Field("four_quadrant", description="propeller model")
    table: Text = Field(description="packaged table name or CSV path relative to the vehicle file")
    diameter: float = _quantity(*_DIAMETER)
    c_T: float = _quantity("1", 0.1, 10.0, "thrust correction factor")
    c_Q: float = _quantity("1", 0.1, 10.0, "torque correction factor")
    order: Integer | None = Field(
        None, ge=-_MAX_ORDER, le=_MAX_ORDER, description="Fourier harmonics used (absent: all)"
    )


class LinearPropellerTable(VehicleTable):
    """Open-water K_T, K_Q linear in the advance ratio J (Fossen 2021, 9.3)."""

    model: Literal["linear"] = Field(description="propeller model")
    name: Name = Field("linear", description="short identifier of the propeller")
    source: Name = Field("vehicle file", description="citation of the coefficients")
    diameter: float = _quantity(*_DIAMETER)
    K_T0: float = _quantity("1", 1e-3, 2.0, "thrust coefficient at J = 0")
    K_Q0: float = _quantity("1", 1e-4, 0.5, "torque coefficient at J = 0")
    J_max: float = _quantity("1", 0.01, 3.0, "advance ratio of the second point of the fit")
    K_T_at_J_max: float = _quantity("1", -2.0, 2.0, "thrust coefficient at J_max")
    K_Q_at_J_max: float = _quantity("1", 1e-5, 0.5, "torque coefficient at J_max")


PROPELLER_MODELS: Final = ("four_quadrant", "linear")


def _propeller_model(table: Any) -> Any:
    """The ``model`` of a propeller table (four-quadrant when absent)."""
    return table.get("model", "four_quadrant") if isinstance(table, dict) else "four_quadrant"


def _known_propeller_model(table: Any) -> Any:
    model = _propeller_model(table)
    if model not in PROPELLER_MODELS:
        raise ValueError(f"model: must be 'four_quadrant' or 'linear', got {model!r}")
    return table


PropellerTable = Annotated[
    Annotated[FourQuadrantPropellerTable, Tag("four_quadrant")]
    | Annotated[LinearPropellerTable, Tag("linear")],
    Discriminator(_propeller_model),
    BeforeValidator(_known_propeller_model),
]


class CurrentCurveTable(VehicleTable):
    """A measured motor current ``I(n)`` (used when ``current_model = "measured"``)."""

    n: tuple[Annotated[float, Field(ge=0.0, le=1000.0)], ...] = Field(
        description="shaft speeds", json_schema_extra={"unit": "rev/s"}
    )
    current: tuple[Annotated[float, Field(ge=0.0, le=1e4)], ...] = Field(
        description="current at each speed", json_schema_extra={"unit": "A"}
    )


class MotorTable(VehicleTable):
    """A brushed DC motor driving one propeller."""

    R_a: float = _quantity("ohm", 0.0, 1e3, "armature resistance")
    K_e: float = _quantity("V s/rad", 1e-5, 100.0, "back-EMF (= torque) constant")
    V_bus: float = _quantity("V", 0.5, 1e4, "supply (battery bus) voltage")
    I_0: float = _quantity("A", 0.0, 1e3, "no-load current", 0.0)
    current_model: CurrentModel = Field(
        "torque", description="'torque' (I = Q/K_t + I_0 sgn n) or 'measured' (the curve)"
    )
    current_curve: CurrentCurveTable | None = Field(None, description="measured current I(n)")


class ThrusterTable(VehicleTable):
    """One propeller driven by a DC motor, at ``(x, y)``, pushing along ``axis``."""

    name: Name = Field(description="identifier; the state is n_<name>")
    x: float = _quantity("m", -1e3, 1e3, "longitudinal position, forward positive")
    y: float = _quantity("m", -1e3, 1e3, "lateral position, starboard positive")
    axis: float = _quantity("rad", -math.pi, math.pi, "thrust axis from the body x axis")
    n_max: float = _quantity("rev/s", 0.5, 1000.0, "maximum propeller speed")
    w_c: float = _quantity("rev/s^2", 0.01, 1e5, "maximum propeller acceleration")
    wake_fraction: float = _quantity("1", 0.0, 0.9, "wake fraction w", 0.0)
    thrust_deduction: float = _quantity("1", 0.0, 0.9, "thrust deduction t", 0.0)
    propeller: PropellerTable = Field(description="the propeller")
    motor: MotorTable = Field(description="the motor driving the propeller")


class ControlSurfaceTable(VehicleTable):
    """A vertical control surface (rudder) at ``(x, y)``."""

    name: Name = Field(description="identifier; the state is delta_<name>")
    x: float = _quantity("m", -1e3, 1e3, "centre of pressure, forward positive")
    y: float = _quantity("m", -1e3, 1e3, "centre of pressure, starboard positive")
    area: float = _quantity("m^2", 1e-6, 1e3, "planform area")
    lift_slope: float = _quantity("1/rad", 1e-3, 10.0, "lift coefficient per radian C_L_delta")
    drag_slope: float = _quantity("1/rad^2", 0.0, 10.0, "drag coefficient per rad^2 C_D_delta")
    delta_max: float = _quantity("rad", 1e-3, math.pi / 2, "maximum deflection")
    rate_max: float = _quantity("rad/s", 1e-3, 1e3, "maximum deflection rate")


class PowerTable(VehicleTable):
    """The power drawn besides propulsion, and the battery that supplies all of it.

    ``battery_capacity`` is the energy of a full battery (a vehicle of 0.1 kg carries more than
    1 J; a submarine's battery a few 10¹¹ J). Absent, the capacity is unknown and no plan is
    checked against it: the packaged types give none, since no published figure was found
    for either (``reference/vehicle.md`` and ``reference/navigation-fleets-formats.md`` give
    only MEDUSA's assumed 24 V bus and no REMUS 100 battery).
    """

    hotel: float = _quantity("W", 0.0, 1e7, "hotel load (computers, sensors, radios)")
    battery_capacity: float | None = _quantity(
        "J", 1.0, 1e13, "energy of a full battery (absent: unknown, no reserve check)", None
    )


class VerticalTable(VehicleTable):
    """The depth profile's limits (:class:`auvplan.vehicle.DepthLimits`); absent: its defaults.

    Rates must be > 0: a vehicle that cannot change depth flies ``[mission] depth_m``.
    """

    climb_rate: float = _quantity(
        "m/s", 1e-3, 20.0, "largest rate of ascent", DEFAULT_VERTICAL_RATE
    )
    dive_rate: float = _quantity(
        "m/s", 1e-3, 20.0, "largest rate of descent", DEFAULT_VERTICAL_RATE
    )
    min_altitude: float = _quantity(
        "m", 0.0, 1e3, "smallest height above the seabed (hard bound)", DEFAULT_MIN_ALTITUDE
    )


class SmoothingTable(VehicleTable):
    """Smoothing that makes the model twice continuously differentiable."""

    inflow: float = _quantity("m/s", 1e-6, 1.0, "eps_V of the propeller inflow", DEFAULT_EPS_INFLOW)
    abs_speed: float = _quantity(
        "m/s", 1e-6, 1.0, "eps of |u| ~ sqrt(u^2 + eps^2)", DEFAULT_EPS_ABS_SPEED
    )
    abs_rate: float = _quantity(
        "rad/s", 1e-6, 1.0, "eps of |r| ~ sqrt(r^2 + eps^2)", DEFAULT_EPS_ABS_RATE
    )
    sign_n: float = _quantity(
        "rev/s", 1e-6, 10.0, "eps of sgn(n) (motor current)", DEFAULT_EPS_SIGN_N
    )


_SHORTHAND: Final = ("propulsion", "propeller", "motor")


class VehicleFile(VehicleTable):
    """A vehicle file: the twin-thruster shorthand or a list of actuators."""

    name: Name = Field(description="vehicle type name")
    description: Text = Field("", description="free text (origin of the set)")
    hull: HullTable
    power: PowerTable
    smoothing: SmoothingTable = Field(default_factory=SmoothingTable)
    vertical: VerticalTable = Field(
        default_factory=VerticalTable, description="climb/dive rates and minimum altitude"
    )
    propulsion: PropulsionTable | None = Field(None, description="twin-thruster shorthand")
    propeller: PropellerTable | None = Field(None, description="twin-thruster shorthand")
    motor: MotorTable | None = Field(None, description="twin-thruster shorthand")
    thrusters: tuple[ThrusterTable, ...] = Field((), alias="thruster")
    surfaces: tuple[ControlSurfaceTable, ...] = Field((), alias="control_surface")

    @model_validator(mode="before")
    @classmethod
    def _no_shorthand_with_thrusters(cls, data: Any) -> Any:
        """A shorthand table next to [[thruster]] tables is refused before its keys are read."""
        if isinstance(data, dict) and data.get("thruster", []) != []:
            given = [key for key in _SHORTHAND if key in data]
            if given:
                raise ValueError(
                    f"'[{given[0]}]' belongs to the twin-thruster shorthand; with [[thruster]] "
                    "tables give it inside each thruster"
                )
        return data

    @model_validator(mode="after")
    def _one_layout(self) -> VehicleFile:
        """Without [[thruster]] tables: the shorthand's three tables and no control surface."""
        if self.thrusters:
            return self
        if self.surfaces:
            raise ValueError("[[control_surface]] needs [[thruster]] tables")
        missing = [key for key in _SHORTHAND if getattr(self, key) is None]
        if missing:
            raise ValueError(
                f"missing section '[{missing[0]}]' (the twin-thruster shorthand; or give "
                "[[thruster]] tables)"
            )
        return self


__all__ = ["UNITS", "VehicleFile"]
