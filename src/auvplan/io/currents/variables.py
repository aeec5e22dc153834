"""Which variables of a current file are the two velocity components, and their units.

Found by CF standard name with cf_xarray (``eastward_sea_water_velocity`` /
``northward_sea_water_velocity``; ROMS ``sea_water_x_velocity_at_u_location`` /
``sea_water_y_velocity_at_v_location``), else by the names each provider publishes
(:data:`CURRENT_NAMES`). Components on the staggered ROMS/CROCO C-grid (``u`` along
``xi_u``, ``v`` along ``eta_v``) are grid-relative and handled by :mod:`.roms`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError

if TYPE_CHECKING:
    import xarray as xr

__all__ = [
    "CURRENT_NAMES",
    "MAX_CURRENT",
    "Components",
    "find_components",
    "finite_values",
    "velocity_values",
]

#: ``(east, north)`` names tried in order after the CF standard names: Copernicus Marine,
#: HYCOM, NOAA RTOFS 2-D files, then RTOFS 3-D files, ROMS/CROCO and plain files.
CURRENT_NAMES: Final = (
    ("uo", "vo"),
    ("water_u", "water_v"),
    ("u_velocity", "v_velocity"),
    ("u", "v"),
)
_STANDARD_NAMES: Final = ("eastward_sea_water_velocity", "northward_sea_water_velocity")
#: Fastest current [m/s] a file may hold: above every ocean and tidal current measured (the
#: Saltstraumen tidal race, about 11 m/s); beyond it the values are fill without a declared
#: ``_FillValue``, or the units are wrong.
MAX_CURRENT: Final = 15.0
_GRID_STANDARD_NAMES: Final = (
    "sea_water_x_velocity_at_u_location",
    "sea_water_y_velocity_at_v_location",
)
#: Dimensions of the ROMS/CROCO C-grid's u and v points.
_U_DIMS: Final = ("eta_u", "xi_u")
_V_DIMS: Final = ("eta_v", "xi_v")
#: Velocity units understood, with their factor to m/s.
_UNITS: Final = {
    "m s-1": 1.0, "m/s": 1.0, "m s**-1": 1.0, "m.s-1": 1.0, "meter second-1": 1.0,
    "meters/second": 1.0, "meter/second": 1.0, "meters second-1": 1.0, "cm s-1": 0.01,
    "cm/s": 0.01,
}  # fmt: skip


@dataclass(frozen=True)
class Components:
    """The file's velocity variables.

    ``east``/``north`` are earth-relative components on the same nodes, or, when ``staggered``,
    the ROMS/CROCO grid-relative ``u`` (along ξ, on the u-points) and ``v`` (along η, on the
    v-points).
    """

    east: str
    north: str
    staggered: bool


def find_components(dataset: xr.Dataset) -> Components:
    """The two velocity variables of ``dataset`` (module notes).

    Raises
    ------
    DataFormatError
        If none of the standard names or provider names is there (naming what the file has).
    """
    import cf_xarray  # noqa: F401  (registers the .cf accessor)

    by_standard = dataset.cf.standard_names
    for names, staggered in ((_STANDARD_NAMES, False), (_GRID_STANDARD_NAMES, True)):
        if all(name in by_standard for name in names):
            return Components(by_standard[names[0]][0], by_standard[names[1]][0], staggered)
    for east, north in CURRENT_NAMES:
        if east in dataset.data_vars and north in dataset.data_vars:
            dims = (*dataset[east].dims, *dataset[north].dims)
            staggered = all(dim in dims for dim in (*_U_DIMS, *_V_DIMS))
            return Components(east, north, staggered)
    raise DataFormatError(
        f"no current variables (standard_name {' / '.join(_STANDARD_NAMES)}, or "
        f"{', '.join('/'.join(pair) for pair in CURRENT_NAMES)}); has "
        f"{sorted(map(str, dataset.data_vars))}"
    )


def velocity_values(data: xr.DataArray, values: object) -> FloatArray:
    """``values`` of the component ``data`` in m/s, each NaN or within :data:`MAX_CURRENT`.

    The factor comes from the variable's ``units`` (none: m/s); NaN is land or fill.

    Raises
    ------
    DataFormatError
        If the units are not a velocity this module knows, or a value is infinite or faster
        than :data:`MAX_CURRENT` (naming the variable, the first value and the count).
    """
    units = str(data.attrs.get("units", "m s-1")).strip()
    if units not in _UNITS:
        raise DataFormatError(f"{data.name} has units {units!r}, not a velocity (m s-1)")
    speeds = _UNITS[units] * np.asarray(values, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        wild = np.abs(speeds) > MAX_CURRENT
    if np.any(wild):
        raise DataFormatError(
            f"{data.name} holds {speeds[wild].flat[0]:g} m/s at {np.count_nonzero(wild)} of its "
            f"{speeds.size} values, faster than any current ({MAX_CURRENT:g} m/s): fill values "
            "without a _FillValue, or wrong units?"
        )
    return speeds


def finite_values(dataset: xr.Dataset, name: str) -> FloatArray:
    """The values of the coordinate or grid variable ``name``, all finite numbers.

    Raises
    ------
    DataFormatError
        If one is not (naming the coordinate and the count).
    """
    values = np.asarray(dataset[name].values, dtype=np.float64)
    bad = np.count_nonzero(~np.isfinite(values))
    if bad:
        raise DataFormatError(f"{name} holds {bad} of {values.size} values that are not numbers")
    return values
