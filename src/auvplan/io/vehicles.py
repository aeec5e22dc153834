"""Vehicle files: TOML parameter sets, one file per vehicle type.

A vehicle is named either by a packaged type (``"medusa"``, ``"remus100"``) or by the path of
a TOML file. Its actuators are given either by the twin-thruster shorthand (MEDUSA)::

    name = "medusa"
    [hull]        m, I_z, X_udot, Y_vdot, N_rdot, X_u, Y_v, N_r, X_uu, Y_vv, N_rr, rho,
                  linear_damping_fade (optional), added_mass_coriolis (optional bool),
                  [hull.crossflow] length, height, drag_coefficient, strips (optional)
    [propulsion]  l, n_max, w_c                  (two identical thrusters at y = -/+ l)
    [propeller]   table = "<packaged name>" | "<csv path relative to this file>",
                  diameter, c_T, c_Q, order (optional integer)
    [motor]       R_a, K_e, V_bus, I_0 (optional), current_model (optional),
                  [motor.current_curve] n, current (optional)
    [power]       hotel
    [smoothing]   inflow, abs_speed, abs_rate, sign_n (all optional)

or by a list of actuators (any layout; :mod:`auvplan.vehicle.actuators`)::

    [[thruster]]          name, x, y, axis, n_max, w_c, wake_fraction, thrust_deduction
                          (the last two optional)
    [thruster.propeller]  model = "four_quadrant" (as [propeller] above) or "linear":
                          diameter, K_T0, K_Q0, J_max, K_T_at_J_max, K_Q_at_J_max
    [thruster.motor]      as [motor] above
    [[control_surface]]   name, x, y, area, lift_slope, drag_slope, delta_max, rate_max

Every number is a table ``{ value = ..., unit = "..." }``; its unit and physical range are
checked (:mod:`auvplan.io._vehicle_schema`). Four-quadrant propeller tables are read by
:mod:`auvplan.io._propeller_tables`.
"""

from __future__ import annotations

from collections.abc import Mapping
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Any, Final

import numpy as np
from pydantic import ValidationError

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.io._propeller_tables import (
    PROPELLER_COLUMNS,
    data_dir,
    load_propeller_table,
    packaged_propeller_tables,
)
from auvplan.io._vehicle_schema import (
    CROSSFLOW,
    CURRENT_CURVE,
    HOTEL,
    HULL,
    HULL_DEFAULTS,
    HULL_OPTIONAL,
    LINEAR_PROPELLER,
    MOTOR,
    PROPELLER,
    PROPULSION,
    SMOOTHING,
    SMOOTHING_DEFAULTS,
    SURFACE,
    THRUSTER,
    THRUSTER_DEFAULTS,
    flag,
    integer,
    reject_unknown,
    scalar,
    scalars,
    section,
    tables,
    text,
    vector,
)
from auvplan.io.tables import one_line
from auvplan.io.text import read_toml
from auvplan.io.vehicle_tables import (
    FourQuadrantPropellerTable,
    LinearPropellerTable,
    MotorTable,
    ThrusterTable,
    VehicleFile,
)
from auvplan.vehicle.actuators import (
    ActuatedVehicleParams,
    ControlSurfaceParams,
    ThrusterParams,
)
from auvplan.vehicle.params import (
    CrossFlowParams,
    HullParams,
    LinearPropellerParams,
    MotorParams,
    Propeller,
    VehicleParams,
)

#: Validation errors of a value outside its range or set (InputError); the others are
#: errors of the file's layout (DataFormatError).
_OUT_OF_RANGE: Final = frozenset(
    {
        "greater_than",
        "greater_than_equal",
        "less_than",
        "less_than_equal",
        "finite_number",
        "literal_error",
    }
)


def packaged_vehicle_types() -> tuple[str, ...]:
    """Names of the vehicle types shipped with auvplan.

    Examples
    --------
    >>> "medusa" in packaged_vehicle_types()
    True
    """
    return tuple(
        sorted(
            entry.name.removesuffix(".toml")
            for entry in data_dir("vehicles").iterdir()
            if entry.name.endswith(".toml")
        )
    )


def vehicle_file(type_or_path: str) -> Path | Traversable:
    """The file a vehicle type is read from: the packaged TOML of a type name, else the path.

    Examples
    --------
    >>> vehicle_file("medusa").name, vehicle_file("boats/mine.toml")
    ('medusa.toml', PosixPath('boats/mine.toml'))
    """
    if type_or_path in packaged_vehicle_types():
        return data_dir("vehicles").joinpath(f"{type_or_path}.toml")
    return Path(type_or_path)


def _propeller(
    table: FourQuadrantPropellerTable | LinearPropellerTable, base_dir: Path | None
) -> Propeller:
    if isinstance(table, LinearPropellerTable):
        return LinearPropellerParams(**table.model_dump(exclude={"model"}))
    return load_propeller_table(
        table.table,
        diameter=table.diameter,
        c_T=table.c_T,
        c_Q=table.c_Q,
        order=table.order,
        base_dir=base_dir,
    )


def _motor(table: MotorTable) -> MotorParams:
    curve = table.current_curve
    return MotorParams(
        R_a=table.R_a,
        K_e=table.K_e,
        V_bus=table.V_bus,
        I_0=table.I_0,
        current_model=table.current_model,
        current_curve_n=None if curve is None else np.asarray(curve.n, dtype=np.float64),
        current_curve_amps=None if curve is None else np.asarray(curve.current, dtype=np.float64),
    )


def _thruster(table: ThrusterTable, base_dir: Path | None) -> ThrusterParams:
    return ThrusterParams(
        propeller=_propeller(table.propeller, base_dir),
        motor=_motor(table.motor),
        **table.model_dump(exclude={"propeller", "motor"}),
    )


def _vehicle(tables: VehicleFile, base_dir: Path | None) -> VehicleParams | ActuatedVehicleParams:
    """The parameters of a validated vehicle file (SI units, propeller speeds in rev/s)."""
    hull = tables.hull
    crossflow = hull.crossflow
    common: dict[str, Any] = {
        "name": tables.name,
        "hull": HullParams(
            **hull.model_dump(exclude={"crossflow"}),
            crossflow=None if crossflow is None else CrossFlowParams(**crossflow.model_dump()),
        ),
        "hotel_power": tables.power.hotel,
        **{f"eps_{key}": value for key, value in tables.smoothing.model_dump().items()},
        "description": tables.description,
    }
    propulsion, propeller, motor = tables.propulsion, tables.propeller, tables.motor
    if propulsion is not None and propeller is not None and motor is not None:  # the shorthand
        return VehicleParams(
            propeller=_propeller(propeller, base_dir),
            motor=_motor(motor),
            **propulsion.model_dump(),
            **common,
        )
    return ActuatedVehicleParams(
        thrusters=tuple(_thruster(table, base_dir) for table in tables.thrusters),
        surfaces=tuple(ControlSurfaceParams(**table.model_dump()) for table in tables.surfaces),
        **common,
    )


def _parse_hull(document: Mapping[str, object]) -> HullParams:
    hull_section = section(document, "hull")
    crossflow: CrossFlowParams | None = None
    if "crossflow" in hull_section:
        strips_section = section(hull_section, "crossflow", "hull")
        reject_unknown(strips_section, "hull.crossflow", {*CROSSFLOW, "strips"})
        strips = integer(strips_section, "strips", "hull.crossflow", 1, 1000, None)
        if strips is None:
            raise DataFormatError(
                "missing key 'hull.crossflow.strips' (an integer) in vehicle file"
            )
        crossflow = CrossFlowParams(
            **scalars(strips_section, "hull.crossflow", CROSSFLOW), strips=strips
        )
    return HullParams(
        **scalars(hull_section, "hull", HULL),
        **scalars(hull_section, "hull", HULL_OPTIONAL, HULL_DEFAULTS),
        added_mass_coriolis=flag(hull_section, "added_mass_coriolis", "hull", True),
        crossflow=crossflow,
    )


def _parse_propeller(
    propeller_section: Mapping[str, object], where: str, base_dir: Path | None
) -> Propeller:
    model = text(propeller_section, "model", where, "four_quadrant")
    if model == "linear":
        coefficients = scalars(propeller_section, where, LINEAR_PROPELLER)
        return LinearPropellerParams(
            name=text(propeller_section, "name", where, "linear"),
            source=text(propeller_section, "source", where, "vehicle file"),
            **coefficients,
        )
    if model != "four_quadrant":
        raise DataFormatError(f"'{where}.model' must be 'four_quadrant' or 'linear', got {model!r}")
    table = propeller_section.get("table")
    if not isinstance(table, str):
        raise DataFormatError(f"missing key '{where}.table' (packaged name or CSV path)")
    scaling = scalars(propeller_section, where, PROPELLER)
    return load_propeller_table(
        table,
        diameter=scaling["diameter"],
        c_T=scaling["c_T"],
        c_Q=scaling["c_Q"],
        order=integer(propeller_section, "order", where, -(2**31), 2**31, None),
        base_dir=base_dir,
    )


def _parse_motor(motor_section: Mapping[str, object], where: str) -> MotorParams:
    current_model = motor_section.get("current_model", "torque")
    curve_n: FloatArray | None = None
    curve_amps: FloatArray | None = None
    if "current_curve" in motor_section:
        curve = section(motor_section, "current_curve", where)
        curve_n = vector(curve, "n", f"{where}.current_curve", CURRENT_CURVE["n"])
        curve_amps = vector(curve, "current", f"{where}.current_curve", CURRENT_CURVE["current"])
    electrics = scalars(motor_section, where, MOTOR, {"I_0": 0.0})
    return MotorParams(
        R_a=electrics["R_a"],
        K_e=electrics["K_e"],
        V_bus=electrics["V_bus"],
        I_0=electrics["I_0"],
        current_model=current_model,  # type: ignore[arg-type]  # validated by MotorParams
        current_curve_n=curve_n,
        current_curve_amps=curve_amps,
    )


def _parse_thruster(
    entry: Mapping[str, object], where: str, base_dir: Path | None
) -> ThrusterParams:
    reject_unknown(entry, where, {*THRUSTER, "name", "propeller", "motor"})
    return ThrusterParams(
        name=text(entry, "name", where),
        propeller=_parse_propeller(
            section(entry, "propeller", where), f"{where}.propeller", base_dir
        ),
        motor=_parse_motor(section(entry, "motor", where), f"{where}.motor"),
        **scalars(entry, where, THRUSTER, THRUSTER_DEFAULTS),
    )


def _parse_surface(entry: Mapping[str, object], where: str) -> ControlSurfaceParams:
    reject_unknown(entry, where, {*SURFACE, "name"})
    return ControlSurfaceParams(name=text(entry, "name", where), **scalars(entry, where, SURFACE))


def _parse_vehicle(
    document: Mapping[str, object], base_dir: Path | None
) -> VehicleParams | ActuatedVehicleParams:
    name = document.get("name")
    if not isinstance(name, str) or not name:
        raise DataFormatError("missing key 'name' (a non-empty string) in vehicle file")
    hull = _parse_hull(document)
    smoothing_section = document.get("smoothing", {})
    if not isinstance(smoothing_section, Mapping):
        raise DataFormatError("'smoothing' must be a table")
    smoothing = scalars(smoothing_section, "smoothing", SMOOTHING, SMOOTHING_DEFAULTS)
    description = document.get("description", "")
    common = {
        "name": name,
        "hull": hull,
        "hotel_power": scalar(section(document, "power"), "hotel", "power", HOTEL),
        "eps_inflow": smoothing["inflow"],
        "eps_abs_speed": smoothing["abs_speed"],
        "eps_abs_rate": smoothing["abs_rate"],
        "eps_sign_n": smoothing["sign_n"],
        "description": description if isinstance(description, str) else "",
    }
    thrusters = tables(document, "thruster")
    if not thrusters:  # the twin-thruster shorthand
        if "control_surface" in document:
            raise DataFormatError("[[control_surface]] needs [[thruster]] tables in vehicle file")
        limits = scalars(section(document, "propulsion"), "propulsion", PROPULSION)
        return VehicleParams(
            propeller=_parse_propeller(section(document, "propeller"), "propeller", base_dir),
            motor=_parse_motor(section(document, "motor"), "motor"),
            l=limits["l"],
            n_max=limits["n_max"],
            w_c=limits["w_c"],
            **common,  # type: ignore[arg-type]  # the types of common are checked above
        )
    for shorthand in ("propulsion", "propeller", "motor"):
        if shorthand in document:
            raise DataFormatError(
                f"'[{shorthand}]' belongs to the twin-thruster shorthand; with [[thruster]] "
                "tables give it inside each thruster"
            )
    return ActuatedVehicleParams(
        thrusters=tuple(
            _parse_thruster(entry, f"thruster[{k}]", base_dir) for k, entry in enumerate(thrusters)
        ),
        surfaces=tuple(
            _parse_surface(entry, f"control_surface[{k}]")
            for k, entry in enumerate(tables(document, "control_surface"))
        ),
        **common,  # type: ignore[arg-type]  # the types of common are checked above
    )


def load_vehicle(type_or_path: str | Path) -> VehicleParams | ActuatedVehicleParams:
    """Load a vehicle type: a packaged name (``"medusa"``) or the path of a TOML file.

    Parameters
    ----------
    type_or_path : str or Path
        Packaged type name (see :func:`packaged_vehicle_types`) or a vehicle file.

    Returns
    -------
    VehicleParams or ActuatedVehicleParams
        Validated parameters in SI units (propeller speeds in rev/s): the twin-thruster
        shorthand or the actuator list, as the file gives them.

    Raises
    ------
    InputError
        Unknown type / missing file, or a value out of range (the message names it).
    DataFormatError
        Malformed TOML, a missing key or a wrong unit (the message names the key).

    Examples
    --------
    >>> vehicle = load_vehicle("medusa")
    >>> vehicle.hull.m, vehicle.propeller.diameter, vehicle.n_max
    (30.0, 0.057, 75.0)
    """
    name = str(type_or_path)
    if isinstance(type_or_path, str) and name in packaged_vehicle_types():
        document = read_toml(vehicle_file(name), what="vehicle file")
        base_dir: Path | None = None
        origin = f"packaged vehicle {name}"
    else:
        path = Path(type_or_path)
        if not path.exists():
            raise InputError(
                f"unknown vehicle type or missing file {name!r} "
                f"(packaged types: {', '.join(packaged_vehicle_types())})"
            )
        document = read_toml(path, what="vehicle file")
        base_dir = path.resolve().parent
        origin = str(path)
    try:
        tables = VehicleFile.model_validate(document)
    except ValidationError as error:
        kind = InputError if error.errors()[0]["type"] in _OUT_OF_RANGE else DataFormatError
        raise kind(f"{origin}: {one_line(error, VehicleFile)}") from None
    try:
        return _vehicle(tables, base_dir)
    except (DataFormatError, InputError) as error:
        raise type(error)(f"{origin}: {error}") from None


__all__ = [
    "PROPELLER_COLUMNS",
    "load_propeller_table",
    "load_vehicle",
    "packaged_propeller_tables",
    "packaged_vehicle_types",
    "vehicle_file",
]
