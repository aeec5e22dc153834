"""Fuzzing ``[current] file``: provider files damaged as real downloads and edits damage them.

Each example writes a valid file of one provider's convention (HYCOM, Copernicus Marine, NOAA
RTOFS, ROMS/CROCO, plain CF; :mod:`._current_files`) and damages it — a variable or
coordinate dropped or renamed, its units, calendar or time units garbled, its values NaN,
infinite or absurd in whole or in a block, a coordinate reversed or shuffled, the times moved
by years, a dimension cut to one index, the file's bytes truncated — then plans a Monterey
mission with it through ``auvplan plan MISSION -o OUT --stage preplan --no-figures``. Every
run must end with exit code 0, 2 or 3, at most one line on stderr, no traceback and nothing
left beside the mission but (on success) the output folder
(:func:`test_fuzz_missions.check_mission`). 12 examples by default, 150 in the slow suite.

Run as a script (``python tests/cli/test_fuzz_current_files.py N SEED``) for a longer
campaign.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, note, settings
from hypothesis import strategies as st
from test_fuzz_missions import check_mission

from ocean._current_files import (
    write_copernicus,
    write_current_file,
    write_hycom,
    write_roms,
    write_rtofs,
)

Choose = Callable[[Sequence[Any]], Any]

#: One MEDUSA on a 300 m leg in Monterey Bay, one hour into the files' times.
MISSION = """
[terrain]
sample = "monterey"
window = {{ lat = [36.788, 36.802], lon = [-121.822, -121.802] }}
[fleet]
horizon_s = 600.0
safety_radius_m = 5.0
[mission]
start_time = 2026-05-01T07:00:00Z
depth_m = {depth}
[current]
file = "{file}"
[[vehicle]]
name = "blue"
start = {{ lat = 36.7945, lon = -121.8150, heading_deg = 60.0 }}
goal = {{ lat = 36.7960, lon = -121.8125, heading_deg = 60.0 }}
"""

WRITERS: dict[str, Callable[[Path], Path]] = {
    "hycom": write_hycom,
    "copernicus": write_copernicus,
    "rtofs-2d": lambda path: write_rtofs(path, three_d=False),
    "rtofs-3d": lambda path: write_rtofs(path, three_d=True),
    "roms": lambda path: write_roms(path, angle_deg=30.0),
    "cf": write_current_file,
}
BAD_UNITS: tuple[Any, ...] = ("furlongs", "", "m", "cm/s", "degrees", "knots", "m s-2")
BAD_TIME_UNITS: tuple[Any, ...] = (
    "hours since bogus", "days since 1-1-1", "seconds since 2026-05-01", "", "fortnights", "1",
)  # fmt: skip
BAD_CALENDARS: tuple[Any, ...] = ("noleap", "360_day", "julian", "bogus", "")
BAD_VALUES: tuple[float, ...] = (np.nan, np.inf, -np.inf, 1e30, -1e30, 0.0, 99.0)


def _damage(dataset: Any, choose: Choose) -> tuple[Any, str]:
    """``dataset`` (opened without CF decoding) damaged once, and what was done."""
    name = choose(sorted(map(str, dataset.variables)))
    variable = dataset[name]
    kind = choose(["drop", "rename", "units", "time", "values", "block", "order", "shift", "cut"])
    values = np.array(variable.values, dtype=np.float64) if variable.dtype.kind in "fiu" else None
    if kind == "drop":
        return dataset.drop_vars(name), f"drop {name}"
    if kind == "rename":
        return dataset.rename_vars({name: f"{name}_x"}), f"rename {name}"
    if kind == "cut" and variable.ndim:
        dim = choose(list(variable.dims))
        return dataset.isel({dim: slice(0, 1)}), f"cut {dim}"
    if kind in ("units", "time"):
        attribute = "units" if kind == "units" else choose(["units", "calendar"])
        bad = BAD_UNITS if kind == "units" else BAD_TIME_UNITS
        variable.attrs[attribute] = choose(bad if attribute == "units" else BAD_CALENDARS)
        return dataset, f"{attribute} of {name}"
    if values is None or not values.ndim:
        return dataset, f"nothing to {kind} in {name}"
    if kind in ("values", "block"):
        whole = tuple(slice(None) for _ in values.shape)
        half = tuple(slice(0, max(1, n // 2)) for n in values.shape)
        values[whole if kind == "values" else half] = choose(BAD_VALUES)
    elif kind == "order" and values.ndim == 1 and values.size > 1:
        values = values[choose([np.arange(values.size)[::-1], np.roll(np.arange(values.size), 3)])]
    elif kind == "shift" and values.ndim == 1:
        values = values + choose([24 * 365 * 5, -1e6, 1e9])
    with np.errstate(invalid="ignore", over="ignore"):
        replaced = (variable.dims, values.astype(variable.dtype), variable.attrs)
    if name in dataset.coords:
        return dataset.assign_coords({name: replaced}), f"{kind} {name}"
    return dataset.assign({name: replaced}), f"{kind} {name}"


def current_mission(choose: Choose, folder: Path) -> tuple[str, list[str]]:
    """A mission's TOML text with a damaged current file in ``folder``, and what was done."""
    import xarray as xr

    convention = choose(sorted(WRITERS))
    clean = WRITERS[convention](folder / "clean.nc")
    damaged = folder / "damaged.nc"
    done = [convention]
    if choose([False] * 4 + [True]):
        data = clean.read_bytes()
        damaged.write_bytes(data[: int(len(data) * choose([0.0, 0.1, 0.5, 0.9, 0.99]))])
        done.append("truncated")
    else:
        with xr.open_dataset(clean, decode_cf=False) as opened:
            dataset = opened.load()
        for _ in range(choose([0, 1, 1, 2, 3])):
            dataset, what = _damage(dataset, choose)
            done.append(what)
        dataset.to_netcdf(damaged)
    depth = choose([0.0, 5.0, 30.0, 5000.0])
    return MISSION.format(depth=depth, file=damaged.as_posix()), done


def _fuzz(data: st.DataObject) -> None:
    with tempfile.TemporaryDirectory() as folder:
        text, done = current_mission(
            lambda options: data.draw(st.sampled_from(list(options))), Path(folder)
        )
        note("\n".join(done) + "\n" + text)
        code, problem = check_mission(text)
    assert problem is None, problem
    event(f"exit {code}")


@settings(
    max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow], database=None
)
@given(st.data())
def test_damaged_current_files_never_crash_or_leave_files(data: st.DataObject) -> None:
    _fuzz(data)


@pytest.mark.slow
@settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow], database=None
)
@given(st.data())
def test_many_damaged_current_files_never_crash_or_leave_files(data: st.DataObject) -> None:
    _fuzz(data)
