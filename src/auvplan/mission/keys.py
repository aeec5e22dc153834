"""The reference of every mission-file key, generated from the models of :mod:`.config`.

Nothing here is written by hand: key names, types, defaults, ranges, units and descriptions
come from the pydantic fields, so the reference cannot drift from what the parser accepts.
"""

from __future__ import annotations

import re
import types
from dataclasses import dataclass
from pathlib import PurePath
from typing import Any, Literal, Union, get_args, get_origin

import annotated_types
import tomli_w
from pydantic import BaseModel
from pydantic.fields import FieldInfo
from pydantic_core import PydanticUndefined

from auvplan.io.tables import nested_model
from auvplan.mission.config import MissionConfig

_BOUNDS = (
    (annotated_types.Gt, "gt", ">"),
    (annotated_types.Ge, "ge", ">="),
    (annotated_types.Lt, "lt", "<"),
    (annotated_types.Le, "le", "<="),
)


@dataclass(frozen=True)
class KeyReference:
    """One key: dotted TOML path, type, default, range, unit and description."""

    key: str
    type: str
    default: str
    range: str
    unit: str
    description: str


def _type_name(annotation: Any) -> str:
    if hasattr(annotation, "__metadata__"):  # Annotated: the type it annotates
        return _type_name(get_args(annotation)[0])
    origin = get_origin(annotation)
    if origin is Literal:
        return " | ".join(repr(value) for value in get_args(annotation))
    if origin in (Union, types.UnionType):
        names = [_type_name(a) for a in get_args(annotation) if a is not type(None)]
        return " | ".join(names)
    if origin is tuple:
        arguments = get_args(annotation)
        if len(arguments) == 2 and arguments[1] is Ellipsis:
            return f"[{_type_name(arguments[0])}, ...]"
        return "[" + ", ".join(_type_name(a) for a in arguments) + "]"
    return {float: "number", int: "integer", bool: "boolean", str: "string"}.get(
        annotation, getattr(annotation, "__name__", str(annotation))
    )


def toml_value(value: Any) -> str:
    """``value`` as it is written in a mission file (TOML), not as Python prints it.

    Examples
    --------
    >>> [toml_value(v) for v in (True, (2, 2), "paper", 4294967295, 0.0, 1e-7, PurePath("a"))]
    ['true', '[2, 2]', '"paper"', '4294967295', '0.0', '1e-07', '"a"']
    """
    if isinstance(value, tuple | list):
        return "[" + ", ".join(toml_value(item) for item in value) + "]"
    if isinstance(value, float):
        text = f"{value:.12g}"
        return text if any(mark in text for mark in ".ein") else f"{text}.0"  # a TOML float
    if isinstance(value, PurePath):
        value = str(value)
    return tomli_w.dumps({"v": value}).removeprefix("v = ").strip()


def plain_text(text: str) -> str:
    """A docstring line without Sphinx markup: roles and ````literals```` as Markdown code.

    Examples
    --------
    >>> plain_text("see :func:`auvplan.deconfliction.deconflict` and ``max_range_m``")
    'see `auvplan.deconfliction.deconflict` and `max_range_m`'
    """
    return re.sub(r":[a-z]+:`~?([^`]*)`", r"`\1`", text).replace("``", "`")


def _range(field: FieldInfo) -> str:
    parts = []
    for kind, attribute, symbol in _BOUNDS:
        for item in field.metadata:
            if isinstance(item, kind):
                parts.append(f"{symbol} {toml_value(getattr(item, attribute))}")
    return ", ".join(parts)


def _default(field: FieldInfo) -> str:
    if field.default_factory is not None:
        return ""
    if field.default is PydanticUndefined:
        return "required"
    return "" if field.default is None else toml_value(field.default)


def key_reference(model: type[BaseModel] = MissionConfig, prefix: str = "") -> list[KeyReference]:
    """Every key below ``model``, depth first, tables before their keys.

    Examples
    --------
    >>> keys = {row.key: row for row in key_reference()}
    >>> keys["solver.dt_s"].unit, keys["fleet.safety_radius_m"].default
    ('s', 'required')
    """
    rows: list[KeyReference] = []
    for name, field in model.model_fields.items():
        if field.exclude:
            continue
        key = f"{prefix}{field.alias or name}"
        nested, is_array = nested_model(field.annotation)
        if nested is not None:
            table = f"[[{key}]]" if is_array else f"[{key}]"
            summary = plain_text((nested.__doc__ or "").split("\n")[0])
            rows.append(KeyReference(table, "table", "", "", "", summary))
            rows.extend(key_reference(nested, f"{key}."))
            continue
        extra = field.json_schema_extra if isinstance(field.json_schema_extra, dict) else {}
        rows.append(
            KeyReference(
                key=key,
                type=_type_name(field.annotation),
                default=_default(field),
                range=_range(field),
                unit=str(extra.get("unit", "")),
                description=plain_text(field.description or ""),
            )
        )
    return rows


def key_reference_markdown() -> str:
    """The key reference as a Markdown table."""
    lines = ["| key | type | default | range | unit | meaning |", "|---|---|---|---|---|---|"]
    for row in key_reference():
        cells = [f"`{row.key}`", row.type, row.default, row.range, row.unit, row.description]
        lines.append("| " + " | ".join(cell.replace("|", "\\|") for cell in cells) + " |")
    return "\n".join(lines) + "\n"


def mission_json_schema() -> dict[str, Any]:
    """The JSON Schema of a mission file, for editors (Even Better TOML, taplo, VS Code).

    Generated by pydantic from :class:`~auvplan.mission.config.MissionConfig` with the keys as
    written in the file (aliases); validation by auvplan itself stays the authority (some
    rules, such as "a start has north/east or lat/lon", span several keys).
    """
    schema = MissionConfig.model_json_schema(by_alias=True, mode="validation")
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        **schema,
    }


__all__ = [
    "KeyReference",
    "key_reference",
    "key_reference_markdown",
    "mission_json_schema",
    "plain_text",
    "toml_value",
]
