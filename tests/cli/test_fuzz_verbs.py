"""Fuzzing every verb but ``plan``: damaged output folders and bad command-line arguments.

(a) An output folder planned once per module (two vehicles on a georeferenced grid,
``tests/export/_plans.py``) is copied and damaged: ``summary.json`` truncated, overwritten
with garbage, given values of the wrong JSON type, keys deleted, numbers set to NaN or 1e300;
``trajectories.csv`` truncated, columns dropped, cells NaN/inf/1e300, header only, rows
shuffled or repeated, times duplicated; ``trajectories.nc`` and ``maps.nc`` truncated,
garbage or deleted (sometimes without the ``digest`` of ``summary.json``, as an older folder,
so that the damage reaches the readers behind it). Then ``export`` or ``evaluate`` (2 runs of
50 particles) runs on the copy.

(b) The arguments of ``export``, ``evaluate``, ``sweep``, ``scenarios``, ``vehicle`` and
``maps`` get numbers out of range, NaN, inf, huge and negative, empty and unicode strings,
missing files and folders where files are expected.

Every case runs in-process (``auvplan -q VERB ...``, in a fresh copy of the inputs, as the
current folder) and must end in at most :data:`TIMEOUT_S` with exit code 0, 2 or 3; a refusal
(2) is exactly one stderr line ``auvplan...`` and leaves every file as it was; a run (0 or 3)
prints nothing on stderr and changes nothing but its outputs; never a traceback, and never a
hidden file, ``.partial`` or ``.old`` left behind.
"""

from __future__ import annotations

import collections
import contextlib
import io
import json
import math
import os
import random
import re
import shutil
import signal
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, note, settings
from hypothesis import strategies as st

from auvplan.cli.main import main
from export._plans import MISSION, write_geographic_grid

SHARED_BATHYMETRY = (
    Path(
        os.environ.get("AUVPLAN_SHARED_DATA", Path(__file__).parents[2] / ".." / "shared" / "data")
    )
    / "bathymetry"
)
#: A case taking longer than this [s] is a hang.
TIMEOUT_S = 60.0
#: Written by ``@`` at the start of an argument: the case's folder (also the current folder).
ROOT = "@"
PLAN = "@/plan"


# --- the cases -------------------------------------------------------------------------------


@dataclass(frozen=True)
class Damage:
    """One change to a file of the plan folder: ``how`` at relative places ``at`` in [0, 1)."""

    file: str
    how: str
    at: tuple[float, ...] = ()
    value: Any = None

    def __str__(self) -> str:
        places = ", ".join(f"{a:.3g}" for a in self.at)
        return (
            f"{self.file}: {self.how}({places}){'' if self.value is None else f' = {self.value!r}'}"
        )


@dataclass(frozen=True)
class Case:
    """``auvplan -q *argv`` (``@`` = the case's folder) after ``damage`` to its plan folder."""

    argv: tuple[str, ...]
    damage: tuple[Damage, ...] = ()
    undigested: bool = False  # summary.json without its digest (an older folder)
    outputs: tuple[str, ...] = field(default=(), compare=False)

    def __str__(self) -> str:
        lines = [" ".join(repr(a) if not a or " " in a else a for a in self.argv)]
        lines += [f"  {d}" for d in self.damage]
        return "\n".join(lines + (["  digest removed"] if self.undigested else []))


#: Values of the wrong JSON type or out of any range.
JSON_VALUES: tuple[Any, ...] = (
    None, True, 0, -1, 2**63, 1e300, -1e300, math.nan, math.inf, -math.inf, "", "x", "名前",
    [], [1e300], {}, {"a": 1},
)  # fmt: skip
NUMBERS_IN_JSON: tuple[float, ...] = (math.nan, math.inf, -math.inf, 1e300, -1e300, 0.0, -1.0)
CELLS: tuple[str, ...] = ("nan", "inf", "-inf", "1e300", "-1e300", "", "x", "0", "-0", "1e-300")
GARBAGE = st.binary(min_size=1, max_size=64)
PLACE = st.floats(min_value=0.0, max_value=1.0, exclude_max=True)
FILE_DAMAGE = ("truncate", "garbage", "delete")


@st.composite
def damages(draw: st.DrawFn) -> Damage:
    """One damage to a file of the plan folder."""
    file = draw(
        st.sampled_from(
            ["summary.json"] * 3 + ["trajectories.csv"] * 3
            + ["trajectories.nc", "maps.nc", "mission.toml", "desired.csv"]
        )
    )  # fmt: skip
    if file == "summary.json":
        how = draw(st.sampled_from([*FILE_DAMAGE, "delete-key", "set", "set-number"]))
    elif file == "trajectories.csv":
        how = draw(
            st.sampled_from(
                [*FILE_DAMAGE, "drop-column", "cell", "cell", "header-only", "shuffle",
                 "duplicate-time", "repeat-row"]
            )
        )  # fmt: skip
    else:
        how = draw(st.sampled_from(FILE_DAMAGE))
    at = tuple(draw(PLACE) for _ in range(2))
    value: Any = None
    if how == "garbage":
        value = draw(GARBAGE)
    elif how == "set":
        value = draw(st.sampled_from(JSON_VALUES))
    elif how == "set-number":
        value = draw(st.sampled_from(NUMBERS_IN_JSON))
    elif how == "cell":
        value = draw(st.sampled_from(CELLS))
    return Damage(file, how, at, value)


@st.composite
def damaged_folder_cases(draw: st.DrawFn) -> Case:
    """``export`` or ``evaluate`` on a damaged copy of the plan folder."""
    if draw(st.booleans()):
        formats = draw(st.sampled_from(["gpx", "kml", "moos,qgc,imc,gpx,kml,geojson"]))
        argv: tuple[str, ...] = ("export", PLAN, "--format", formats, "-o", "@/exported")
    else:
        argv = ("evaluate", PLAN, "--runs", "2", "--particles", "50", "--no-figure")
    damage = tuple(draw(st.lists(damages(), min_size=1, max_size=3)))
    return _with_outputs(Case(argv, damage, undigested=draw(st.booleans())))


#: Numbers a careless user or a script may pass.
BAD_NUMBERS: tuple[str, ...] = (
    "-1", "0", "-0", "nan", "NaN", "inf", "-inf", "1e300", "-1e300", "1e-300", "1e999",
    "9223372036854775808", "1" + "0" * 400, "1" + "0" * 5000, "0x10", "1_0", "1e", "", " ",
    "½", "２", "名前",
)  # fmt: skip
STRINGS: tuple[str, ...] = ("", " ", "名前", "😀", "a\nb", "-x", "x" * 300, "..", "/", "a\u2028b")
PATHS: tuple[str, ...] = (
    "@/missing", "@/missing/deeper/file.png", "@/a_folder", "@/a_folder/", "@/empty.toml",
    "@/garbage.bin", "@/plan/summary.json", "@/名前 😀", "/dev/null", "",
)  # fmt: skip


def _number_option(*valid: str) -> tuple[tuple[str, ...], ...]:
    return tuple((value,) for value in (*valid, *BAD_NUMBERS))


def _choice_option(*valid: str) -> tuple[tuple[str, ...], ...]:
    return tuple((value,) for value in (*valid, *STRINGS, "PNG", "UTM"))


def _path_option(*valid: str) -> tuple[tuple[str, ...], ...]:
    return tuple((value,) for value in (*valid, *PATHS, *STRINGS[2:5]))


def _pair_option(*valid: tuple[str, str]) -> tuple[tuple[str, ...], ...]:
    bad = [(a, b) for a, b in zip(BAD_NUMBERS, reversed(BAD_NUMBERS), strict=True)]
    return (*valid, *bad, ("0", "0"), ("10", "-10"), ("1e300", "1e301"), ("0", "nan"))


NAVIGATION: dict[str, tuple[tuple[str, ...], ...]] = {
    "--runs": _number_option("1", "3"),
    "--particles": _number_option("10", "200"),
    "--sensor": _choice_option("altimeter", "multibeam"),
    "--update-period": _number_option("1", "10", "0.5"),
    "--initial-sigma": _number_option("1", "20"),
    "--drift": _number_option("0.5", "5"),
    "--convergence-updates": _number_option("1", "50"),
}
FIGURES: dict[str, tuple[tuple[str, ...], ...]] = {
    "--figure-format": _choice_option("png", "svg", "pdf"),
    "--dpi": _number_option("20", "72"),
}


@dataclass(frozen=True)
class Verb:
    """A verb's cheapest valid command line (``positional`` is drawn) and its options."""

    head: tuple[str, ...]
    positionals: tuple[tuple[str, ...], ...]
    tail: tuple[str, ...]
    options: dict[str, tuple[tuple[str, ...], ...]]


#: The cheapest sweep: one preplan run of the folder's mission on an in-process cluster.
SWEEP_TAIL = ("-o", "@/swept", "--stage", "preplan", "--workers", "1", "--vary",
              "weights.terrain=1", "--seeds", "0", "--runs", "2", "--particles", "50")  # fmt: skip
VERBS: dict[str, Verb] = {
    "export": Verb(
        ("export",),
        ((PLAN,), *((p,) for p in PATHS)),
        ("--format", "gpx"),
        {
            "-o": _path_option("@/exported", PLAN),
            "--format": _choice_option("moos,qgc,imc,gpx,kml,geojson", "kml", ",", "gpx,gpx"),
            "--tolerance-m": _number_option("0.5", "5", "2e7", "2.1e7"),
            "--moos-frame": _choice_option("utm", "local"),
        },
    ),
    "evaluate": Verb(
        ("evaluate",),
        ((PLAN,), *((p,) for p in PATHS), ("@/grid.nc",)),
        ("--runs", "2", "--particles", "50", "--no-figure"),
        {"--seed": _number_option("0", "7"), **NAVIGATION, **FIGURES, "(draw figures)": ()},
    ),
    "sweep": Verb(
        ("sweep",),
        (("@/mission.toml",), ("scenarios",), *((p,) for p in PATHS)),
        SWEEP_TAIL,
        {
            "--vary": tuple(
                (v,)
                for v in (
                    "weights.terrain=0,1",
                    "weights.terrain=",
                    "nokey=1",
                    "=",
                    "x",
                    "weights.terrain=nan",
                    "weights.terrain=[[[1]]]",
                    "fleet.horizon_s=1e300",
                    "fleet.horizon_s=-1",
                    "vehicle[5].start.speed=1",
                    "名前=1",
                    "solver.dt_s=0.001",
                    "fleet.horizon_s=inf",
                )
            ),
            "--seeds": tuple(
                (v,)
                for v in (
                    "0",
                    "0..1",
                    "-1",
                    "1..0",
                    "a",
                    "",
                    "0,0",
                    "99999999999999999999",
                    "0..1e3",
                    "0.5",
                    "..",
                    "0..",
                )
            ),
            "--workers": _number_option("1", "2"),
            "--stage": _choice_option("preplan", "deconflict", "full"),
            "--evaluate": (),
            "--scheduler": tuple(
                (v,) for v in ("", "tcp://127.0.0.1:1", "nonsense", "名前", "tcp://:99999")
            ),
            "--data-dir": _path_option(str(SHARED_BATHYMETRY)),
            **NAVIGATION,
        },
    ),
    "scenarios": Verb(
        ("scenarios",),
        (("0",), ("1", "2"), *((v,) for v in BAD_NUMBERS), ("0", "0"), ("1e3",)),
        ("-o", "@/scenarios"),
        {
            "-o": _path_option("@/scenarios", PLAN),
            "--data-dir": _path_option(str(SHARED_BATHYMETRY)),
            "--kind": _choice_option("reliability", "transit"),
        },
    ),
    "vehicle": Verb(
        ("vehicle",),
        ((), ("medusa",), ("remus100",), *((p,) for p in PATHS), ("名前",), ("mission.toml",)),
        (),
        {
            "--json": (),
            "--figure": _path_option("@/figure.png", "@/figure.svg", "@/figure.xyz", "@/.png"),
            "--order": _number_option("1", "3"),
        },
    ),
    "maps": Verb(
        ("maps",),
        (
            ("synthetic",),
            ("@/grid.nc",),
            ("@/plan/maps.nc",),
            ("@/plan/trajectories.nc",),
            ("@/plan/trajectories.csv",),
            *((p,) for p in PATHS),
        ),
        ("-o", "@/maps"),
        {
            "-o": _path_option("@/maps", PLAN),
            "--seed": _number_option("0", "3"),
            "--window-north": _pair_option(("0", "300")),
            "--window-east": _pair_option(("0", "300")),
            "--window-lat": _pair_option(("36.79", "36.793")),
            "--window-lon": _pair_option(("-121.815", "-121.812")),
            "--s": _number_option("0.5", "2"),
            "--block": _pair_option(("1", "1"), ("4", "4")),
            "--omega": _number_option("1", "100"),
            "--w": _number_option("0", "20"),
            **FIGURES,
        },
    ),
}


@st.composite
def argument_cases(draw: st.DrawFn, verbs: tuple[str, ...] = tuple(VERBS)) -> Case:
    """A verb with a drawn positional argument and one to three drawn options."""
    name = draw(st.sampled_from(verbs))
    verb = VERBS[name]
    argv = [*verb.head, *draw(st.sampled_from(verb.positionals)), *verb.tail]
    for flag in draw(st.lists(st.sampled_from(sorted(verb.options)), max_size=3, unique=True)):
        values = verb.options[flag]
        if flag == "(draw figures)":  # evaluate without --no-figure
            argv.remove("--no-figure")
            continue
        argv += [flag, *(draw(st.sampled_from(values)) if values else ())]
    return _with_outputs(Case(tuple(argv)))


def _with_outputs(case: Case) -> Case:
    """``case`` with the paths its verb may write (relative to the case's folder or absolute)."""
    argv = case.argv
    verb, first = argv[0], (argv[1] if len(argv) > 1 and not argv[1].startswith("-") else "")

    def last(flag: str, default: str) -> str:
        given = [argv[i + 1] for i, a in enumerate(argv[:-1]) if a == flag]
        return given[-1] if given else default

    if verb == "evaluate":
        outputs: tuple[str, ...] = tuple(
            f"{first}/navigation.{e}" for e in ("json", "png", "svg", "pdf")
        )
    elif verb == "export":
        outputs = (last("-o", f"{first}/export"),)
    elif verb == "vehicle":
        outputs = (last("--figure", ""),)
    else:
        outputs = (last("-o", ""),)
    return Case(argv, case.damage, case.undigested, tuple(o for o in outputs if o))


# --- the plan folder and its damage ----------------------------------------------------------


@pytest.fixture(scope="module")
def template(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """A folder copied for every case: ``plan/`` (a full plan), its ``mission.toml`` and
    ``grid.nc``, an empty file, a garbage file and an empty folder; the sweep's local cluster
    runs its workers as threads (as ``tests/sweep``'s ``inprocess_cluster``)."""
    root = tmp_path_factory.mktemp("fuzz_verbs")
    write_geographic_grid(root / "grid.nc")
    (root / "mission.toml").write_text(MISSION, encoding="utf-8")
    argv = ["-q", "plan", str(root / "mission.toml"), "-o", str(root / "plan"), "--no-figures"]
    assert main(argv) == 0
    (root / "empty.toml").write_bytes(b"")
    (root / "garbage.bin").write_bytes(np.random.default_rng(3).bytes(4096))
    (root / "a_folder").mkdir()
    with pytest.MonkeyPatch.context() as patch:
        with contextlib.suppress(ImportError):
            import distributed

            original: Callable[..., Any] = distributed.LocalCluster

            def threads(*args: Any, **kwargs: Any) -> Any:
                return original(*args, **{**kwargs, "processes": False})

            patch.setattr(distributed, "LocalCluster", threads)
        yield root


def _json_paths(node: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Every key or index path of a JSON document."""
    items = (
        node.items()
        if isinstance(node, dict)
        else enumerate(node)
        if isinstance(node, list)
        else ()
    )
    found = []
    for key, child in items:
        found.append((*prefix, key))
        found.extend(_json_paths(child, (*prefix, key)))
    return found


def _pick(options: list[Any], at: float) -> Any:
    return options[min(int(at * len(options)), len(options) - 1)]


def _node(document: Any, path: tuple[Any, ...]) -> Any:
    for key in path[:-1]:
        document = document[key]
    return document


def _damage_summary(document: Any, damage: Damage) -> None:
    paths = _json_paths(document)
    if damage.how == "delete-key":
        paths = [p for p in paths if isinstance(_node(document, p), dict)]
    elif damage.how == "set-number":
        paths = [
            p for p in paths
            if isinstance(_node(document, p)[p[-1]], int | float)
            and not isinstance(_node(document, p)[p[-1]], bool)
        ]  # fmt: skip
    if not paths:
        return
    path = _pick(paths, damage.at[0])
    if damage.how == "delete-key":
        del _node(document, path)[path[-1]]
    else:
        _node(document, path)[path[-1]] = damage.value


def _damage_table(lines: list[str], damage: Damage) -> list[str]:
    if not lines:  # truncated to nothing before
        return lines
    header, rows = lines[0].split(","), [line.split(",") for line in lines[1:]]
    if damage.how == "header-only":
        return lines[:1]
    if damage.how == "drop-column":
        column = _pick(list(range(len(header))), damage.at[0])
        return [",".join(c for i, c in enumerate(r) if i != column) for r in [header, *rows]]
    if not rows:
        return lines
    row = _pick(list(range(len(rows))), damage.at[0])
    if damage.how == "cell":
        rows[row][_pick(list(range(len(rows[row]))), damage.at[1])] = damage.value
    elif damage.how == "shuffle":
        random.Random(int(damage.at[0] * 1e6)).shuffle(rows)
    elif damage.how == "duplicate-time" and row > 0 and len(header) > 1:
        rows[row][1] = rows[row - 1][1]
    elif damage.how == "repeat-row":
        rows.insert(row, list(rows[row]))
    return [",".join(r) for r in [header, *rows]]


def apply(folder: Path, case: Case) -> None:
    """Damage the plan folder as ``case`` says."""
    summary = folder / "summary.json"
    if case.undigested:
        document = json.loads(summary.read_text(encoding="utf-8"))
        document.pop("digest", None)
        summary.write_text(json.dumps(document), encoding="utf-8")
    for damage in case.damage:
        path = folder / damage.file
        if not path.is_file():
            continue
        data = path.read_bytes()
        if damage.how == "delete":
            path.unlink()
        elif damage.how == "truncate":
            path.write_bytes(data[: int(damage.at[0] * len(data))])
        elif damage.how == "garbage":
            start = int(damage.at[0] * len(data))
            path.write_bytes(data[:start] + damage.value + data[start + len(damage.value) :])
        elif damage.file == "summary.json":
            try:
                document = json.loads(data)
            except ValueError:
                continue  # an earlier damage made it unreadable
            _damage_summary(document, damage)
            path.write_text(json.dumps(document), encoding="utf-8")
        else:
            text = data.decode("utf-8", errors="replace")
            path.write_text("\n".join(_damage_table(text.splitlines(), damage)) + "\n")


# --- running a case --------------------------------------------------------------------------


class _Hang(BaseException):
    """The case ran longer than TIMEOUT_S."""


def _tree(root: Path) -> dict[Path, bytes | None]:
    """Every entry below ``root``: path -> file content (None for folders and others)."""
    return {
        path: path.read_bytes() if path.is_file() and not path.is_symlink() else None
        for path in sorted(root.rglob("*"))
    }


def _run_captured(argv: list[str]) -> tuple[int, str]:
    """Exit code and stderr of ``main(argv)`` (stdout discarded)."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main(argv)
        except SystemExit as exit_:
            code = exit_.code if isinstance(exit_.code, int) else 2
    return code, err.getvalue()


def check_case(case: Case, template: Path) -> tuple[int | None, str | None]:
    """Run ``case`` in a copy of ``template``: its exit code and what went wrong (or None).

    What went wrong starts with its kind: ``traceback``, ``hang``, ``leftover``, ``stderr``
    or ``exit``.
    """
    with tempfile.TemporaryDirectory() as folder:
        root = Path(folder)
        shutil.copytree(template, root, dirs_exist_ok=True)
        apply(root / "plan", case)
        argv = ["-q", *(str(root) + a[1:] if a.startswith(ROOT + "/") else a for a in case.argv)]
        outputs = [root / o[2:] if o.startswith(ROOT + "/") else root / o for o in case.outputs]
        before = _tree(root)

        def hang(_signum: int, _frame: FrameType | None) -> None:
            raise _Hang

        previous = signal.signal(signal.SIGALRM, hang)
        cwd = Path.cwd()
        os.chdir(root)
        signal.setitimer(signal.ITIMER_REAL, TIMEOUT_S)
        try:
            code, err = _run_captured(argv)
        except _Hang:
            return None, f"hang (> {TIMEOUT_S:g} s)"
        except Exception as error:  # noqa: BLE001  (a traceback is what we look for)
            return None, f"traceback: {type(error).__name__}: {str(error)[:300]}"
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
            signal.signal(signal.SIGALRM, previous)
            os.chdir(cwd)
        return code, _problem(code, err, before, _tree(root), outputs)


def _problem(
    code: int,
    err: str,
    before: dict[Path, bytes | None],
    after: dict[Path, bytes | None],
    outputs: list[Path],
) -> str | None:
    """What breaks the contract in a finished case, or None."""
    if "Traceback" in err:
        return f"traceback on stderr: {err[-300:]}"
    if code not in (0, 2, 3):
        return f"exit {code}: {err.strip()[:300]}"
    lines = err.splitlines()
    if code == 2 and (len(lines) != 1 or not lines[0].startswith("auvplan")):
        return f"stderr of {len(lines)} lines on exit 2: {err[:300]!r}"
    if code == 3 and (len(lines) > 1 or not err.startswith("auvplan")):
        return f"stderr of {len(lines)} lines on exit 3: {err[:300]!r}"
    if code == 0 and err:
        return f"stderr on exit 0 with -q: {err[:300]!r}"
    new = [p for p in after if p not in before]
    hidden = [
        p for p in new
        if (p.name.startswith(".") or p.suffix in (".partial", ".old")) and p not in outputs
    ]  # fmt: skip
    if hidden:
        return f"leftover: {sorted(map(str, hidden))[:3]}"
    changed = [p for p in {*before, *after} if before.get(p, b"") != after.get(p, b"")]
    if code == 2:
        allowed: list[Path] = []
    else:
        allowed = [  # the outputs, what is in them, and the folders made to hold them
            p for p in changed
            if any(p == o or o in p.parents or (p in o.parents and p not in before)
                   for o in outputs)
        ]  # fmt: skip
    others = sorted(str(p) for p in changed if p not in allowed)
    if others:
        return f"leftover: exit {code} changed {others[:3]}"
    return None


# --- the tests -------------------------------------------------------------------------------


CI = settings(
    max_examples=20,
    derandomize=True,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)


@CI
@given(case=damaged_folder_cases())
def test_damaged_folders_are_refused_in_one_line(template: Path, case: Case) -> None:
    note(str(case))
    code, problem = check_case(case, template)
    assert problem is None, problem
    event(f"{case.argv[0]}: exit {code}")


@settings(CI, max_examples=40)
@given(case=argument_cases())
def test_bad_arguments_are_refused_in_one_line(template: Path, case: Case) -> None:
    note(str(case))
    code, problem = check_case(case, template)
    assert problem is None, problem
    event(f"{case.argv[0]}: exit {code}")


@dataclass
class Tally:
    """Counts of a campaign: cases, exit codes and problems by kind, first examples of each."""

    cases: int = 0
    codes: collections.Counter[str] = field(default_factory=collections.Counter)
    problems: collections.Counter[str] = field(default_factory=collections.Counter)
    examples: dict[str, list[str]] = field(default_factory=dict)

    def add(self, case: Case, code: int | None, problem: str | None) -> None:
        self.cases += 1
        self.codes[f"{case.argv[0]} {code}"] += 1
        if problem is not None:
            print(f"--- {problem}\n{case}", flush=True)  # noqa: T201  (as found, with -s)
            kind = problem.split(":")[0].split(" ")[0]
            self.problems[kind] += 1
            self.examples.setdefault(problem[:120], []).append(f"{problem}\n{case}")

    def report(self) -> str:
        lines = [f"{self.cases} cases; problems {dict(self.problems)}"]
        lines += [f"exit codes {dict(sorted(self.codes.items()))}"]
        for found in self.examples.values():
            lines.append(f"--- {len(found)} x {found[0]}")
        return "\n".join(lines)


@pytest.mark.slow
def test_campaign_over_every_verb(template: Path) -> None:
    """1,200 cases (a third damaged folders): every problem counted, then reported."""
    tally = Tally()

    @settings(
        max_examples=1200,
        deadline=None,
        database=None,
        suppress_health_check=list(HealthCheck),
    )
    @given(case=st.one_of(damaged_folder_cases(), argument_cases(), argument_cases()))
    def campaign(case: Case) -> None:
        tally.add(case, *check_case(case, template))

    campaign()
    print(tally.report())  # noqa: T201  (the campaign's counts, with -s)
    assert not tally.problems, tally.report()


# --- cases the campaign found ----------------------------------------------------------------


def _refused(case: Case, template: Path) -> str:
    """Run ``case`` (checked as the campaign does); its one stderr line, asserted exit 2."""
    assert check_case(case, template) == (2, None)
    with tempfile.TemporaryDirectory() as folder:  # again, to read the line
        root = Path(folder)
        shutil.copytree(template, root, dirs_exist_ok=True)
        apply(root / "plan", case)
        argv = [str(root) + a[1:] if a.startswith(ROOT + "/") else a for a in case.argv]
        code, err = _run_captured(["-q", *argv])
    assert code == 2
    return err.strip().replace(str(root), "@")


def test_garbage_in_a_compressed_chunk_of_maps_nc_is_one_line(template: Path) -> None:
    """The NetCDF library opened the file but raised RuntimeError('NetCDF: HDF error') when
    reading a damaged chunk (exit 1 and a traceback from export and evaluate)."""
    from auvplan.errors import DataFormatError
    from auvplan.io.maps_file import read_maps_netcdf

    data = (template / "plan" / "maps.nc").read_bytes()
    chunks = [m.start() for m in re.finditer(rb"\x78\x5e", data)]  # zlib level 4 headers
    unreadable = 0
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "maps.nc"
        for start in chunks:
            path.write_bytes(data[: start + 2] + b"\xff" * 8 + data[start + 10 :])
            with contextlib.suppress(DataFormatError):
                read_maps_netcdf(path)
                continue
            unreadable += 1
    assert unreadable >= 5  # the five maps at least


@pytest.mark.parametrize(
    "damage",
    [
        Damage("maps.nc", "garbage", (0.424, 0.0), b"\x94`\xb6\xad"),  # a data chunk
        Damage("maps.nc", "garbage", (0.994, 0.0), b"\xe6Z\xbd\x82"),  # an attribute
    ],
)
def test_maps_nc_damaged_as_the_campaign_found_it(damage: Damage, template: Path) -> None:
    case = _with_outputs(Case(("export", PLAN, "--format", "kml", "-o", "@/exported"), (damage,)))
    assert "@/plan/maps.nc: cannot " in _refused(case, template)


def test_a_1e300_position_is_a_step_too_long_not_an_overflow(
    template: Path,
) -> None:
    """north = 1e300 in one row (no digest): numpy's norm overflowed squaring the step."""
    damage = Damage("trajectories.csv", "cell", (0.13, 0.203), "1e300")
    argv = ("evaluate", PLAN, "--runs", "2", "--particles", "50", "--no-figure")
    line = _refused(_with_outputs(Case(argv, (damage,), undigested=True)), template)
    assert line == (
        "auvplan: error: @/plan/trajectories.csv line 23: vehicle 'blue': north/east step of "
        "1e+300 m in 1 s is longer than 1.5 x (top speed 1.47 + current 0 m/s) x dt"
    )


@pytest.mark.parametrize("verb", ["scenarios", "sweep"])
def test_a_seed_above_2_63_is_refused_before_any_folder_is_made(verb: str, template: Path) -> None:
    """scenarios 1e400 made the output folder, then failed naming seed_1000…'s folder
    ("File name too long"); sweep --seeds of 5000 digits was a ValueError traceback."""
    big = "1" + "0" * 400
    if verb == "scenarios":
        argv: tuple[str, ...] = ("scenarios", big, "-o", "@/scenarios")
        expected = f"scenario seed must be in 0 … 9223372036854775807 (2**63 - 1), got {big}"
    else:
        huge = "1" + "0" * 5000
        argv = ("sweep", "scenarios", "-o", "@/swept", "--seeds", huge)
        expected = f"--seeds '{huge}': '{huge}' is above the largest seed 9223372036854775807"
    assert _refused(_with_outputs(Case(argv)), template) == f"auvplan: error: {expected}"


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (("vehicle", "--figure", "a\nb"), "auvplan: error: --figure a\\nb: unsupported"),
        (("scenarios", "0", "-o", "@/s", "--data-dir", "a\u2028b"), "data folder a\\u2028b does"),
        (("vehicle", "medusa", "x\ry"), "unrecognized arguments: x\\ry (see auvplan --help)"),
    ],
)
def test_a_line_break_in_an_argument_stays_in_the_one_line(
    argv: tuple[str, ...], expected: str, template: Path
) -> None:
    """A path with a newline split the error message over two lines."""
    assert expected in _refused(_with_outputs(Case(argv)), template)
