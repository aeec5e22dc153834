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

from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.io.text import read_text, read_toml
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


@dataclass(frozen=True)
class _Range:
    """Canonical unit and physically meaningful closed range ``[low, high]`` of a number."""

    unit: str
    low: float
    high: float


# Ranges span every marine vehicle from a 0.1 kg model to a 10,000 t ship; they reject typos
# and unit slips (n_max = 1e-9 rev/s, a density of 1.025 kg/m^3), not unusual designs.
_HULL: Final = {
    "m": _Range("kg", 0.1, 1e7),
    "I_z": _Range("kg m^2", 1e-4, 1e12),
    "X_udot": _Range("kg", -1e7, 0.0),
    "Y_vdot": _Range("kg", -1e7, 0.0),
    "N_rdot": _Range("kg m^2", -1e12, 0.0),
    "X_u": _Range("kg/s", -1e7, 0.0),
    "Y_v": _Range("kg/s", -1e7, 0.0),
    "N_r": _Range("kg m^2/s", -1e12, 0.0),
    "X_uu": _Range("kg/m", -1e7, 0.0),
    "Y_vv": _Range("kg/m", -1e7, 0.0),
    "N_rr": _Range("kg m^2", -1e12, 0.0),
    "rho": _Range("kg/m^3", 950.0, 1100.0),
}
_PROPULSION: Final = {
    "l": _Range("m", 0.005, 50.0),
    "n_max": _Range("rev/s", 0.5, 1000.0),
    "w_c": _Range("rev/s^2", 0.01, 1e5),
}
_PROPELLER: Final = {
    "diameter": _Range("m", 0.005, 15.0),
    "c_T": _Range("1", 0.1, 10.0),
    "c_Q": _Range("1", 0.1, 10.0),
}
_MOTOR: Final = {
    "R_a": _Range("ohm", 0.0, 1e3),
    "K_e": _Range("V s/rad", 1e-5, 100.0),
    "V_bus": _Range("V", 0.5, 1e4),
    "I_0": _Range("A", 0.0, 1e3),
}
_CURRENT_CURVE: Final = {
    "n": _Range("rev/s", 0.0, 1000.0),
    "current": _Range("A", 0.0, 1e4),
}
_HOTEL: Final = _Range("W", 0.0, 1e7)
_SMOOTHING: Final = {
    "inflow": _Range("m/s", 1e-6, 1.0),
    "abs_speed": _Range("m/s", 1e-6, 1.0),
    "abs_rate": _Range("rad/s", 1e-6, 1.0),
    "sign_n": _Range("rev/s", 1e-6, 10.0),
}
_SMOOTHING_DEFAULTS: Final = {
    "inflow": DEFAULT_EPS_INFLOW,
    "abs_speed": DEFAULT_EPS_ABS_SPEED,
    "abs_rate": DEFAULT_EPS_ABS_RATE,
    "sign_n": DEFAULT_EPS_SIGN_N,
}
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


def _quantity(
    section: Mapping[str, object], key: str, where: str, expected: _Range
) -> float | FloatArray:
    """The value of ``where.key`` in ``expected.unit``, every element inside its range."""
    qualified = f"{where}.{key}"
    unit = expected.unit
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
        result: float | FloatArray = float(value) * factor
    elif isinstance(value, list) and all(
        isinstance(v, int | float) and not isinstance(v, bool) for v in value
    ):
        result = np.asarray(value, dtype=np.float64) * factor
    else:
        raise DataFormatError(f"'{qualified}' must be a number or a list of numbers, got {value!r}")
    _check_range(qualified, np.atleast_1d(result), expected)
    return result


def _check_range(qualified: str, values: FloatArray, expected: _Range) -> None:
    """Raise InputError naming the key, the first value outside ``expected`` and the range."""
    span = f"range {expected.low:g} … {expected.high:g} {expected.unit}"
    for value in values:
        if not np.isfinite(value):
            raise InputError(f"{qualified} must be finite ({span}), got {value}")
        if value < expected.low:
            raise InputError(
                f"{qualified} must be >= {expected.low:g} {expected.unit} ({span}), got {value:g}"
            )
        if value > expected.high:
            raise InputError(
                f"{qualified} must be <= {expected.high:g} {expected.unit} ({span}), got {value:g}"
            )


def _scalar(section: Mapping[str, object], key: str, where: str, expected: _Range) -> float:
    value = _quantity(section, key, where, expected)
    if not isinstance(value, float):
        raise DataFormatError(f"'{where}.{key}' must be a single number")
    return value


def _scalars(
    section: Mapping[str, object],
    where: str,
    expected: Mapping[str, _Range],
    defaults: Mapping[str, float] | None = None,
) -> dict[str, float]:
    """Every key of ``expected`` read with :func:`_scalar`; absent keys take ``defaults``."""
    defaults = defaults or {}
    return {
        key: defaults[key]
        if key in defaults and key not in section
        else _scalar(section, key, where, value_range)
        for key, value_range in expected.items()
    }


def _vector(section: Mapping[str, object], key: str, where: str, expected: _Range) -> FloatArray:
    value = _quantity(section, key, where, expected)
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
    hull_section = _section(document, "hull")
    hull = HullParams(**_scalars(hull_section, "hull", _HULL))
    propulsion = _section(document, "propulsion")
    propeller_section = _section(document, "propeller")
    table = propeller_section.get("table")
    if not isinstance(table, str):
        raise DataFormatError("missing key 'propeller.table' (packaged name or CSV path)")
    order = propeller_section.get("order")
    if order is not None and (not isinstance(order, int) or isinstance(order, bool)):
        raise DataFormatError(f"'propeller.order' must be an integer, got {order!r}")
    scaling = _scalars(propeller_section, "propeller", _PROPELLER)
    propeller = load_propeller_table(
        table,
        diameter=scaling["diameter"],
        c_T=scaling["c_T"],
        c_Q=scaling["c_Q"],
        order=order,
        base_dir=base_dir,
    )
    motor_section = _section(document, "motor")
    current_model = motor_section.get("current_model", "torque")
    curve_n: FloatArray | None = None
    curve_amps: FloatArray | None = None
    if "current_curve" in motor_section:
        curve = _section(motor_section, "current_curve", "motor")
        curve_n = _vector(curve, "n", "motor.current_curve", _CURRENT_CURVE["n"])
        curve_amps = _vector(curve, "current", "motor.current_curve", _CURRENT_CURVE["current"])
    electrics = _scalars(motor_section, "motor", _MOTOR, {"I_0": 0.0})
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
    smoothing = _scalars(smoothing_section, "smoothing", _SMOOTHING, _SMOOTHING_DEFAULTS)
    limits = _scalars(propulsion, "propulsion", _PROPULSION)
    description = document.get("description", "")
    return VehicleParams(
        name=name,
        hull=hull,
        propeller=propeller,
        motor=motor,
        l=limits["l"],
        hotel_power=_scalar(_section(document, "power"), "hotel", "power", _HOTEL),
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
        document = read_toml(_data_dir("vehicles").joinpath(f"{name}.toml"), what="vehicle file")
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
]
