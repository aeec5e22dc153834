"""Parameter dataclasses: every field documented with a unit; validation names the value."""

from __future__ import annotations

import ast
import dataclasses
import inspect
import re

import numpy as np
import pytest

from auvplan.errors import InputError
from auvplan.io.vehicles import load_vehicle
from auvplan.vehicle import params as params_module
from auvplan.vehicle.params import HullParams, MotorParams, PropellerParams, VehicleParams

CLASSES = (HullParams, PropellerParams, MotorParams, VehicleParams)


def _field_docstrings(cls: type) -> dict[str, str]:
    tree = ast.parse(inspect.getsource(params_module))
    node = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == cls.__name__)
    docs: dict[str, str] = {}
    for current, following in zip(node.body, node.body[1:], strict=False):
        if (
            isinstance(current, ast.AnnAssign)
            and isinstance(current.target, ast.Name)
            and isinstance(following, ast.Expr)
            and isinstance(following.value, ast.Constant)
            and isinstance(following.value.value, str)
        ):
            docs[current.target.id] = following.value.value
    return docs


@pytest.mark.parametrize("cls", CLASSES, ids=lambda c: c.__name__)
def test_every_field_has_a_docstring_with_a_unit(cls: type) -> None:
    docs = _field_docstrings(cls)
    for field in dataclasses.fields(cls):
        assert field.name in docs, f"{cls.__name__}.{field.name} has no docstring"
        unit = re.search(r"\[[^\]]+\]", docs[field.name])
        assert unit, f"{cls.__name__}.{field.name} docstring names no unit: {docs[field.name]!r}"


def test_validation_names_the_offending_value() -> None:
    vehicle = load_vehicle("medusa")
    with pytest.raises(InputError, match=r"m must be > 0, got -1\.0"):
        dataclasses.replace(vehicle.hull, m=-1.0)
    with pytest.raises(InputError, match="N_rr must be <= 0"):
        dataclasses.replace(vehicle.hull, N_rr=6.23)
    with pytest.raises(InputError, match="differ in length"):
        dataclasses.replace(vehicle.propeller, B_Q=np.zeros(3))
    with pytest.raises(InputError, match="needs a current curve"):
        MotorParams(R_a=0.3, K_e=0.05, V_bus=24.0, current_model="measured")
    with pytest.raises(InputError, match="increasing"):
        MotorParams(
            R_a=0.3,
            K_e=0.05,
            V_bus=24.0,
            current_curve_n=np.array([0.0, 2.0, 1.0]),
            current_curve_amps=np.zeros(3),
        )
    with pytest.raises(InputError, match="eps_inflow must be > 0"):
        dataclasses.replace(vehicle, eps_inflow=0.0)
    with pytest.raises(InputError, match="n_max must be finite"):
        dataclasses.replace(vehicle, n_max=float("nan"))


def test_coefficient_arrays_are_read_only() -> None:
    propeller = load_vehicle("medusa").propeller
    with pytest.raises(ValueError, match="read-only"):
        propeller.A_T[0] = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        propeller.diameter = 1.0  # type: ignore[misc]
