"""Dependency direction (STYLE B1): core packages never import cli or viz, and
terrain <- planning <- deconfliction; vehicle <- optimization; mission -> everything;
api (the notebook API: mission + viz) is imported only by cli and users; and the command
line is a calm shell (issue 24): no cli module over MAX_CLI_LOGIC_LINES lines of logic."""

from __future__ import annotations

import ast
import io
import tokenize
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


#: Most lines of logic a command-line module may hold (issue 24: a verb parses its arguments,
#: calls one library function, prints what it returned and chooses the exit code).
MAX_CLI_LOGIC_LINES = 120


def _lines_of_logic(path: Path) -> int:
    """Lines holding code, less docstrings and the ``add_argument(...)`` calls.

    Comments and blank lines hold no code token. Every ``add_argument`` call is left out, in
    ``register`` and in the helpers it calls to declare shared options (``_add_common``,
    ``add_navigation_options``): they are the verb's declaration, not its logic.
    """
    text = path.read_text(encoding="utf-8")
    no_code = {
        tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT,
        tokenize.ENCODING, tokenize.ENDMARKER,
    }  # fmt: skip
    code = {
        line
        for token in tokenize.generate_tokens(io.StringIO(text).readline)
        if token.type not in no_code
        for line in range(token.start[0], token.end[0] + 1)
    }
    left_out: set[int] = set()
    for node in ast.walk(ast.parse(text)):
        span: ast.stmt | ast.expr | None = None
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            first = node.body[0] if node.body else None
            if (
                isinstance(first, ast.Expr)
                and isinstance(first.value, ast.Constant)
                and isinstance(first.value.value, str)
            ):
                span = first
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            span = node if node.func.attr == "add_argument" else None
        if span is not None:
            left_out.update(range(span.lineno, (span.end_lineno or span.lineno) + 1))
    return len(code - left_out)


@pytest.mark.parametrize(
    "module", sorted(path.name for path in (SRC / "cli").glob("*.py")), ids=str
)
def test_cli_modules_only_parse_and_call(module: str) -> None:
    """No ``cli/<verb>.py`` over :data:`MAX_CLI_LOGIC_LINES`: the work is in the library."""
    n_lines = _lines_of_logic(SRC / "cli" / module)
    assert n_lines <= MAX_CLI_LOGIC_LINES, (
        f"cli/{module} has {n_lines} lines of logic (> {MAX_CLI_LOGIC_LINES}): move what is "
        "not argument parsing, printing or the exit code into the library module that owns it"
    )


def test_lines_of_logic_leave_out_docstrings_comments_and_arguments(tmp_path: Path) -> None:
    path = tmp_path / "verb.py"
    path.write_text(
        '"""A verb."""\n'
        "\n"
        "def register(parser):\n"
        '    """Add it."""\n'
        "    # a comment\n"
        "    parser.add_argument(\n"
        '        "--flag", help="a flag"\n'
        "    )\n"
        "    parser.set_defaults(run=run)\n"
        "\n"
        "def run(args):\n"
        "    return 0\n",
        encoding="utf-8",
    )
    assert _lines_of_logic(path) == 4  # the two def lines, set_defaults and return
