"""Fuzzing ``auvplan plan`` with mutated mission files: never a traceback, never a leftover.

Valid missions (the packaged demo and ``examples/missions/*.toml``) are mutated as a careless
user would: keys deleted, duplicated or renamed (wrong unit suffixes), values of the wrong
type, extreme numbers (0, -1, 1e-300, 1e300, nan, inf, nan-like strings), bad vehicle names,
optional keys added with such values. Each mutant runs in-process through
``auvplan plan MISSION -o OUT --stage preplan --no-figures`` and must end with exit code 0, 2
or 3, at most one line on stderr, no traceback, and nothing in the mission's folder but the
inputs and (on success) the output folder.

Run as a script (``python tests/cli/test_fuzz_missions.py N SEED [STAGE]``) it tries ``N``
random mutants up to ``STAGE`` (default preplan) and prints every failure, for a longer
campaign than the test suite's.
"""

from __future__ import annotations

import copy
import json
import math
import random
import signal
import sys
import tempfile
from collections.abc import Callable, Sequence
from importlib import resources
from pathlib import Path
from types import FrameType
from typing import Any

from hypothesis import HealthCheck, event, given, note, settings
from hypothesis import strategies as st

from auvplan.cli.main import main

EXAMPLES = Path(__file__).parents[2] / "examples" / "missions"
SHARED_BATHYMETRY = Path(__file__).parents[2] / ".." / "shared" / "data" / "bathymetry"
#: An example taking longer than this [s] is a hang.
TIMEOUT_S = 60.0

Choose = Callable[[Sequence[Any]], Any]
Path_ = tuple[str | int, ...]


def _seeds() -> dict[str, dict[str, Any]]:
    """Valid mission documents by name (terrain files made absolute; missing ones skipped)."""
    import tomllib

    texts = {"demo": resources.files("auvplan").joinpath("data/missions/demo.toml").read_text()}
    texts |= {path.stem: path.read_text() for path in sorted(EXAMPLES.glob("*.toml"))}
    seeds = {}
    for name, text in texts.items():
        document = tomllib.loads(text)
        terrain = document.get("terrain", {})
        if "file" in terrain:
            path = (EXAMPLES / terrain["file"]).resolve()
            if not path.is_file():
                continue
            terrain["file"] = str(path)
        seeds[name] = document
    return seeds


SEEDS = _seeds()

EXTREMES: tuple[Any, ...] = (
    0, -1, 0.0, 1e-300, -1e-300, 1e300, -1e300, math.nan, math.inf, -math.inf, 2**63,
    "nan", "NaN", "inf", "-inf", "1e999", "", "0", True, [], {}, [1e300, -1e300], "x" * 300,
)  # fmt: skip
BAD_NAMES: tuple[str, ...] = ("", " ", "obstacle 0", "a/b", "../up", "x" * 300, "名前", "\t")
#: Optional keys a user may add, with a sane value (the extremes are tried too).
OPTIONAL: dict[Path_, Any] = {
    ("fleet", "cruise_speed"): 0.5,
    ("fleet", "horizon_s"): 600.0,
    ("maps", "block"): [2, 2],
    ("maps", "omega"): 10.0,
    ("maps", "s"): 1.0,
    ("maps", "w"): 10.0,
    ("terrain", "seed"): 7,
    ("terrain", "window"): {"north": [0.0, 300.0]},
    ("weights", "terrain"): 1.0,
    ("weights", "energy"): 1.0,
    ("planner", "edge_model"): "crossed",
    ("deconfliction", "time_step_s"): 0.5,
    ("deconfliction", "coarsening"): 1,
    ("deconfliction", "method"): "auto",
    ("solver", "dt_s"): 0.5,
    ("solver", "max_iter"): 100,
    ("solver", "propeller_order"): 5,
    ("obstacle",): [{"center": {"north": 200.0, "east": 410.0}, "radius_m": 20.0}],
    ("comm",): [{"pair": ["blue", "green"], "max_range_m": 400.0}],
    ("mission", "start_time"): "2026-05-01T08:00:00Z",
    ("mission", "depth_m"): 3.0,
    ("mission", "altitude_m"): 5.0,
    ("mission", "reserve_fraction"): 0.2,
    ("navigation", "max_error_m"): 20.0,
    ("metadata", "creator_name"): "A. Operator",
    ("metadata", "creator_email"): "operator@example.org",
    ("area", "polygon"): [[-50.0, 250.0], [-50.0, 700.0], [700.0, 700.0], [700.0, 250.0]],
}
#: Factors a number is scaled by (a slip of units or of the decimal point, or worse).
SCALES = (1e-6, 1e-3, 0.1, 10.0, 1e3, 1e6)
UNIT_SWAPS = {"_s": "_ms", "_deg": "_rad", "_m": "_km"}


# --- mutations -------------------------------------------------------------------------------


def _paths(node: Any, prefix: Path_ = ()) -> list[Path_]:
    """Every key or index path in a document (containers and leaves)."""
    items: Sequence[tuple[str | int, Any]]
    if isinstance(node, dict):
        items = list(node.items())
    elif isinstance(node, list):
        items = list(enumerate(node))
    else:
        return []
    found = []
    for key, child in items:
        found.append((*prefix, key))
        found.extend(_paths(child, (*prefix, key)))
    return found


def _parent(document: dict[str, Any], path: Path_) -> Any:
    node: Any = document
    for key in path[:-1]:
        node = node[key]
    return node


def _set(document: dict[str, Any], path: Path_, value: Any) -> None:
    node: Any = document
    for key in path[:-1]:
        if isinstance(node, dict):
            node = node.setdefault(key, {})
            if not isinstance(node, dict | list):
                return  # a scalar where a table was: nothing to add to
        else:
            return
    if isinstance(node, dict) or (isinstance(node, list) and isinstance(path[-1], int)):
        node[path[-1]] = value


def mutate(document: dict[str, Any], choose: Choose) -> tuple[dict[str, Any], list[str]]:
    """Apply 1-3 random mutations to a deep copy; return it and a description of each."""
    document = copy.deepcopy(document)
    done = []
    for _ in range(choose([1, 1, 2, 3])):
        paths = _paths(document)
        operation = choose(["delete", "set", "set", "rename", "name", "add"])
        if operation in ("delete", "set", "rename") and not paths:
            continue
        if operation == "delete":
            path = choose(paths)
            del _parent(document, path)[path[-1]]
        elif operation == "set":
            path = choose(paths)
            current = _parent(document, path)[path[-1]]
            value = copy.deepcopy(choose([*EXTREMES, *_type_swaps(current)]))
            _parent(document, path)[path[-1]] = value
            operation = f"set={value!r}"
        elif operation == "rename":
            path = choose([p for p in paths if isinstance(p[-1], str)] or [None])
            if path is None:
                continue
            key = str(path[-1])
            new = next((key[: -len(a)] + b for a, b in UNIT_SWAPS.items() if key.endswith(a)), "")
            new = new or key + "_x"
            parent = _parent(document, path)
            parent[new] = parent.pop(key)
            operation = f"rename->{new}"
        elif operation == "name":
            listed = document.get("vehicle")
            vehicles = (
                [v for v in listed if isinstance(v, dict)] if isinstance(listed, list) else []
            )
            if not vehicles:
                continue
            others = [v.get("name") for v in vehicles if isinstance(v.get("name"), str)]
            value = choose([*BAD_NAMES, *others])
            index = choose(range(len(vehicles)))
            vehicles[index]["name"] = value
            path = ("vehicle", index, "name")
            operation = f"name={value!r}"
        else:
            path = choose(list(OPTIONAL))
            value = copy.deepcopy(choose([OPTIONAL[path], *EXTREMES]))
            _set(document, path, value)
            operation = f"add={value!r}"
        done.append(f"{'.'.join(map(str, path))}: {operation}")
    return document, done


def _type_swaps(value: Any) -> list[Any]:
    if isinstance(value, bool):
        return ["true", 1]
    if isinstance(value, int | float):
        return [str(value), [value], {"value": value}, -value, *(value * f for f in SCALES)]
    if isinstance(value, str):
        return [1, [value], value.upper()]
    if isinstance(value, list):
        return [value[:1], value * 2, value[0] if value else 0]
    return ["table", 1]


# --- TOML writing ----------------------------------------------------------------------------


def to_toml(document: dict[str, Any]) -> str:
    """Serialise a document: top-level tables as ``[name]``, lists of tables as ``[[name]]``."""
    lines = [f"{_key(k)} = {_value(v)}" for k, v in document.items() if not _is_section(v)]
    for key, value in document.items():
        if isinstance(value, dict):
            lines += [f"[{_key(key)}]", *(f"{_key(k)} = {_value(v)}" for k, v in value.items())]
        elif _is_section(value):
            for table in value:
                lines += [
                    f"[[{_key(key)}]]",
                    *(f"{_key(k)} = {_value(v)}" for k, v in table.items()),
                ]
    return "\n".join(lines) + "\n"


def _is_section(value: Any) -> bool:
    return isinstance(value, dict) or (
        isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)
    )


def _key(key: str) -> str:
    return (
        key
        if key.replace("_", "").replace("-", "").isalnum() and key.isascii()
        else json.dumps(key)
    )


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return (
            "nan"
            if math.isnan(value)
            else ("inf" if value > 0 else "-inf")
            if math.isinf(value)
            else repr(value)
        )
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, list):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    return "{ " + ", ".join(f"{_key(k)} = {_value(v)}" for k, v in value.items()) + " }"


def duplicate_a_line(text: str, choose: Choose) -> str:
    """Repeat one ``key = value`` line (a duplicate key, invalid TOML)."""
    lines = text.splitlines()
    candidates = [i for i, line in enumerate(lines) if " = " in line]
    index = choose(candidates)
    return "\n".join([*lines[: index + 1], lines[index], *lines[index + 1 :]]) + "\n"


# --- running ---------------------------------------------------------------------------------


class _Hang(BaseException):
    """The example ran longer than TIMEOUT_S."""


def check_mission(text: str, stage: str = "preplan") -> tuple[int | None, str | None]:
    """Run the mission through the command line: its exit code, and what went wrong or None."""
    with tempfile.TemporaryDirectory() as folder:
        root = Path(folder)
        mission = root / "mission.toml"
        mission.write_text(text, encoding="utf-8")
        out = root / "out"
        argv = ["plan", str(mission), "-o", str(out), "--stage", stage, "--no-figures"]

        def hang(_signum: int, _frame: FrameType | None) -> None:
            raise _Hang

        previous = signal.signal(signal.SIGALRM, hang)
        signal.setitimer(signal.ITIMER_REAL, TIMEOUT_S)
        try:
            code, err = _run_captured(argv)
        except _Hang:
            return None, f"hang (> {TIMEOUT_S:g} s)"
        except Exception as error:  # noqa: BLE001  (a traceback is what we look for)
            return None, f"traceback: {type(error).__name__}: {str(error)[:200]}"
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
            signal.signal(signal.SIGALRM, previous)
        if code not in (0, 2, 3):
            return code, f"exit {code}: {err.strip()[:200]}"
        if "Traceback" in err or len(err.splitlines()) > 1:
            return code, f"stderr of {len(err.splitlines())} lines: {err[:300]}"
        expected = {"mission.toml", "out"} if code in (0, 3) else {"mission.toml"}
        left = {path.name for path in root.iterdir()}
        if left != expected:
            return code, f"left {sorted(left - expected)}, missing {sorted(expected - left)}"
    return code, None


def _run_captured(argv: list[str]) -> tuple[int, str]:
    """Exit code and stderr of ``main(argv)`` (stdout discarded)."""
    import contextlib
    import io

    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main(argv)
        except SystemExit as exit_:
            code = int(exit_.code or 0) if not isinstance(exit_.code, str) else 2
    return code, err.getvalue()


# --- the test and the campaign ---------------------------------------------------------------


def _mutant(choose: Choose) -> tuple[str, list[str]]:
    """A mutant's TOML text and its mutations."""
    name = choose(sorted(SEEDS))
    document, done = mutate(SEEDS[name], choose)
    text = to_toml(document)
    if " = " in text and choose([False] * 9 + [True]):  # a mutant may have no key left
        text = duplicate_a_line(text, choose)
        done.append("duplicated a line")
    return text, [f"seed {name}", *done]


@settings(
    max_examples=600,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
    database=None,
)
@given(st.data())
def test_mutated_missions_never_crash_or_leave_files(data: st.DataObject) -> None:
    text, done = _mutant(lambda options: data.draw(st.sampled_from(list(options))))
    note("\n".join(done) + "\n" + text)
    code, problem = check_mission(text)
    assert problem is None, problem
    event(f"exit {code}")


def _campaign(n_examples: int, seed: int, stage: str) -> None:
    import logging

    logging.getLogger().addHandler(logging.NullHandler())  # as under pytest: logs not on stderr
    rng = random.Random(seed)
    failures = 0
    codes: dict[int | None, int] = {}
    for index in range(n_examples):
        text, done = _mutant(lambda options: rng.choice(list(options)))
        code, problem = check_mission(text, stage)
        codes[code] = codes.get(code, 0) + 1
        if problem is not None:
            failures += 1
            sys.stdout.write(f"--- #{index}: {problem}\n    " + "; ".join(done) + "\n")
            sys.stdout.flush()
    sys.stdout.write(f"{failures} failures in {n_examples} mutants; exit codes {codes}\n")


if __name__ == "__main__":
    _campaign(int(sys.argv[1]), int(sys.argv[2]), sys.argv[3] if len(sys.argv) > 3 else "preplan")
