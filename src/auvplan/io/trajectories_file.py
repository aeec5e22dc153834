"""``trajectories.nc``: the optimised trajectories as a CF ``featureType = "trajectory"`` file.

It follows the NCEI NetCDF trajectory template v2.0 and carries ACDD-1.3 discovery attributes
(:func:`_discovery_attributes`: computed from the plan; who made it, from the mission's
``[metadata]``, and when, as ``maps.nc`` does, by :mod:`auvplan.io._discovery`), and every
variable its ``coverage_content_type`` and valid range.

The layout follows the NCEI NetCDF trajectory template (v2.0, multidimensional array
representation, CF §H.4.1): one ``trajectory`` per vehicle (the ``trajectory`` variable holds
the vehicle names, ``cf_role = "trajectory_id"``) and ``obs`` samples on the solver's time
grid. ``time``, ``lat``, ``lon`` and ``depth`` are the auxiliary coordinates of every variable
(the names of ``trajectories.csv`` are kept where the quantity is the same):

* ``time`` [seconds since ``start_time``, UTC] (standard name ``time``);
* ``lat``, ``lon`` [degrees, WGS 84] (``latitude``, ``longitude``; georeferenced terrain only);
* ``depth`` [m, positive down], the plan's constant depth (``depth``), or each sample's
  depth along a depth profile (``[mission] altitude_m``), which also writes ``altitude``
  [m], the height above the seabed (``height_above_sea_floor``);
* ``north``, ``east`` [m]: the position in the local frame of ``maps.nc``;
* ``heading`` [degree]: ψ clockwise from true north (``platform_orientation``);
* ``u``, ``v`` [m s-1]: surge (body x, forward) and sway (body y, to starboard) speed through
  the water (``platform_surge_rate_fore``, ``platform_sway_rate_starboard``);
* ``r`` [rad s-1]: yaw rate, positive bow to starboard (``platform_yaw_rate_fore_starboard``);
* ``n_ps``, ``n_sb`` [s-1]: port and starboard propeller speeds (revolutions per second);
* ``power`` [W]: electrical power drawn from the battery.

A fleet with other actuators (:func:`actuator_series`) adds, after these, each other state by
its ``trajectories.csv`` name: ``n_<thruster>`` [s-1] and ``delta_<surface>`` [rad] (a
``remus100``: ``n_prop``, ``delta_rudder``), and ``vehicle_type`` (the vehicle type's name per
trajectory). A vehicle's samples of a state it does not have (a ``remus100``'s ``n_ps``) are
NaN, written as the ``_FillValue`` NaN; variables without missing samples have no
``_FillValue``, so an all-MEDUSA file is unchanged.

On a georeferenced terrain the local frame's north is the north of a transverse Mercator
projection centred on the map, which differs from true north by the meridian convergence
(about 1e-4 rad a kilometre off the central meridian); ``heading`` is corrected for it, so it
is a true heading. On terrain without georeference (the synthetic bank) there is no ``lat`` /
``lon`` and ``heading`` is relative to the local north.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from datetime import datetime, timedelta
from pathlib import Path
from typing import TYPE_CHECKING, Any, Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError
from auvplan.io._discovery import (
    DEPTH_BELOW_SEA_SURFACE_CRS,
    content_id,
    geospatial_attributes,
    run_attributes,
)
from auvplan.terrain.projection import LocalProjection

if TYPE_CHECKING:
    import xarray as xr

#: The state and output series written, by their ``trajectories.csv`` names: CF attributes.
SERIES: Final[Mapping[str, Mapping[str, str]]] = {
    "north": {"units": "m", "long_name": "north of the local frame's origin"},
    "east": {"units": "m", "long_name": "east of the local frame's origin"},
    "u": {
        "units": "m s-1",
        "standard_name": "platform_surge_rate_fore",
        "long_name": "surge speed through the water (body x, forward)",
    },
    "v": {
        "units": "m s-1",
        "standard_name": "platform_sway_rate_starboard",
        "long_name": "sway speed through the water (body y, to starboard)",
    },
    "r": {
        "units": "rad s-1",
        "standard_name": "platform_yaw_rate_fore_starboard",
        "long_name": "yaw rate (positive: bow to starboard)",
    },
    "n_ps": {"units": "s-1", "long_name": "port propeller speed (revolutions per second)"},
    "n_sb": {"units": "s-1", "long_name": "starboard propeller speed (revolutions per second)"},
    "power": {"units": "W", "long_name": "electrical power drawn from the battery"},
}
_LAT_ATTRIBUTES: Final = {
    "standard_name": "latitude",
    "long_name": "latitude (WGS 84)",
    "units": "degrees_north",
    "axis": "Y",
}
_LON_ATTRIBUTES: Final = {
    "standard_name": "longitude",
    "long_name": "longitude (WGS 84)",
    "units": "degrees_east",
    "axis": "X",
}
#: Attributes of an actuator's state by its name prefix: units and a long name ``{}``.
_ACTUATOR_ATTRIBUTES: Final = {
    "n_": ("s-1", "speed of propeller {} (revolutions per second)"),
    "delta_": ("rad", "deflection of control surface {} (positive: bow turns to starboard)"),
}
#: Length [m] of the step along ψ used to measure the meridian convergence.
_HEADING_STEP_M: Final = 1.0


def actuator_series(names: Sequence[str]) -> dict[str, dict[str, str]]:
    """CF attributes of the actuator states ``names`` not in :data:`SERIES`, by name.

    ``n_<thruster>`` [s-1] and ``delta_<surface>`` [rad]
    (:class:`auvplan.vehicle.ThrusterParams`, :class:`auvplan.vehicle.ControlSurfaceParams`).

    Raises
    ------
    DataFormatError
        For a name that is neither.

    Examples
    --------
    >>> actuator_series(["n_ps", "n_prop"])["n_prop"]["units"]
    's-1'
    """
    attributes = {}
    for name in names:
        if name in SERIES:
            continue
        prefix = next((p for p in _ACTUATOR_ATTRIBUTES if name.startswith(p)), None)
        if prefix is None:
            raise DataFormatError(f"state {name!r} is not an actuator state (n_* or delta_*)")
        units, long_name = _ACTUATOR_ATTRIBUTES[prefix]
        attributes[name] = {"units": units, "long_name": long_name.format(name[len(prefix) :])}
    return attributes


def true_heading(
    projection: LocalProjection | None, north: FloatArray, east: FloatArray, psi: FloatArray
) -> FloatArray:
    """Heading [deg] in ``[0, 360)``, clockwise from true north, of ψ [rad] in the local frame.

    The geodesic azimuth (WGS 84) from each point to the point one metre ahead along ψ, so
    that the projection's meridian convergence is accounted for. Without a projection, ψ in
    degrees.
    """
    if projection is None:
        return np.mod(np.degrees(psi), 360.0)
    from pyproj import Geod

    lat, lon = projection.to_geographic(north, east)
    ahead_lat, ahead_lon = projection.to_geographic(
        north + _HEADING_STEP_M * np.cos(psi), east + _HEADING_STEP_M * np.sin(psi)
    )
    azimuth, _, _ = Geod(ellps="WGS84").inv(lon, lat, ahead_lon, ahead_lat)
    return np.mod(np.asarray(azimuth, dtype=np.float64), 360.0)


def trajectories_dataset(
    names: Sequence[str],
    time: FloatArray,
    series: Mapping[str, FloatArray],
    *,
    psi: FloatArray,
    start_time: datetime,
    depth: float | FloatArray,
    projection: LocalProjection | None,
    attributes: Mapping[str, Any],
    vehicle_types: Sequence[str] | None = None,
    metadata: Mapping[str, str] | None = None,
    created: datetime | None = None,
    altitude: FloatArray | None = None,
) -> xr.Dataset:
    """The content of ``trajectories.nc`` as :func:`read_trajectories_netcdf` returns it.

    ``time`` is decoded (UTC ``datetime64``); the CF encoding of the file (time units, no fill
    values, the vehicle names as characters) is kept in each variable's ``encoding``, so that
    ``dataset.to_netcdf(path)`` writes ``trajectories.nc``.

    Parameters
    ----------
    names : sequence of str
        Vehicle names, length ``n_vehicles``.
    time : ndarray of shape (n_t,)
        Time since ``start_time`` [s].
    series : mapping of str to ndarray of shape (n_vehicles, n_t)
        Every entry of :data:`SERIES` by name, in its unit, then any other actuator states
        (:func:`actuator_series`); NaN where a vehicle has no such state.
    psi : ndarray of shape (n_vehicles, n_t)
        Yaw angle [rad], clockwise from the local north.
    start_time : datetime
        UTC time of ``t = 0`` (time-zone aware).
    depth : float or ndarray of shape (n_vehicles, n_t)
        Constant depth [m] of the plan, or each sample's depth (a depth profile).
    projection : LocalProjection or None
        Local frame to WGS 84; ``None`` gives no ``lat``/``lon``.
    attributes : mapping
        Extra global attributes (strings or numbers).
    vehicle_types : sequence of str, optional
        Each vehicle's type name, written as ``vehicle_type`` when given.
    metadata : mapping of str to str, optional
        Who made the plan: ACDD attributes by name (the mission's ``[metadata]``); an
        attribute computed here or in ``attributes`` takes precedence.
    created : datetime, optional
        Time the plan was made: ``date_created``, ``date_modified`` and ``date_issued``
        (none when not given).
    altitude : ndarray of shape (n_vehicles, n_t), optional
        Height above the seabed [m] along a depth profile, written as ``altitude``.

    Returns
    -------
    xarray.Dataset
        Dimensions ``trajectory`` (vehicles) and ``obs`` (samples); see the module notes.
    """
    import xarray as xr

    n_vehicles, n_t = len(names), time.size
    shape = (n_vehicles, n_t)
    dims = ("trajectory", "obs")
    north, east = series["north"], series["east"]
    epoch = np.datetime64(start_time.replace(tzinfo=None), "ns")
    offsets = np.rint(np.asarray(time, dtype=np.float64) * 1e9).astype("timedelta64[ns]")
    coords: dict[str, Any] = {
        "trajectory": (
            "trajectory",
            np.array(names, dtype=object),
            {"cf_role": "trajectory_id", "long_name": "vehicle name"},
        ),
        "time": (
            dims,
            np.broadcast_to(epoch + offsets, shape).copy(),
            {"standard_name": "time", "long_name": "time (UTC)", "axis": "T"},
        ),
        "depth": (
            dims,
            np.broadcast_to(np.asarray(depth, dtype=np.float64), shape).copy(),
            {
                "standard_name": "depth",
                "long_name": "depth below the sea surface",
                "units": "m",
                "positive": "down",
                "axis": "Z",
            },
        ),
    }
    if projection is not None:
        lat, lon = projection.to_geographic(north, east)
        coords["lat"] = (dims, lat, _LAT_ATTRIBUTES)
        coords["lon"] = (dims, lon, _LON_ATTRIBUTES)
    heading_reference = "true north" if projection is not None else "the local frame's north"
    data: dict[str, Any] = {
        name: (dims, np.asarray(series[name], dtype=np.float64), dict(attrs))
        for name, attrs in {**SERIES, **actuator_series(list(series))}.items()
    }
    data["heading"] = (
        dims,
        true_heading(projection, north, east, psi),
        {
            "units": "degree",
            "standard_name": "platform_orientation",
            "long_name": f"heading, clockwise from {heading_reference}",
        },
    )
    if altitude is not None:
        data["altitude"] = (
            dims,
            np.asarray(altitude, dtype=np.float64),
            {
                "units": "m",
                "standard_name": "height_above_sea_floor",
                "long_name": "height of the vehicle above the seabed",
            },
        )
    if vehicle_types is not None:
        data["vehicle_type"] = (
            "trajectory",
            np.array(vehicle_types, dtype=object),
            {"long_name": "vehicle type (auvplan vehicle file name)"},
        )
    dataset = xr.Dataset(data, coords=coords)
    for name, variable in dataset.variables.items():
        variable.attrs["coverage_content_type"] = (
            "coordinate" if name in dataset.coords else "modelResult"
        )
        if variable.dtype.kind == "f" and bool(np.isfinite(variable.values).any()):
            variable.attrs["valid_min"] = float(np.nanmin(variable.values))
            variable.attrs["valid_max"] = float(np.nanmax(variable.values))
    dataset.attrs = {
        **run_attributes(metadata, created),
        **_discovery_attributes(dataset, names, time, start_time),
        **attributes,
    }
    for variable in dataset.variables.values():
        is_filled = variable.dtype.kind == "f" and bool(np.isnan(variable.values).any())
        variable.encoding["_FillValue"] = np.nan if is_filled else None
    dataset["trajectory"].encoding.update(dtype="S1", char_dim_name="name_strlen")
    if vehicle_types is not None:
        dataset["vehicle_type"].encoding.update(dtype="S1", char_dim_name="type_strlen")
    dataset["time"].encoding.update(
        units=f"seconds since {start_time.strftime('%Y-%m-%dT%H:%M:%S.%fZ')}",
        calendar="standard",
        dtype="float64",
    )
    return dataset


#: The NCEI NetCDF template the file follows (checked by ``cc-plugin-ncei``).
NCEI_TEMPLATE: Final = "NCEI_NetCDF_Trajectory_Template_v2.0"
#: ``Conventions``: the file follows CF-1.8 (``compliance-checker -t cf:1.8``) and ACDD-1.3;
#: the NCEI trajectory template v2.0 requires ``CF-1.6`` in the list too (its checker,
#: ``compliance-checker -t ncei-trajectory:2.0``, finds no required attribute missing).
CONVENTIONS: Final = "CF-1.8, CF-1.6, ACDD-1.3"


def _discovery_attributes(
    dataset: xr.Dataset,
    names: Sequence[str],
    time: FloatArray,
    start_time: datetime,
) -> dict[str, Any]:
    """CF, ACDD-1.3 and NCEI trajectory-template global attributes from the data itself.

    Everything is derived from the plan (extent, times, vehicles): the same plan gives the
    same attributes. ``id`` is the :func:`~auvplan.io._discovery.content_id` of the
    positions; ``time_coverage_duration`` and ``_resolution`` are ISO 8601 durations
    (``PT<seconds>S``) of the horizon and the solver step. The attributes of the run (who,
    when, version) are :func:`~auvplan.io._discovery.run_attributes`.
    """
    end_time = start_time + timedelta(seconds=float(time[-1]))
    depth = dataset["depth"].values
    shallowest, deepest = float(np.min(depth)), float(np.max(depth))
    depths = (
        f"at a constant depth of {shallowest:g} m"
        if shallowest == deepest
        else f"at depths of {shallowest:.1f} to {deepest:.1f} m"
    )
    attributes: dict[str, Any] = {
        "Conventions": CONVENTIONS,
        "ncei_template_version": NCEI_TEMPLATE,
        "featureType": "trajectory",
        "cdm_data_type": "Trajectory",
        "title": "auvplan optimised trajectories",
        "summary": f"Energy-optimal, collision-free trajectories of {len(names)} marine "
        f"vehicle(s) ({', '.join(names)}) planned by auvplan over a bathymetry grid, from "
        f"{start_time.isoformat()} to {end_time.isoformat()}, {depths}: positions, body "
        "velocities, actuator states and electrical power at the solver's time steps.",
        "keywords": "autonomous underwater vehicle, AUV, trajectory planning, multi-vehicle, "
        "terrain-aided navigation, bathymetry, energy",
        "id": content_id(dataset["north"].values, dataset["east"].values),
        "source": "numerical trajectory optimisation (auvplan)",
        "processing_level": "planned trajectories (model output), not measurements",
        "time_coverage_start": start_time.isoformat(),
        "time_coverage_end": end_time.isoformat(),
        "time_coverage_duration": f"PT{float(time[-1]):g}S",
        "time_coverage_resolution": f"PT{float(time[1] - time[0]):g}S" if time.size > 1 else "",
        "comment": "A plan, not observations: what each vehicle is to fly, at the optimiser's "
        "time steps (trajectories.csv holds the same numbers).",
        "acknowledgment": "Method: Häusler, Saccon, Pascoal, Hauser and Aguiar, Cooperative AUV "
        "Motion Planning using Terrain Information, OCEANS 2013; bathymetry: the source named "
        "in the run's summary.json",
    }
    is_georeferenced = "lat" in dataset.coords
    attributes |= geospatial_attributes(
        dataset["lat"].values if is_georeferenced else None,
        dataset["lon"].values if is_georeferenced else None,
        depth,
        vertical_crs=DEPTH_BELOW_SEA_SURFACE_CRS,
    )
    return attributes


def read_trajectories_netcdf(path: Path) -> xr.Dataset:
    """Read ``trajectories.nc`` into memory (times decoded as UTC ``datetime64``).

    Raises
    ------
    DataFormatError
        If the file cannot be read or lacks a variable of :data:`SERIES`, ``time`` or
        ``trajectory``; the message names the file.
    """
    import xarray as xr

    try:
        with xr.open_dataset(path) as dataset:
            loaded = dataset.load()
    except (OSError, ValueError, RuntimeError, TypeError, KeyError) as error:
        raise DataFormatError(f"{path}: unreadable NetCDF ({error})") from None
    missing = sorted({"time", "trajectory", *SERIES} - set(map(str, loaded.variables)))
    if missing:
        raise DataFormatError(f"{path}: not an auvplan trajectories file (no {', '.join(missing)})")
    return loaded


__all__ = [
    "SERIES",
    "actuator_series",
    "read_trajectories_netcdf",
    "trajectories_dataset",
    "true_heading",
]
