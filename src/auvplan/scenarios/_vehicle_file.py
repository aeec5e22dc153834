"""The independent checker's own reading of a vehicle file into a :class:`ReferenceModel`.

Reads the TOML document directly (not :func:`auvplan.io.vehicles.load_vehicle`): the hull
(``linear_damping_fade``, ``added_mass_coriolis``, ``[hull.crossflow]``), the actuators
(``[[thruster]]`` with ``[thruster.propeller]`` four-quadrant or linear, and
``[[control_surface]]``; or the twin-thruster shorthand ``[propulsion]``/``[propeller]``:
thrusters ``ps`` at ``y = −l`` and ``sb`` at ``y = +l``) and ``[smoothing]``. Each number is
``{ value, unit }`` in the unit the planner documents, or one of :data:`CONVERSIONS`.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from importlib import resources
from pathlib import Path
from typing import Any, Final

import numpy as np

from auvplan.errors import DataFormatError, InputError
from auvplan.scenarios._model import (
    FourQuadrantPropeller,
    LinearPropeller,
    ReferenceModel,
    Surface,
    Thruster,
)
from auvplan.vehicle.params import (
    DEFAULT_EPS_ABS_RATE,
    DEFAULT_EPS_ABS_SPEED,
    DEFAULT_EPS_INFLOW,
    DEFAULT_EPS_SIGN_N,
)

#: Accepted units other than the expected one: (unit, expected) -> factor to the expected.
CONVERSIONS: Final = {
    ("rpm", "rev/s"): 1.0 / 60.0,
    ("deg", "rad"): math.pi / 180.0,
    ("deg/s", "rad/s"): math.pi / 180.0,
}
#: Hull keys and units.
_HULL: Final = (
    ("m", "kg"), ("I_z", "kg m^2"), ("X_udot", "kg"), ("Y_vdot", "kg"), ("N_rdot", "kg m^2"),
    ("X_u", "kg/s"), ("Y_v", "kg/s"), ("N_r", "kg m^2/s"), ("X_uu", "kg/m"), ("Y_vv", "kg/m"),
    ("N_rr", "kg m^2"), ("rho", "kg/m^3"),
)  # fmt: skip
#: Control-surface keys and units.
_SURFACE: Final = {
    "x": "m", "y": "m", "area": "m^2", "lift_slope": "1/rad", "drag_slope": "1/rad^2",
    "delta_max": "rad", "rate_max": "rad/s",
}  # fmt: skip
#: Smoothing keys, units and the values used when the vehicle file omits them.
_SMOOTHING: Final = {
    "inflow": ("m/s", DEFAULT_EPS_INFLOW),
    "abs_speed": ("m/s", DEFAULT_EPS_ABS_SPEED),
    "abs_rate": ("rad/s", DEFAULT_EPS_ABS_RATE),
    "sign_n": ("rev/s", DEFAULT_EPS_SIGN_N),
}


def _quantity(
    table: Mapping[str, Any], key: str, unit: str, where: str, default: float | None = None
) -> float:
    """``where.key`` in ``unit`` (or converted by :data:`CONVERSIONS`); ``default`` if absent."""
    entry = table.get(key)
    if entry is None and default is not None:
        return default
    if not isinstance(entry, Mapping) or "value" not in entry:
        raise DataFormatError(f"vehicle file: missing {where}.{key} = {{ value, unit }}")
    given = entry.get("unit")
    factor = 1.0 if given == unit else CONVERSIONS.get((str(given), unit))
    if factor is None:
        raise DataFormatError(
            f"vehicle file: {where}.{key} must be in {unit!r} for the check, got {given!r}"
        )
    return float(entry["value"]) * factor


def read_text(name: str, kind: str, suffix: str, base_dirs: tuple[Path, ...]) -> tuple[str, Path]:
    """Text of a packaged data file ``data/<kind>/<name><suffix>`` or of a file ``name``."""
    packaged = resources.files("auvplan").joinpath("data", kind, f"{name}{suffix}")
    if "/" not in name and packaged.is_file():
        return packaged.read_text(encoding="utf-8"), Path()
    for base in base_dirs:
        path = base / name
        if path.is_file():
            return path.read_text(encoding="utf-8"), path.parent
    raise InputError(f"{kind[:-1]} {name!r} is neither packaged nor a file")


def _propeller(
    table: Mapping[str, Any],
    where: str,
    *,
    rho: float,
    smoothing: Mapping[str, float],
    order: int | None,
    vehicle_dir: Path,
) -> FourQuadrantPropeller | LinearPropeller:
    """A thruster's propeller; ``order`` caps the four-quadrant harmonics (None: the file's)."""
    diameter = _quantity(table, "diameter", "m", where)
    if table.get("model", "four_quadrant") == "linear":
        j_max = _quantity(table, "J_max", "1", where)
        k_t0 = _quantity(table, "K_T0", "1", where)
        return LinearPropeller(
            rho=rho,
            diameter=diameter,
            K_T0=k_t0,
            slope=(_quantity(table, "K_T_at_J_max", "1", where) - k_t0) / j_max,
            eps_n=smoothing["sign_n"],
        )
    text, _ = read_text(str(table["table"]), "propellers", ".csv", (vehicle_dir,))
    rows = [line for line in text.splitlines() if line.strip() and not line.startswith("#")]
    coefficients = np.array([[float(v) for v in row.split(",")] for row in rows[1:]])
    max_order = coefficients.shape[0] - 1
    harmonics = min(int(order if order is not None else table.get("order", max_order)), max_order)
    return FourQuadrantPropeller(
        diameter=diameter,
        thrust_scale=_quantity(table, "c_T", "1", where) * 0.5 * rho * math.pi * diameter**2 / 4,
        A_T=coefficients[: harmonics + 1, 1].copy(),
        B_T=coefficients[: harmonics + 1, 2].copy(),
        eps_inflow=smoothing["inflow"],
    )


def _actuators(
    document: Mapping[str, Any], propeller: Any
) -> tuple[tuple[Thruster, ...], tuple[Surface, ...]]:
    """Thrusters and surfaces; ``propeller(table, where)`` reads a propeller table."""
    entries = document.get("thruster", [])
    if not entries:  # the twin-thruster shorthand
        twin = document["propulsion"]
        shared = {
            "x": 0.0, "axis": 0.0, "wake_fraction": 0.0, "thrust_deduction": 0.0,
            "n_max": _quantity(twin, "n_max", "rev/s", "propulsion"),
            "w_c": _quantity(twin, "w_c", "rev/s^2", "propulsion"),
            "propeller": propeller(document["propeller"], "propeller"),
        }  # fmt: skip
        arm = _quantity(twin, "l", "m", "propulsion")
        return (Thruster("ps", y=-arm, **shared), Thruster("sb", y=arm, **shared)), ()
    thrusters = tuple(
        Thruster(
            name=str(entry["name"]),
            x=_quantity(entry, "x", "m", where),
            y=_quantity(entry, "y", "m", where),
            axis=_quantity(entry, "axis", "rad", where),
            wake_fraction=_quantity(entry, "wake_fraction", "1", where, 0.0),
            thrust_deduction=_quantity(entry, "thrust_deduction", "1", where, 0.0),
            n_max=_quantity(entry, "n_max", "rev/s", where),
            w_c=_quantity(entry, "w_c", "rev/s^2", where),
            propeller=propeller(entry["propeller"], f"{where}.propeller"),
        )
        for k, entry in enumerate(entries)
        for where in [f"thruster[{k}]"]
    )
    surfaces = tuple(
        Surface(
            name=str(entry["name"]),
            **{
                key: _quantity(entry, key, unit, f"control_surface[{k}]")
                for key, unit in _SURFACE.items()
            },
        )
        for k, entry in enumerate(document.get("control_surface", []))
    )
    return thrusters, surfaces


def read_reference_model(
    vehicle_type: str, *, propeller_order: int | None, base_dirs: tuple[Path, ...] = (Path(),)
) -> ReferenceModel:
    """The independent model of a vehicle type (packaged name or vehicle-file path).

    ``propeller_order`` is the solver's setting (capped at the table's order); None uses the
    vehicle file's ``propeller.order`` or the whole table, as the planner does. File paths
    are tried relative to each of ``base_dirs``.

    Raises
    ------
    InputError
        If the vehicle type is neither packaged nor a file.
    DataFormatError
        If a number is missing or in a unit the check does not know.
    """
    text, vehicle_dir = read_text(vehicle_type, "vehicles", ".toml", base_dirs)
    document = tomllib.loads(text)
    section = document.get("hull", {})
    hull = {key: _quantity(section, key, unit, "hull") for key, unit in _HULL}
    smoothing = {
        key: _quantity(document.get("smoothing", {}), key, unit, "smoothing", default)
        for key, (unit, default) in _SMOOTHING.items()
    }
    strips = section.get("crossflow")
    stations, crossflow_scale = np.empty(0), 0.0
    if strips is not None:
        length = _quantity(strips, "length", "m", "hull.crossflow")
        count = int(strips.get("strips", 20))
        stations = np.asarray(-0.5 * length + length / count * np.arange(count + 1), dtype=float)
        crossflow_scale = (
            -0.5 * hull["rho"] * _quantity(strips, "height", "m", "hull.crossflow")
            * _quantity(strips, "drag_coefficient", "1", "hull.crossflow") * length / count
        )  # fmt: skip

    def propeller(table: Mapping[str, Any], where: str) -> FourQuadrantPropeller | LinearPropeller:
        return _propeller(
            table, where, rho=hull["rho"], smoothing=smoothing, order=propeller_order,
            vehicle_dir=vehicle_dir,
        )  # fmt: skip

    thrusters, surfaces = _actuators(document, propeller)
    m_u, m_v = hull["m"] - hull["X_udot"], hull["m"] - hull["Y_vdot"]
    has_added_coriolis = bool(section.get("added_mass_coriolis", True))
    return ReferenceModel(
        m_u=m_u,
        m_v=m_v,
        m_r=hull["I_z"] - hull["N_rdot"],
        coriolis_u=m_u if has_added_coriolis else hull["m"],
        coriolis_v=m_v if has_added_coriolis else hull["m"],
        **{key: hull[key] for key in ("X_u", "Y_v", "N_r", "X_uu", "Y_vv", "N_rr", "rho")},
        damping_fade=_quantity(section, "linear_damping_fade", "s/m", "hull", 0.0),
        crossflow_scale=crossflow_scale,
        stations=stations,
        thrusters=thrusters,
        surfaces=surfaces,
        eps_abs_speed=smoothing["abs_speed"],
        eps_abs_rate=smoothing["abs_rate"],
    )
