"""Dependency direction (STYLE B1): core packages never import cli or viz, and
terrain <- planning <- deconfliction; vehicle <- optimization; mission -> everything;
api (the notebook API: mission + viz) is imported only by cli and users."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).parents[1] / "src" / "auvplan"

# package -> auvplan subpackages it must NOT import
FORBIDDEN = {
    "terrain": {
        "planning",
        "deconfliction",
        "vehicle",
        "optimization",
        "mission",
        "cli",
        "viz",
        "api",
    },
    "planning": {"deconfliction", "vehicle", "optimization", "mission", "cli", "viz", "api"},
    "deconfliction": {"vehicle", "optimization", "mission", "cli", "viz", "api"},
    "vehicle": {
        "terrain",
        "planning",
        "deconfliction",
        "optimization",
        "mission",
        "cli",
        "viz",
        "api",
    },
    "optimization": {"terrain", "planning", "deconfliction", "mission", "cli", "viz", "api"},
    "io": {"mission", "cli", "viz", "optimization", "export", "api", "record"},
    # the output folder's record: above io, terrain, vehicle and export; below mission
    "record": {
        "planning",
        "deconfliction",
        "optimization",
        "navigation",
        "ocean",
        "mission",
        "scenarios",
        "sweep",
        "cli",
        "viz",
        "api",
    },
    "export": {
        "record",
        "planning",
        "deconfliction",
        "vehicle",
        "optimization",
        "mission",
        "scenarios",
        "cli",
        "viz",
        "api",
    },
    "mission": {"cli", "viz", "scenarios", "api"},
    "navigation": {
        "planning",
        "deconfliction",
        "vehicle",
        "optimization",
        "mission",
        "cli",
        "viz",
        "io",
        "api",
    },
    "ocean": {
        "planning",
        "deconfliction",
        "vehicle",
        "optimization",
        "mission",
        "io",
        "cli",
        "viz",
        "api",
    },
    "scenarios": {"optimization", "mission", "cli", "viz", "api"},
    "sweep": {"cli", "viz", "api"},
    "viz": {"cli", "api"},
    "api": {"cli"},
}


def _imported_subpackages(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found: set[str] = set()
    for node in ast.walk(tree):
        names: list[str] = []
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module]
        for name in names:
            parts = name.split(".")
            if parts[0] == "auvplan" and len(parts) > 1:
                found.add(parts[1])
    return found


@pytest.mark.parametrize("package", sorted(FORBIDDEN))
def test_dependency_direction(package: str) -> None:
    offenders = {
        str(path.relative_to(SRC)): bad
        for path in sorted((SRC / package).rglob("*.py"))
        if (bad := _imported_subpackages(path) & FORBIDDEN[package])
    }
    assert not offenders, f"{package} imports forbidden subpackages: {offenders}"


def _names_taken_from_the_package_face(path: Path) -> set[str]:
    """Names a module imports from ``auvplan`` itself that are not modules of their own.

    ``from auvplan import X`` where ``X`` is defined in ``auvplan/__init__.py`` (the public
    face, which imports the layers lazily) points up from every layer; a top-level module
    (``auvplan/errors.py``, ``auvplan/_version.py`` ...) is a layer below all of them.
    """
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return {
        alias.name
        for node in ast.walk(tree)
        if isinstance(node, ast.ImportFrom) and node.module == "auvplan" and node.level == 0
        for alias in node.names
        if not (SRC / f"{alias.name}.py").is_file()
    }


def test_no_module_imports_the_package_face() -> None:
    """No upward arrow: nothing below the face takes a name from ``auvplan/__init__.py``."""
    offenders = {
        str(path.relative_to(SRC)): names
        for path in sorted(SRC.rglob("*.py"))
        if path != SRC / "__init__.py" and (names := _names_taken_from_the_package_face(path))
    }
    assert not offenders, f"upward imports from the package face: {offenders}"
