"""Vehicle files validated by the pydantic models of :mod:`auvplan.io.vehicle_tables`."""

from __future__ import annotations

import dataclasses
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from auvplan.io.text import read_toml
from auvplan.io.vehicles import _parse_vehicle, load_vehicle, packaged_vehicle_types

TESTS = Path(__file__).parents[1]
VEHICLES = resources.files("auvplan").joinpath("data", "vehicles")
MEDUSA_TEXT = VEHICLES.joinpath("medusa.toml").read_text()
REMUS_TEXT = VEHICLES.joinpath("remus100.toml").read_text()

#: Edits of the packaged files exercising unit conversions and optional keys.
VARIANTS = {
    "medusa_rpm_mm": MEDUSA_TEXT.replace(
        '{ value = 75.0,  unit = "rev/s" }', '{ value = 4500, unit = "rpm" }'
    ).replace('{ value = 0.057, unit = "m" }', '{ value = 57, unit = "mm" }'),
    "medusa_order_measured_unsmoothed": MEDUSA_TEXT.split("\n[smoothing]")[0]
    .replace("[propeller]\n", "[propeller]\norder = 5\n")
    .replace('current_model = "torque"', 'current_model = "measured"'),
    "remus_cm_mm_spellings": REMUS_TEXT.replace(
        '{ value = 1.6,   unit = "m" }', '{ value = 160, unit = "cm" }'
    )
    .replace('{ value = 0.14,   unit = "m" }', '{ value = 140, unit = "mm" }')
    .replace('{ value = 0.0133,  unit = "m^2" }', '{ value = 133, unit = "cm^2" }')
    .replace('unit = "kg m^2/s"', 'unit = "kg*m^2/s"')
    .replace('unit = "kg m^2"', 'unit = "kg  m2"'),
}


def _same(old: Any, new: Any, where: str = "vehicle") -> None:
    """Assert ``old`` and ``new`` hold the same types and the same bytes, field by field."""
    assert type(old) is type(new), where
    if dataclasses.is_dataclass(old):
        for field in dataclasses.fields(old):
            _same(getattr(old, field.name), getattr(new, field.name), f"{where}.{field.name}")
    elif isinstance(old, np.ndarray):
        assert (old.dtype, old.shape, old.tobytes()) == (new.dtype, new.shape, new.tobytes()), where
    elif isinstance(old, tuple):
        assert len(old) == len(new), where
        for k, (a, b) in enumerate(zip(old, new, strict=True)):
            _same(a, b, f"{where}[{k}]")
    elif isinstance(old, float):
        assert old.hex() == new.hex(), where
    else:
        assert old == new, where


def _files(tmp_path: Path) -> list[Path]:
    packaged = [Path(str(VEHICLES.joinpath(f"{name}.toml"))) for name in packaged_vehicle_types()]
    examples = sorted(
        path
        for folder in (TESTS, TESTS.parent / "examples")
        for path in folder.rglob("*.toml")
        if "[hull]" in path.read_text(encoding="utf-8")
    )
    variants = []
    for name, text in VARIANTS.items():
        variants.append(tmp_path / f"{name}.toml")
        variants[-1].write_text(text, encoding="utf-8")
    return packaged + examples + variants


def test_models_load_every_file_as_the_hand_written_schema(tmp_path: Path) -> None:
    files = _files(tmp_path)
    assert len(files) >= 6
    for path in files:
        old = _parse_vehicle(read_toml(path, what="vehicle file"), path.resolve().parent)
        _same(old, load_vehicle(path), path.name)
    for name in packaged_vehicle_types():
        document = read_toml(VEHICLES.joinpath(f"{name}.toml"), what="vehicle file")
        _same(_parse_vehicle(document, None), load_vehicle(name), name)
