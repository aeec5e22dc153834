"""Public names of a package imported from their modules on first use (PEP 562).

A package that keeps its ``import`` light (``auvplan``, :mod:`auvplan.api`,
:mod:`auvplan.viz`) names each public attribute's module in a table and takes its module
``__getattr__`` and ``__dir__`` from :func:`lazy_attributes`; its ``if TYPE_CHECKING:``
imports give type checkers the real names.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Collection, Mapping
from typing import Any


def lazy_attributes(
    package: str, modules: Mapping[str, str], public: Collection[str]
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """``__getattr__`` and ``__dir__`` for the package named ``package``.

    ``modules`` maps each lazily imported name to the module that defines it; the first
    access imports that module and keeps the value in the package's namespace (later
    accesses do not reach ``__getattr__``). ``public`` is the package's ``__all__``.
    """
    namespace = sys.modules[package].__dict__

    def __getattr__(name: str) -> Any:
        module = modules.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted({*namespace, *public})

    return __getattr__, __dir__
