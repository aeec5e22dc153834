"""What a sweep runs: ``--vary KEY=v1,v2,...`` axes × seeds, each run validated before any runs.

A key is addressed as in the mission file and in ``auvplan keys`` (``table.key``, e.g.
``weights.terrain``, ``solver.dt_s``); an array of tables takes an index
(``vehicle[1].start.speed``) or, without one, sets the key in every element
(``vehicle.start.speed``). Values are TOML values (``0.3``, ``true``, ``"paper"``, ``[4, 4]``);
a bare word that is not TOML is a string (``planner.edge_model=paper,crossed``). Each value is
coerced by the mission schema (:func:`auvplan.mission.config.parse_mission`), so ``1`` and
``1.0`` are the same value of a number key, and the run's folder name shows the coerced value.

The grid is the cartesian product of the axes (in the order given) and the seeds. Every run's
mission is validated by the schema before anything runs; an unknown key or an invalid value is
an :class:`~auvplan.errors.InputError` whose one line names the ``--vary`` key and value.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import re
import tomllib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final

from auvplan.errors import InputError
from auvplan.mission.config import parse_mission, resolved_document
from auvplan.scenarios.family import MAX_SEED

#: Most runs one sweep may hold.
MAX_RUNS: Final = 100_000
#: Deepest nesting of brackets and braces in a ``--vary`` value (an array of obstacle tables
#: with their polygons nests 4 deep); deeper values are refused before the TOML parser recurses.
MAX_VALUE_DEPTH: Final = 16
#: Longest run id kept readable; longer ids are cut and end with a digest.
MAX_ID_LENGTH: Final = 120
_SAFE = re.compile(r"[^A-Za-z0-9._-]")
_PART = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)(?:\[(\d+)\])?$")
_SEEDS = re.compile(r"^(\d+)(?:\.\.(\d+))?$")


@dataclass(frozen=True)
class VaryAxis:
    """One ``--vary`` option: a key path and its values, coerced by the mission schema."""

    key: str
    values: tuple[Any, ...]


@dataclass(frozen=True)
class MissionBase:
    """The mission a run starts from: a TOML document and where its relative paths point.

    ``label`` names it in messages (the file, or ``scenario 7``).
    """

    document: Mapping[str, Any]
    base_dir: Path
    source: Path | None
    label: str


@dataclass(frozen=True)
class SweepRun:
    """One run of the grid.

    ``values`` maps each varied key to its coerced value, ``seed`` is the run's seed (``None``
    without ``--seeds``), ``document`` the run's mission (the base with the values set) and
    ``digest`` a SHA-256 of everything that determines the run's outputs (the document, its
    folder and the stage): a finished run folder is reused only when its digest matches.
    """

    run_id: str
    values: Mapping[str, Any]
    seed: int | None
    document: Mapping[str, Any] = field(repr=False)
    base_dir: Path
    source: Path | None
    digest: str


def parse_vary(text: str) -> tuple[str, list[Any]]:
    """Split ``KEY=v1,v2,...`` into the key and its TOML-parsed values (not yet coerced).

    Commas inside brackets, braces or quotes do not split (``maps.block=[2, 2],[4, 4]``).

    Raises
    ------
    InputError
        If there is no ``=``, no key, an empty value, a malformed key path, or values nested
        deeper than :data:`MAX_VALUE_DEPTH`.

    Examples
    --------
    >>> parse_vary("weights.terrain=0,0.3,1")
    ('weights.terrain', [0, 0.3, 1])
    >>> parse_vary("maps.block=[2, 2],[4, 4]")
    ('maps.block', [[2, 2], [4, 4]])
    >>> parse_vary("planner.edge_model=paper,'crossed'")
    ('planner.edge_model', ['paper', 'crossed'])
    """
    key, equals, listing = text.partition("=")
    key = key.strip()
    if not equals or not key:
        raise InputError(
            f"--vary {text!r}: expected KEY=VALUE,VALUE,... (e.g. weights.terrain=0,1)"
        )
    _key_parts(key)
    tokens, depth = _split_top_level(listing)
    if depth > MAX_VALUE_DEPTH:
        raise InputError(
            f"--vary {key}: values nested {depth} deep, more than {MAX_VALUE_DEPTH} brackets "
            "or braces"
        )
    if any(not token.strip() for token in tokens):
        raise InputError(f"--vary {key}: empty value in {listing!r}")
    return key, [_toml_value(token.strip()) for token in tokens]


def parse_seeds(text: str) -> tuple[int, ...]:
    """Seeds from ``A..B`` (inclusive), ``A,B,C`` or a mix (``0..9,20``), in the order given.

    Raises
    ------
    InputError
        If a part is not an integer or range in 0 … 2**63 - 1
        (:data:`auvplan.scenarios.family.MAX_SEED`), a range runs backwards, a seed
        repeats, or there are more than :data:`MAX_RUNS` seeds (counted from the ranges, in
        time linear in the number of parts).

    Examples
    --------
    >>> parse_seeds("0..3,7")
    (0, 1, 2, 3, 7)
    """
    ranges: list[range] = []
    for part in text.split(","):
        match = _SEEDS.match(part.strip())
        if match is None:
            raise InputError(f"--seeds {text!r}: {part!r} is not a seed (N) or a range (A..B)")
        if any(len(n) > len(str(MAX_SEED)) or int(n) > MAX_SEED for n in match.groups() if n):
            raise InputError(f"--seeds {text!r}: {part!r} is above the largest seed {MAX_SEED}")
        low = int(match[1])
        high = low if match[2] is None else int(match[2])
        if high < low:
            raise InputError(f"--seeds {text!r}: range {part!r} runs backwards")
        ranges.append(range(low, high + 1))
    count = sum(len(seeds) for seeds in ranges)  # counted before any range is expanded
    if count > MAX_RUNS:
        raise InputError(f"--seeds {text!r}: {count} seeds, more than {MAX_RUNS} runs")
    highest = -1  # of the ranges so far in ascending order: an overlap is a repeated seed
    for seeds in sorted(ranges, key=lambda seeds: seeds.start):
        if seeds.start <= highest:
            raise InputError(f"--seeds {text!r}: seed {seeds.start} given twice")
        highest = max(highest, seeds.stop - 1)
    return tuple(itertools.chain.from_iterable(ranges))


def build_runs(
    options: Sequence[str],
    seeds: Sequence[int | None],
    base_of: Callable[[int | None], MissionBase],
    *,
    stage: str = "full",
) -> tuple[tuple[VaryAxis, ...], tuple[SweepRun, ...]]:
    """Parse the ``--vary`` options and expand the grid, validating every run's mission.

    Parameters
    ----------
    options : sequence of str
        The ``--vary`` texts, ``KEY=v1,v2,...``.
    seeds : sequence of int or None
        The seeds (``[None]`` for a mission file swept without ``--seeds``).
    base_of : callable
        The mission a seed's runs start from (the same one for a mission file).
    stage : str
        The pipeline stage the runs stop after (part of each run's digest).

    Returns
    -------
    axes : tuple of VaryAxis
        The axes with coerced values.
    runs : tuple of SweepRun
        ``product(axis values..., seeds)``, the last axis and then the seed varying fastest.

    Raises
    ------
    InputError
        A key given twice, an unknown key, a value the schema refuses (naming the key and
        value), two values of an axis equal after coercion, or more than :data:`MAX_RUNS` runs.
    """
    parsed = [parse_vary(text) for text in options]
    keys = [key for key, _ in parsed]
    for key in keys:
        if keys.count(key) > 1:
            raise InputError(f"--vary {key} given twice: list all its values in one option")
    size = len(seeds)
    for _, values in parsed:
        size *= len(values)
    if size > MAX_RUNS:
        raise InputError(f"the sweep has {size} runs, more than {MAX_RUNS}: vary fewer values")
    first = base_of(seeds[0])
    axes = tuple(_coerced_axis(key, values, first) for key, values in parsed)
    runs = []
    for combination in itertools.product(*(axis.values for axis in axes), seeds):
        *values, seed = combination
        base = base_of(seed)
        chosen = dict(zip(keys, values, strict=True))
        document = _with_values(base, chosen)
        run_id = run_identifier(chosen, seed)
        try:
            parse_mission(document, base_dir=base.base_dir, source=base.source)
        except InputError as error:
            raise InputError(f"sweep run {run_id} ({base.label}): {error}") from None
        digest = _digest(document, base.base_dir, stage)
        runs.append(SweepRun(run_id, chosen, seed, document, base.base_dir, base.source, digest))
    identifiers = [run.run_id for run in runs]
    if len(set(identifiers)) != len(identifiers):  # only if two sanitised strings collide
        raise InputError("two runs of the sweep would share a folder name: use simpler values")
    return axes, tuple(runs)


def run_identifier(values: Mapping[str, Any], seed: int | None) -> str:
    """The run's folder name: ``key=value`` pairs joined by ``__``, then ``seed=N``.

    Only ``A-Z a-z 0-9 . _ - =`` appear; a value whose text had to be changed to fit, and an
    id longer than :data:`MAX_ID_LENGTH`, end with a digest of the exact values, so ids
    stay unique.

    Examples
    --------
    >>> run_identifier({"weights.terrain": 0.3, "vehicle[1].start.speed": 0.5}, 4)
    'weights.terrain=0.3__vehicle1.start.speed=0.5__seed=4'
    """
    parts = [f"{_SAFE.sub('', key)}={_value_text(value)}" for key, value in values.items()]
    if seed is not None:
        parts.append(f"seed={seed}")
    text = "__".join(parts) or "run"
    exact = json.dumps([list(values.items()), seed], default=str)
    changed = any(
        isinstance(value, str) and _SAFE.sub("_", value) != value for value in values.values()
    )
    if changed or len(text) > MAX_ID_LENGTH:
        text = f"{text[:MAX_ID_LENGTH]}__{hashlib.sha256(exact.encode()).hexdigest()[:10]}"
    return text


def lookup(document: Mapping[str, Any], key: str) -> Any:
    """The value at ``key`` in a mission document (the first element's for a whole array)."""
    node: Any = document
    for name, index in _key_parts(key):
        node = node[name]
        if index is not None:
            node = node[index]
        elif isinstance(node, list) and node and isinstance(node[0], dict):  # array of tables
            node = node[0]
    return node


def _key_parts(key: str) -> list[tuple[str, int | None]]:
    parts = []
    for text in key.split("."):
        match = _PART.match(text)
        if match is None:
            raise InputError(f"--vary {key}: {text!r} is not a key name (e.g. weights.terrain)")
        parts.append((match[1], None if match[2] is None else int(match[2])))
    return parts


def _split_top_level(text: str) -> tuple[list[str], int]:
    """``text`` split at commas outside brackets, braces and quotes; and the deepest nesting."""
    tokens, depth, deepest, quote, start = [], 0, 0, "", 0
    for position, character in enumerate(text):
        if quote:
            quote = "" if character == quote else quote
        elif character in "\"'":
            quote = character
        elif character in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif character in "]}":
            depth -= 1
        elif character == "," and depth == 0:
            tokens.append(text[start:position])
            start = position + 1
    return [*tokens, text[start:]], deepest


def _toml_value(token: str) -> Any:
    """``token`` read as a TOML value, or kept as a string when it is not one."""
    try:
        return tomllib.loads(f"value = {token}")["value"]
    except tomllib.TOMLDecodeError:
        return token


def _with_values(base: MissionBase, values: Mapping[str, Any]) -> dict[str, Any]:
    document = copy.deepcopy(dict(base.document))
    for key, value in values.items():
        _set(document, key, value, base.label)
    return document


def _set(document: dict[str, Any], key: str, value: Any, label: str) -> None:
    """Set ``key`` in ``document`` (creating missing tables; every element of an array)."""
    nodes: list[Any] = [document]
    parts = _key_parts(key)
    for depth, (name, index) in enumerate(parts):
        last = depth == len(parts) - 1
        following = []
        for node in nodes:
            if not isinstance(node, dict):
                where = ".".join(text for text in key.split(".")[:depth])
                raise InputError(f"--vary {key}: {where} is a value, not a table ({label})")
            if last and index is None:
                node[name] = copy.deepcopy(value)
                continue
            child = node.setdefault(name, {} if index is None else [])
            if isinstance(child, list):
                if index is None:
                    following.extend(child)
                    continue
                if index >= len(child):
                    raise InputError(
                        f"--vary {key}: {label} has {len(child)} [[{name}]] tables, "
                        f"no index {index}"
                    )
                if last:
                    child[index] = copy.deepcopy(value)
                else:
                    following.append(child[index])
            elif index is not None:
                raise InputError(f"--vary {key}: {name} is not an array of tables ({label})")
            else:
                following.append(child)
        nodes = following


def _coerced_axis(key: str, values: Sequence[Any], base: MissionBase) -> VaryAxis:
    """The axis with each value validated alone on ``base`` and coerced by the schema."""
    coerced: list[Any] = []
    for value in values:
        document = _with_values(base, {key: value})
        try:
            config = parse_mission(document, base_dir=base.base_dir, source=base.source)
        except InputError as error:
            raise InputError(f"--vary {key}={_shown(value)}: {error}") from None
        typed = lookup(resolved_document(config), key)
        if typed in coerced:
            raise InputError(f"--vary {key}: value {_shown(value)} given twice")
        coerced.append(typed)
    return VaryAxis(key, tuple(coerced))


def _digest(document: Mapping[str, Any], base_dir: Path, stage: str) -> str:
    text = json.dumps(
        {"mission": document, "base_dir": str(base_dir.resolve()), "stage": stage},
        sort_keys=True,
        default=str,
    )
    return hashlib.sha256(text.encode()).hexdigest()


def _value_text(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list | tuple):
        return "-".join(_value_text(item) for item in value)
    if isinstance(value, dict):
        return "-".join(f"{_SAFE.sub('_', key)}-{_value_text(item)}" for key, item in value.items())
    if isinstance(value, float):
        return repr(value)
    return _SAFE.sub("_", str(value))


def _shown(value: Any) -> str:
    return value if isinstance(value, str) else json.dumps(value, default=str)


__all__ = [
    "MAX_RUNS",
    "MissionBase",
    "SweepRun",
    "VaryAxis",
    "build_runs",
    "lookup",
    "parse_seeds",
    "parse_vary",
    "run_identifier",
]
