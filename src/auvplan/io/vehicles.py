"""Vehicle files: TOML parameter sets (one file per vehicle type) and propeller tables.

A vehicle is named either by a packaged type (``"medusa"``) or by the path of a TOML file::

    name = "medusa"
    [hull]        m, I_z, X_udot, Y_vdot, N_rdot, X_u, Y_v, N_r, X_uu, Y_vv, N_rr, rho
    [propulsion]  l, n_max, w_c
    [propeller]   table = "<packaged name>" | "<csv path relative to this file>",
                  diameter, c_T, c_Q, order (optional integer)
    [motor]       R_a, K_e, V_bus, I_0 (optional), current_model (optional),
                  [motor.current_curve] n, current (optional)
    [power]       hotel
    [smoothing]   inflow, abs_speed, abs_rate, sign_n (all optional)

Every number is a table ``{ value = ..., unit = "..." }``; its unit and physical range are
checked (:mod:`auvplan.io._vehicle_schema`). A propeller table is a CSV with ``#``
comment lines, a header ``k,A_T,B_T,A_Q,B_Q`` and one row per harmonic ``k = 0..K``.
"""

from __future__ import annotations

from collections.abc import Mapping
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.io._vehicle_schema import (
    CURRENT_CURVE,
    HOTEL,
    HULL,
    MOTOR,
    PROPELLER,
    PROPULSION,
    SMOOTHING,
    SMOOTHING_DEFAULTS,
    scalar,
    scalars,
    section,
    vector,
)
from auvplan.io.text import read_text, read_toml
from auvplan.vehicle.params import (
    HullParams,
    MotorParams,
    PropellerParams,
    VehicleParams,
)

PROPELLER_COLUMNS: Final = ("k", "A_T", "B_T", "A_Q", "B_Q")

#: Largest magnitude of a Fourier coefficient of C_T* or C_Q* (published series stay below 2).
_MAX_PROPELLER_COEFFICIENT: Final = 10.0


def _data_dir(kind: str) -> Traversable:
    return resources.files("auvplan").joinpath("data", kind)


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
            for entry in _data_dir("vehicles").iterdir()
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
        return _data_dir("vehicles").joinpath(f"{type_or_path}.toml")
    return Path(type_or_path)


def packaged_propeller_tables() -> tuple[str, ...]:
    """Names of the propeller tables shipped with auvplan.

    Examples
    --------
    >>> packaged_propeller_tables()
    ('wageningen_b4-70_pd1.4',)
    """
    return tuple(
        sorted(
            entry.name.removesuffix(".csv")
            for entry in _data_dir("propellers").iterdir()
            if entry.name.endswith(".csv")
        )
    )


def _parse_propeller_table(text: str, origin: str) -> tuple[FloatArray, FloatArray]:
    rows = [
        line.strip()
        for line in text.splitlines()
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not rows or tuple(c.strip() for c in rows[0].split(",")) != PROPELLER_COLUMNS:
        raise DataFormatError(
            f"propeller table {origin}: header must be {','.join(PROPELLER_COLUMNS)}"
        )
    try:
        table = np.array([[float(v) for v in row.split(",")] for row in rows[1:]], dtype=float)
    except ValueError as error:
        raise DataFormatError(f"propeller table {origin}: {error}") from None
    if table.ndim != 2 or table.shape[1] != len(PROPELLER_COLUMNS) or table.shape[0] < 2:
        raise DataFormatError(f"propeller table {origin}: needs rows k,A_T,B_T,A_Q,B_Q for k=0..K")
    if not np.array_equal(table[:, 0], np.arange(table.shape[0])):
        raise DataFormatError(f"propeller table {origin}: k must run 0, 1, 2, ... without gaps")
    if not np.all(np.isfinite(table)):
        raise DataFormatError(f"propeller table {origin}: non-finite coefficient")
    if np.max(np.abs(table[:, 1:])) > _MAX_PROPELLER_COEFFICIENT:
        raise DataFormatError(
            f"propeller table {origin}: coefficient {np.max(np.abs(table[:, 1:])):g} beyond "
            f"±{_MAX_PROPELLER_COEFFICIENT:g} (C_T*, C_Q* are of order 1)"
        )
    return table[:, 0], table[:, 1:]


def load_propeller_table(
    table: str | Path,
    *,
    diameter: float,
    c_T: float = 1.0,
    c_Q: float = 1.0,
    order: int | None = None,
    base_dir: Path | None = None,
) -> PropellerParams:
    """Read a four-quadrant propeller table (packaged name or CSV path).

    Parameters
    ----------
    table : str or Path
        A packaged table name (see :func:`packaged_propeller_tables`) or a CSV path.
    diameter : float
        Propeller diameter [m].
    c_T, c_Q : float
        Thrust and torque correction factors [-].
    order : int, optional
        Harmonics used by default (``None``: all).
    base_dir : Path, optional
        Directory that relative paths are resolved against.

    Returns
    -------
    PropellerParams

    Raises
    ------
    InputError
        If the table is neither packaged nor an existing file.
    DataFormatError
        If the file does not have the expected layout.

    Examples
    --------
    >>> load_propeller_table("wageningen_b4-70_pd1.4", diameter=0.057).max_order
    30
    """
    name = str(table)
    if name in packaged_propeller_tables():
        text = read_text(_data_dir("propellers").joinpath(f"{name}.csv"), what="propeller table")
        source = f"packaged table {name}"
    else:
        path = Path(table)
        if not path.is_absolute() and base_dir is not None:
            path = base_dir / path
        if not path.is_file():
            raise InputError(
                f"propeller table {name!r} is neither packaged "
                f"({', '.join(packaged_propeller_tables())}) nor an existing file"
            )
        text = read_text(path, what="propeller table")
        name = path.stem
        source = str(path)
    _, coefficients = _parse_propeller_table(text, name)
    comments = [line[1:].strip() for line in text.splitlines() if line.startswith("#")]
    citation = " ".join(comments[:5]) if comments else source
    return PropellerParams(
        name=name,
        source=citation,
        diameter=diameter,
        c_T=c_T,
        c_Q=c_Q,
        A_T=coefficients[:, 0],
        B_T=coefficients[:, 1],
        A_Q=coefficients[:, 2],
        B_Q=coefficients[:, 3],
        order=order,
    )


def _parse_vehicle(document: Mapping[str, object], base_dir: Path | None) -> VehicleParams:
    name = document.get("name")
    if not isinstance(name, str) or not name:
        raise DataFormatError("missing key 'name' (a non-empty string) in vehicle file")
    hull_section = section(document, "hull")
    hull = HullParams(**scalars(hull_section, "hull", HULL))
    propulsion = section(document, "propulsion")
    propeller_section = section(document, "propeller")
    table = propeller_section.get("table")
    if not isinstance(table, str):
        raise DataFormatError("missing key 'propeller.table' (packaged name or CSV path)")
    order = propeller_section.get("order")
    if order is not None and (not isinstance(order, int) or isinstance(order, bool)):
        raise DataFormatError(f"'propeller.order' must be an integer, got {order!r}")
    scaling = scalars(propeller_section, "propeller", PROPELLER)
    propeller = load_propeller_table(
        table,
        diameter=scaling["diameter"],
        c_T=scaling["c_T"],
        c_Q=scaling["c_Q"],
        order=order,
        base_dir=base_dir,
    )
    motor_section = section(document, "motor")
    current_model = motor_section.get("current_model", "torque")
    curve_n: FloatArray | None = None
    curve_amps: FloatArray | None = None
    if "current_curve" in motor_section:
        curve = section(motor_section, "current_curve", "motor")
        curve_n = vector(curve, "n", "motor.current_curve", CURRENT_CURVE["n"])
        curve_amps = vector(curve, "current", "motor.current_curve", CURRENT_CURVE["current"])
    electrics = scalars(motor_section, "motor", MOTOR, {"I_0": 0.0})
    motor = MotorParams(
        R_a=electrics["R_a"],
        K_e=electrics["K_e"],
        V_bus=electrics["V_bus"],
        I_0=electrics["I_0"],
        current_model=current_model,  # type: ignore[arg-type]  # validated by MotorParams
        current_curve_n=curve_n,
        current_curve_amps=curve_amps,
    )
    smoothing_section = document.get("smoothing", {})
    if not isinstance(smoothing_section, Mapping):
        raise DataFormatError("'smoothing' must be a table")
    smoothing = scalars(smoothing_section, "smoothing", SMOOTHING, SMOOTHING_DEFAULTS)
    limits = scalars(propulsion, "propulsion", PROPULSION)
    description = document.get("description", "")
    return VehicleParams(
        name=name,
        hull=hull,
        propeller=propeller,
        motor=motor,
        l=limits["l"],
        hotel_power=scalar(section(document, "power"), "hotel", "power", HOTEL),
        n_max=limits["n_max"],
        w_c=limits["w_c"],
        eps_inflow=smoothing["inflow"],
        eps_abs_speed=smoothing["abs_speed"],
        eps_abs_rate=smoothing["abs_rate"],
        eps_sign_n=smoothing["sign_n"],
        description=description if isinstance(description, str) else "",
    )


def load_vehicle(type_or_path: str | Path) -> VehicleParams:
    """Load a vehicle type: a packaged name (``"medusa"``) or the path of a TOML file.

    Parameters
    ----------
    type_or_path : str or Path
        Packaged type name (see :func:`packaged_vehicle_types`) or a vehicle file.

    Returns
    -------
    VehicleParams
        Validated parameters in SI units (propeller speeds in rev/s).

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
        return _parse_vehicle(document, base_dir)
    except (DataFormatError, InputError) as error:
        raise type(error)(f"{origin}: {error}") from None
    except TypeError as error:
        raise DataFormatError(f"{origin}: {error}") from None


__all__ = [
    "PROPELLER_COLUMNS",
    "load_propeller_table",
    "load_vehicle",
    "packaged_propeller_tables",
    "packaged_vehicle_types",
    "vehicle_file",
]
