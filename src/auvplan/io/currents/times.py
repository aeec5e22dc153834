"""The time axis of a current file, in mission seconds, and the slices the mission needs.

Times are decoded with cftime in the file's own ``calendar`` (``standard``/``gregorian``,
``proleptic_gregorian``, ``noleap``/``365_day``, ``360_day``, ``julian`` …) from CF units
``<unit> since <date>`` (HYCOM ``hours since 2000-01-01 00:00:00``, RTOFS ``MT`` in ``days
since 1900-12-31``, ROMS ``ocean_time`` in ``seconds since …``). A mission time ``t`` [s] is
``[mission] start_time + t`` counted in that calendar (without a start time: the file's first
time). Only the slices the mission flies through are kept: those bracketing ``[0, horizon]``
and one more outside on each end, because the cubic B-spline in time (:class:`auvplan.ocean.
GriddedCurrent`) weighs the slices ``i-1 … i+2`` between slices ``i`` and ``i+1``.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import TYPE_CHECKING, Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.io._raster import first_line

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["TimeWindow", "regular_step", "time_dimension", "time_window"]

#: Reference of the seconds counted from (any date the calendars share).
_SECONDS_UNITS: Final = "seconds since 2000-01-01 00:00:00"


def time_dimension(dataset: xr.Dataset, data: xr.DataArray) -> str | None:
    """The dimension of ``data`` whose coordinate has CF time units (None: no time axis).

    Raises
    ------
    DataFormatError
        If a dimension cf_xarray takes for time has no ``<unit> since <date>`` units.
    """
    import cf_xarray  # noqa: F401  (registers the .cf accessor)
    import xarray as xr

    coordinates = {
        str(dim): dataset.variables[dim] for dim in data.dims if dim in dataset.variables
    }
    for dim, variable in coordinates.items():
        if variable.ndim == 1 and " since " in str(variable.attrs.get("units", "")):
            return dim
    probe = xr.Dataset(coords=coordinates).cf.guess_coord_axis()
    for dim in probe.cf.axes.get("T", []):
        if data.sizes[dim] > 1:
            raise DataFormatError(f"time axis {dim} has no CF time units")
    return None


def mission_seconds(variable: xr.Variable, name: str, start_time: datetime | None) -> FloatArray:
    """Mission time [s] of each value of the time coordinate ``variable`` (module notes).

    Raises
    ------
    DataFormatError
        Units or calendar cftime cannot decode.
    InputError
        ``start_time`` does not exist in the file's calendar (29 February in ``noleap``).
    """
    import cftime

    units = str(variable.attrs["units"])
    calendar = str(variable.attrs.get("calendar", "standard")).lower()
    values = np.asarray(variable.values, dtype=np.float64)
    try:
        with warnings.catch_warnings():  # dates before year 1, which no model has: refused
            warnings.simplefilter("error", cftime.CFWarning)
            dates = cftime.num2date(
                values, units, calendar=calendar, only_use_cftime_datetimes=True
            )
            seconds: FloatArray = np.asarray(
                cftime.date2num(dates, _SECONDS_UNITS, calendar=calendar), dtype=np.float64
            )
    except (ValueError, TypeError, OverflowError, cftime.CFWarning) as error:
        raise DataFormatError(
            f"time axis {name} ({units!r}, calendar {calendar!r}) cannot be decoded "
            f"({first_line(error)})"
        ) from None
    if start_time is None:
        return seconds - float(seconds[0])
    utc = start_time.astimezone(UTC) if start_time.tzinfo is not None else start_time
    try:
        start = cftime.datetime(*utc.timetuple()[:6], utc.microsecond, calendar=calendar)
    except ValueError:
        raise InputError(
            f"mission.start_time {start_time.isoformat()} does not exist in the file's "
            f"{calendar!r} calendar"
        ) from None
    return seconds - float(cftime.date2num(start, _SECONDS_UNITS, calendar=calendar))


@dataclass(frozen=True)
class TimeWindow:
    """The evenly spaced slices a mission needs (module notes).

    Attributes
    ----------
    indices : slice
        The slices kept, along the file's time axis.
    time_step : float
        Interval between them [s] (1 s for a single slice).
    start_offset : float
        Mission time [s] of the first kept slice.
    """

    indices: slice
    time_step: float
    start_offset: float


def time_window(
    dataset: xr.Dataset,
    time_dim: str | None,
    start_time: datetime | None,
    horizon: float | None,
) -> TimeWindow | None:
    """The slices of the time axis ``time_dim`` covering mission times ``[0, horizon]`` [s].

    None without a time axis; ``horizon`` None keeps every slice after the start. A single
    slice is the current at every time (as a file without a time axis).

    Raises
    ------
    DataFormatError
        Times that do not increase, or kept slices not evenly spaced.
    InputError
        ``start_time`` outside the file's times.
    """
    if time_dim is None:
        return None
    seconds = mission_seconds(dataset.variables[time_dim], time_dim, start_time)
    last = seconds.size - 1
    if np.any(np.diff(seconds) <= 0.0):
        raise DataFormatError(f"time axis {time_dim} does not increase")
    if last > 0 and not seconds[0] <= 0.0 <= seconds[-1]:
        assert start_time is not None  # without one, mission time 0 is the first slice
        raise InputError(
            f"mission.start_time {start_time.isoformat()} is outside the file's times (its "
            f"first slice is {seconds[0] / 3600.0:+.2f} h, its last {seconds[-1] / 3600.0:+.2f} "
            "h from it)"
        )
    first = int(np.searchsorted(seconds, 0.0, side="right")) - 1
    end = last if horizon is None else int(np.searchsorted(seconds, horizon, side="left"))
    indices = slice(max(first - 1, 0), min(end + 1, last) + 1)
    kept = seconds[indices]
    if kept.size == 1:
        return TimeWindow(indices, 1.0, 0.0)
    return TimeWindow(indices, regular_step(kept, time_dim), float(kept[0]))


def regular_step(axis: FloatArray, label: str) -> float:
    """The step of an evenly spaced increasing axis.

    Raises
    ------
    DataFormatError
        If the steps differ by more than 1e-3 of their mean or do not increase.
    """
    steps = np.diff(axis)
    step = float(steps.mean()) if steps.size else 1.0
    if steps.size and (step <= 0.0 or np.max(np.abs(steps - step)) > 1e-3 * abs(step)):
        raise DataFormatError(f"{label} axis is not evenly spaced and increasing")
    return step
