"""TOML tables declared as pydantic models, and their validation errors as one line.

The mission file (:mod:`auvplan.mission.tables`) and the vehicle files
(:mod:`auvplan.io.vehicle_tables`) are both validated through models built on
:class:`TableModel`; :func:`one_line` turns the first error of either into one line naming
the key path (``vehicle[2].start.north``, ``thruster[0].propeller.K_T0``) and the value.
"""

from __future__ import annotations

import re
import types
from typing import Annotated, Any, Union, get_args, get_origin

from pydantic import BaseModel, ConfigDict, Strict, Tag, ValidationError

#: Strict scalar types: TOML's own types, no strings parsed as numbers, no NaN/inf.
Number = Annotated[float, Strict()]
Integer = Annotated[int, Strict()]
Flag = Annotated[bool, Strict()]
Text = Annotated[str, Strict()]


class TableModel(BaseModel):
    """A TOML table: unknown keys and NaN/inf are refused; instances are immutable."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


def nested_model(annotation: Any) -> tuple[type[BaseModel] | None, bool]:
    """The table model inside ``X``, ``X | None`` or ``tuple[X, ...]``, and whether an array."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation, False
    origin = get_origin(annotation)
    if origin in (Union, types.UnionType, tuple):
        for argument in get_args(annotation):
            model, _ = nested_model(argument)
            if model is not None:
                return model, origin is tuple
    return None, False


def _tagged_model(annotation: Any, tag: str) -> type[BaseModel] | None:
    """The member tagged ``tag`` of a discriminated union inside ``annotation`` (or None)."""
    if get_origin(annotation) is Annotated and Tag(tag) in annotation.__metadata__:
        return nested_model(get_args(annotation)[0])[0]
    for argument in get_args(annotation):
        model = _tagged_model(argument, tag)
        if model is not None:
            return model
    return None


def _is_generated(part: str) -> bool:
    """A location part pydantic adds (a validator or union member), not a TOML key."""
    return part == "function-after" or part.startswith(("int", "literal[", "tuple["))


def _keys(model: type[BaseModel] | None) -> dict[str, Any]:
    """The TOML keys of a table model (aliases where given) and their fields."""
    if model is None:
        return {}
    return {f.alias or name: f for name, f in model.model_fields.items() if not f.exclude}


def _walk(
    root: type[BaseModel], location: tuple[int | str, ...]
) -> tuple[str, type[BaseModel] | None]:
    """The key path of ``location`` (``vehicle[2].start.north``) and the table it ends in.

    A union's tag, which pydantic puts in the location of the member's errors, selects the
    member and is left out of the path.
    """
    text = ""
    model: type[BaseModel] | None = root
    annotation: Any = None
    for part in location:
        if isinstance(part, int):
            text += f"[{part}]"
            continue
        field = _keys(model).get(part)
        if field is not None:
            annotation = field.annotation
            model = nested_model(annotation)[0]
        elif (tagged := _tagged_model(annotation, part)) is not None:
            model = tagged
            continue
        elif _is_generated(part):
            continue
        else:
            annotation, model = None, None
        text += f".{part}" if text else part
    return text, model


def one_line(error: ValidationError, root: type[BaseModel], within: tuple[str, ...] = ()) -> str:
    """The first validation error of ``root`` as one line naming the key path and the value.

    ``within``: the path of the validated table in ``root`` (e.g. ``("navigation",)`` for a
    mission's :class:`~auvplan.mission.tables.NavigationConfig` validated on its own).
    """
    first = error.errors(include_url=False)[0]
    location = (*within, *first["loc"])
    path, _ = _walk(root, location)
    if first["type"] == "extra_forbidden":
        allowed = ", ".join(_keys(_walk(root, location[:-1])[1]))
        return f"unknown key {path!r} (allowed here: {allowed})"
    if first["type"] == "missing":
        return f"{path} is required"
    message = str(first["msg"]).removeprefix("Value error, ")
    if first["type"] == "value_error":
        key = re.match(r"([a-z_]+): ", message)
        if key and path:  # a model validator naming one of its keys
            return f"{path}.{message}"
    else:
        value = first.get("input")
        shown = repr(value) if not isinstance(value, dict | list) else type(value).__name__
        message = f"{message}, got {shown[:60]}"
    return f"{path}: {message}" if path else message


__all__ = ["Flag", "Integer", "Number", "TableModel", "Text", "nested_model", "one_line"]
