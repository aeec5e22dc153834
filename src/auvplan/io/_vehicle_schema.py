"""The schema of a vehicle file: every number's unit, accepted spellings and physical range.

An entry is a TOML table ``{ value = ..., unit = "..." }``. :func:`quantity` checks the unit
(a few conversions are accepted at this edge: rpm, mm, ...), converts the value to the
canonical SI unit, and checks it against the key's range; every message names the key
(``propulsion.n_max``) and, for a range, the value and the range with its unit.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.vehicle.params import (
    DEFAULT_EPS_ABS_RATE,
    DEFAULT_EPS_ABS_SPEED,
    DEFAULT_EPS_INFLOW,
    DEFAULT_EPS_SIGN_N,
)

# canonical unit -> accepted spellings and the factor to the canonical unit
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
    "m/s": {"m/s": 1.0},
    "rad/s": {"rad/s": 1.0, "deg/s": math.pi / 180.0},
    "rad": {"rad": 1.0, "deg": math.pi / 180.0},
    "m^2": {"m^2": 1.0, "m2": 1.0, "cm^2": 1e-4},
    "1/rad": {"1/rad": 1.0},
    "1/rad^2": {"1/rad^2": 1.0, "1/rad2": 1.0},
    "s/m": {"s/m": 1.0},
}


@dataclass(frozen=True)
class Range:
    """Canonical unit and physically meaningful closed range ``[low, high]`` of a number."""

    unit: str
    low: float
    high: float


# Ranges span every marine vehicle from a 0.1 kg model to a 10,000 t ship; they reject typos
# and unit slips (n_max = 1e-9 rev/s, a density of 1.025 kg/m^3), not unusual designs.
HULL: Final = {
    "m": Range("kg", 0.1, 1e7),
    "I_z": Range("kg m^2", 1e-4, 1e12),
    "X_udot": Range("kg", -1e7, 0.0),
    "Y_vdot": Range("kg", -1e7, 0.0),
    "N_rdot": Range("kg m^2", -1e12, 0.0),
    "X_u": Range("kg/s", -1e7, 0.0),
    "Y_v": Range("kg/s", -1e7, 0.0),
    "N_r": Range("kg m^2/s", -1e12, 0.0),
    "X_uu": Range("kg/m", -1e7, 0.0),
    "Y_vv": Range("kg/m", -1e7, 0.0),
    "N_rr": Range("kg m^2", -1e12, 0.0),
    "rho": Range("kg/m^3", 950.0, 1100.0),
}
HULL_OPTIONAL: Final = {"linear_damping_fade": Range("s/m", 0.0, 100.0)}
HULL_DEFAULTS: Final = {"linear_damping_fade": 0.0}
CROSSFLOW: Final = {
    "length": Range("m", 0.01, 1e3),
    "height": Range("m", 1e-3, 1e2),
    "drag_coefficient": Range("1", 0.05, 5.0),
}
PROPULSION: Final = {
    "l": Range("m", 0.005, 50.0),
    "n_max": Range("rev/s", 0.5, 1000.0),
    "w_c": Range("rev/s^2", 0.01, 1e5),
}
PROPELLER: Final = {
    "diameter": Range("m", 0.005, 15.0),
    "c_T": Range("1", 0.1, 10.0),
    "c_Q": Range("1", 0.1, 10.0),
}
LINEAR_PROPELLER: Final = {
    "diameter": Range("m", 0.005, 15.0),
    "K_T0": Range("1", 1e-3, 2.0),
    "K_Q0": Range("1", 1e-4, 0.5),
    "J_max": Range("1", 0.01, 3.0),
    "K_T_at_J_max": Range("1", -2.0, 2.0),
    "K_Q_at_J_max": Range("1", 1e-5, 0.5),
}
THRUSTER: Final = {
    "x": Range("m", -1e3, 1e3),
    "y": Range("m", -1e3, 1e3),
    "axis": Range("rad", -math.pi, math.pi),
    "n_max": Range("rev/s", 0.5, 1000.0),
    "w_c": Range("rev/s^2", 0.01, 1e5),
    "wake_fraction": Range("1", 0.0, 0.9),
    "thrust_deduction": Range("1", 0.0, 0.9),
}
THRUSTER_DEFAULTS: Final = {"wake_fraction": 0.0, "thrust_deduction": 0.0}
SURFACE: Final = {
    "x": Range("m", -1e3, 1e3),
    "y": Range("m", -1e3, 1e3),
    "area": Range("m^2", 1e-6, 1e3),
    "lift_slope": Range("1/rad", 1e-3, 10.0),
    "drag_slope": Range("1/rad^2", 0.0, 10.0),
    "delta_max": Range("rad", 1e-3, math.pi / 2),
    "rate_max": Range("rad/s", 1e-3, 1e3),
}
MOTOR: Final = {
    "R_a": Range("ohm", 0.0, 1e3),
    "K_e": Range("V s/rad", 1e-5, 100.0),
    "V_bus": Range("V", 0.5, 1e4),
    "I_0": Range("A", 0.0, 1e3),
}
CURRENT_CURVE: Final = {
    "n": Range("rev/s", 0.0, 1000.0),
    "current": Range("A", 0.0, 1e4),
}
HOTEL: Final = Range("W", 0.0, 1e7)
SMOOTHING: Final = {
    "inflow": Range("m/s", 1e-6, 1.0),
    "abs_speed": Range("m/s", 1e-6, 1.0),
    "abs_rate": Range("rad/s", 1e-6, 1.0),
    "sign_n": Range("rev/s", 1e-6, 10.0),
}
SMOOTHING_DEFAULTS: Final = {
    "inflow": DEFAULT_EPS_INFLOW,
    "abs_speed": DEFAULT_EPS_ABS_SPEED,
    "abs_rate": DEFAULT_EPS_ABS_RATE,
    "sign_n": DEFAULT_EPS_SIGN_N,
}


def normalise_unit(unit: str) -> str:
    return " ".join(unit.replace("*", " ").replace("·", " ").split())


def quantity(
    section: Mapping[str, object], key: str, where: str, expected: Range
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
    accepted = {normalise_unit(k): v for k, v in UNITS[unit].items()}
    if not isinstance(given, str) or normalise_unit(given) not in accepted:
        raise DataFormatError(f"'{qualified}' has unit {given!r}, expected {unit!r}")
    factor = accepted[normalise_unit(given)]
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
    check_range(qualified, np.atleast_1d(result), expected)
    return result


def check_range(qualified: str, values: FloatArray, expected: Range) -> None:
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


def scalar(section: Mapping[str, object], key: str, where: str, expected: Range) -> float:
    value = quantity(section, key, where, expected)
    if not isinstance(value, float):
        raise DataFormatError(f"'{where}.{key}' must be a single number")
    return value


def scalars(
    section: Mapping[str, object],
    where: str,
    expected: Mapping[str, Range],
    defaults: Mapping[str, float] | None = None,
) -> dict[str, float]:
    """Every key of ``expected`` read with :func:`scalar`; absent keys take ``defaults``."""
    defaults = defaults or {}
    return {
        key: defaults[key]
        if key in defaults and key not in section
        else scalar(section, key, where, value_range)
        for key, value_range in expected.items()
    }


def vector(section: Mapping[str, object], key: str, where: str, expected: Range) -> FloatArray:
    value = quantity(section, key, where, expected)
    if isinstance(value, float):
        raise DataFormatError(f"'{where}.{key}' must be a list of numbers")
    return value


def integer(
    section: Mapping[str, object], key: str, where: str, low: int, high: int, default: int | None
) -> int | None:
    """An optional integer ``where.key`` in ``[low, high]`` (``default`` when absent)."""
    value = section.get(key, default)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int):
        raise DataFormatError(f"'{where}.{key}' must be an integer, got {value!r}")
    if not low <= value <= high:
        raise InputError(f"{where}.{key} must be in [{low}, {high}], got {value}")
    return value


def text(section: Mapping[str, object], key: str, where: str, default: str | None = None) -> str:
    """The string ``where.key`` (``default`` when absent and not None)."""
    value = section.get(key, default)
    if not isinstance(value, str) or not value:
        raise DataFormatError(f"missing key '{where}.{key}' (a non-empty string) in vehicle file")
    return value


def flag(section: Mapping[str, object], key: str, where: str, default: bool) -> bool:
    """The boolean ``where.key`` (``default`` when absent)."""
    value = section.get(key, default)
    if not isinstance(value, bool):
        raise DataFormatError(f"'{where}.{key}' must be true or false, got {value!r}")
    return value


def reject_unknown(section: Mapping[str, object], where: str, allowed: set[str]) -> None:
    """Refuse keys the schema does not know (a typo would otherwise be silently ignored)."""
    unknown = sorted(set(section) - allowed)
    if unknown:
        known = ", ".join(sorted(allowed))
        raise DataFormatError(
            f"unknown key '{where}.{unknown[0]}' in vehicle file (known: {known})"
        )


def tables(document: Mapping[str, object], key: str) -> list[Mapping[str, object]]:
    """The array of tables ``[[key]]`` (empty when absent)."""
    entries = document.get(key, [])
    if not isinstance(entries, list) or not all(isinstance(e, Mapping) for e in entries):
        raise DataFormatError(f"'{key}' must be an array of tables [[{key}]] in vehicle file")
    return entries


def section(document: Mapping[str, object], key: str, where: str = "") -> Mapping[str, object]:
    qualified = f"{where}.{key}" if where else key
    if key not in document:
        raise DataFormatError(f"missing section '[{qualified}]' in vehicle file")
    section = document[key]
    if not isinstance(section, Mapping):
        raise DataFormatError(f"'{qualified}' must be a table")
    return section
