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

Every number is a table ``{ value = ..., unit = "..." }``; the unit is checked (a few
conversions are accepted at this edge: rpm, mm, ...). A propeller table is a CSV with ``#``
comment lines, a header ``k,A_T,B_T,A_Q,B_Q`` and one row per harmonic ``k = 0..K``.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.vehicle.params import (
    DEFAULT_EPS_ABS_RATE,
    DEFAULT_EPS_ABS_SPEED,
    DEFAULT_EPS_INFLOW,
    DEFAULT_EPS_SIGN_N,
    HullParams,
    MotorParams,
    PropellerParams,
    VehicleParams,
)

PROPELLER_COLUMNS: Final = ("k", "A_T", "B_T", "A_Q", "B_Q")

# canonical unit -> accepted spellings and the factor to the canonical unit
_UNITS: Final[dict[str, dict[str, float]]] = {
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
    "m/s": {"m/s": 1.0},
    "rad/s": {"rad/s": 1.0},
}

_HULL_UNITS: Final = {
    "m": "kg",
    "I_z": "kg m^2",
    "X_udot": "kg",
    "Y_vdot": "kg",
    "N_rdot": "kg m^2",
    "X_u": "kg/s",
    "Y_v": "kg/s",
    "N_r": "kg m^2/s",
    "X_uu": "kg/m",
    "Y_vv": "kg/m",
    "N_rr": "kg m^2",
    "rho": "kg/m^3",
}
_SMOOTHING: Final = {
    "inflow": ("m/s", DEFAULT_EPS_INFLOW),
    "abs_speed": ("m/s", DEFAULT_EPS_ABS_SPEED),
    "abs_rate": ("rad/s", DEFAULT_EPS_ABS_RATE),
    "sign_n": ("rev/s", DEFAULT_EPS_SIGN_N),
}


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


def _normalise_unit(unit: str) -> str:
    return " ".join(unit.replace("*", " ").replace("·", " ").split())


def _quantity(section: Mapping[str, object], key: str, where: str, unit: str) -> float | FloatArray:
    qualified = f"{where}.{key}"
    if key not in section:
        raise DataFormatError(f"missing key '{qualified}' in vehicle file")
    entry = section[key]
    if not isinstance(entry, Mapping) or "value" not in entry or "unit" not in entry:
        raise DataFormatError(
            f"'{qualified}' must be a table {{ value = ..., unit = \"{unit}\" }}, got {entry!r}"
        )
    given = entry["unit"]
    accepted = {_normalise_unit(k): v for k, v in _UNITS[unit].items()}
    if not isinstance(given, str) or _normalise_unit(given) not in accepted:
        raise DataFormatError(f"'{qualified}' has unit {given!r}, expected {unit!r}")
    factor = accepted[_normalise_unit(given)]
    value = entry["value"]
    if isinstance(value, bool):
        raise DataFormatError(f"'{qualified}' must be a number, got {value!r}")
    if isinstance(value, int | float):
        return float(value) * factor
    if isinstance(value, list) and all(
        isinstance(v, int | float) and not isinstance(v, bool) for v in value
    ):
        return np.asarray(value, dtype=np.float64) * factor
    raise DataFormatError(f"'{qualified}' must be a number or a list of numbers, got {value!r}")


def _scalar(section: Mapping[str, object], key: str, where: str, unit: str) -> float:
    value = _quantity(section, key, where, unit)
    if not isinstance(value, float):
        raise DataFormatError(f"'{where}.{key}' must be a single number")
    return value


def _vector(section: Mapping[str, object], key: str, where: str, unit: str) -> FloatArray:
    value = _quantity(section, key, where, unit)
    if isinstance(value, float):
        raise DataFormatError(f"'{where}.{key}' must be a list of numbers")
    return value


def _section(document: Mapping[str, object], key: str, where: str = "") -> Mapping[str, object]:
    qualified = f"{where}.{key}" if where else key
    if key not in document:
        raise DataFormatError(f"missing section '[{qualified}]' in vehicle file")
    section = document[key]
    if not isinstance(section, Mapping):
        raise DataFormatError(f"'{qualified}' must be a table")
    return section


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
        text = _data_dir("propellers").joinpath(f"{name}.csv").read_text(encoding="utf-8")
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
        text = path.read_text(encoding="utf-8")
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
    hull_section = _section(document, "hull")
    hull = HullParams(
        **{key: _scalar(hull_section, key, "hull", unit) for key, unit in _HULL_UNITS.items()}
    )
    propulsion = _section(document, "propulsion")
    propeller_section = _section(document, "propeller")
    table = propeller_section.get("table")
    if not isinstance(table, str):
        raise DataFormatError("missing key 'propeller.table' (packaged name or CSV path)")
    order = propeller_section.get("order")
    if order is not None and (not isinstance(order, int) or isinstance(order, bool)):
        raise DataFormatError(f"'propeller.order' must be an integer, got {order!r}")
    propeller = load_propeller_table(
        table,
        diameter=_scalar(propeller_section, "diameter", "propeller", "m"),
        c_T=_scalar(propeller_section, "c_T", "propeller", "1"),
        c_Q=_scalar(propeller_section, "c_Q", "propeller", "1"),
        order=order,
        base_dir=base_dir,
    )
    motor_section = _section(document, "motor")
    current_model = motor_section.get("current_model", "torque")
    curve_n: FloatArray | None = None
    curve_amps: FloatArray | None = None
    if "current_curve" in motor_section:
        curve = _section(motor_section, "current_curve", "motor")
        curve_n = _vector(curve, "n", "motor.current_curve", "rev/s")
        curve_amps = _vector(curve, "current", "motor.current_curve", "A")
    motor = MotorParams(
        R_a=_scalar(motor_section, "R_a", "motor", "ohm"),
        K_e=_scalar(motor_section, "K_e", "motor", "V s/rad"),
        V_bus=_scalar(motor_section, "V_bus", "motor", "V"),
        I_0=_scalar(motor_section, "I_0", "motor", "A") if "I_0" in motor_section else 0.0,
        current_model=current_model,  # type: ignore[arg-type]  # validated by MotorParams
        current_curve_n=curve_n,
        current_curve_amps=curve_amps,
    )
    smoothing_section = document.get("smoothing", {})
    if not isinstance(smoothing_section, Mapping):
        raise DataFormatError("'smoothing' must be a table")
    smoothing = {
        key: _scalar(smoothing_section, key, "smoothing", unit)
        if key in smoothing_section
        else default
        for key, (unit, default) in _SMOOTHING.items()
    }
    description = document.get("description", "")
    return VehicleParams(
        name=name,
        hull=hull,
        propeller=propeller,
        motor=motor,
        l=_scalar(propulsion, "l", "propulsion", "m"),
        hotel_power=_scalar(_section(document, "power"), "hotel", "power", "W"),
        n_max=_scalar(propulsion, "n_max", "propulsion", "rev/s"),
        w_c=_scalar(propulsion, "w_c", "propulsion", "rev/s^2"),
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
        text = _data_dir("vehicles").joinpath(f"{name}.toml").read_text(encoding="utf-8")
        base_dir: Path | None = None
        origin = f"packaged vehicle {name}"
    else:
        path = Path(type_or_path)
        if not path.is_file():
            raise InputError(
                f"unknown vehicle type or missing file {name!r} "
                f"(packaged types: {', '.join(packaged_vehicle_types())})"
            )
        text = path.read_text(encoding="utf-8")
        base_dir = path.resolve().parent
        origin = str(path)
    try:
        document = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise DataFormatError(f"vehicle file {origin} is not valid TOML: {error}") from None
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
]
