"""Vehicle files: TOML parameter sets, one file per vehicle type.

A vehicle is named either by a packaged type (``"medusa"``, ``"remus100"``) or by the path of
a TOML file. Its actuators are given either by the twin-thruster shorthand (MEDUSA)::

    name = "medusa"
    description = "..." (optional)
    [hull]        m, I_z, X_udot, Y_vdot, N_rdot, X_u, Y_v, N_r, X_uu, Y_vv, N_rr, rho,
                  linear_damping_fade (optional), added_mass_coriolis (optional bool),
                  [hull.crossflow] length, height, drag_coefficient, strips (optional)
    [propulsion]  l, n_max, w_c                  (two identical thrusters at y = -/+ l)
    [propeller]   table = "<packaged name>" | "<csv path relative to this file>",
                  diameter, c_T, c_Q, order (optional integer)
    [motor]       R_a, K_e, V_bus, I_0 (optional), current_model (optional),
                  [motor.current_curve] n, current (optional)
    [power]       hotel, battery_capacity (optional; absent: unknown)
    [smoothing]   inflow, abs_speed, abs_rate, sign_n (all optional)
    [vertical]    climb_rate, dive_rate, min_altitude (all optional; the depth profile's limits)

or by a list of actuators (any layout; :mod:`auvplan.vehicle.actuators`)::

    [[thruster]]          name, x, y, axis, n_max, w_c, wake_fraction, thrust_deduction
                          (the last two optional)
    [thruster.propeller]  model = "four_quadrant" (as [propeller] above) or "linear":
                          diameter, K_T0, K_Q0, J_max, K_T_at_J_max, K_Q_at_J_max,
                          name, source (optional)
    [thruster.motor]      as [motor] above
    [[control_surface]]   name, x, y, area, lift_slope, drag_slope, delta_max, rate_max

Every number is a table ``{ value = ..., unit = "..." }``; its unit and physical range are
checked by the pydantic models of :mod:`auvplan.io.vehicle_tables`. Four-quadrant propeller
tables are read by :mod:`auvplan.io._propeller_tables`.
"""

from __future__ import annotations

from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Any, Final

import numpy as np
from pydantic import ValidationError

from auvplan.errors import DataFormatError, InputError
from auvplan.io._propeller_tables import (
    PROPELLER_COLUMNS,
    data_dir,
    load_propeller_table,
    packaged_propeller_tables,
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
from auvplan.vehicle.vertical import DepthLimits

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
        "battery_capacity": tables.power.battery_capacity,
        "depth_limits": DepthLimits(**tables.vertical.model_dump()),
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
        Malformed TOML, a missing or unknown key or a wrong unit (the message names the key).

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
