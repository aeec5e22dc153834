"""A minimal TOML writer for mission documents (``tomllib`` only reads).

Supports what a mission file holds: top-level tables, arrays of tables, inline tables one
level deep inside them, strings, booleans, integers, finite floats and (nested) arrays of
these. :func:`dumps` output round-trips through :func:`tomllib.loads`.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from typing import Any


def dumps(document: Mapping[str, Mapping[str, Any] | Sequence[Mapping[str, Any]]]) -> str:
    """TOML text of ``document``: each value a table or a list of tables, in the given order.

    Examples
    --------
    >>> print(dumps({"fleet": {"horizon_s": 600.0}, "vehicle": [{"name": "a", "start":
    ...     {"north": 1.0, "east": 2.0}}]}), end="")
    [fleet]
    horizon_s = 600.0
    <BLANKLINE>
    [[vehicle]]
    name = "a"
    start = { north = 1.0, east = 2.0 }
    """
    blocks = []
    for name, content in document.items():
        if isinstance(content, Mapping):
            blocks.append(_table(f"[{name}]", content))
        else:
            blocks.extend(_table(f"[[{name}]]", table) for table in content)
    return "\n".join(blocks)


def _table(header: str, table: Mapping[str, Any]) -> str:
    lines = [header] + [f"{key} = {_value(value)}" for key, value in table.items()]
    return "\n".join(lines) + "\n"


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"TOML has no non-finite float, got {value!r}")
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)  # a valid TOML basic string
    if isinstance(value, Mapping):
        items = ", ".join(f"{key} = {_value(item)}" for key, item in value.items())
        return "{ " + items + " }"
    if isinstance(value, Sequence):
        return "[" + ", ".join(_value(item) for item in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} {value!r} to TOML")
