"""Exports of a finished plan for vehicles, ground stations and GIS.

=========== ========================== ===================================================
format      files                      for
=========== ========================== ===================================================
``moos``    ``NAME.bhv``,              MOOS-IvP pHelmIvP (a timed ``BHV_Waypoint`` per
            ``origin.moos``            leg, UTM x/y)
``qgc``     ``NAME.plan``              QGroundControl / ArduSub (waypoints, geofences)
``imc``     ``NAME.imc.json``          Neptus / LSTS IMC (``FollowTrajectory``, timed)
``gpx``     ``trajectories.gpx``       GPX 1.1 viewers (timed tracks)
``kml``     ``trajectories.kml``       Google Earth (``gx:Track`` with time stamps)
``geojson`` ``trajectories.geojson``,  GIS: a ``LineString`` per vehicle, a timed ``Point``
            ``waypoints.geojson``,     per waypoint (QGIS temporal controller), keep-out
            ``obstacles.geojson``      ``Polygon``s
=========== ========================== ===================================================

Every format is written from the same waypoints: each track thinned to ``tolerance`` with its
time law kept (:func:`auvplan.export.waypoints.thin_track`). The plan they are written from is
an :class:`auvplan.export.plan.ExportPlan`. Every format but ``moos`` in its ``local`` frame
places the plan in lat/lon, so on terrain without geographic reference (the synthetic bank)
only that one is written (:func:`check_georeference`). This module imports nothing heavy
(not even numpy) until a format is rendered, so that the command line starts fast.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Final, Literal, get_args

from auvplan.errors import InputError

if TYPE_CHECKING:
    from auvplan.export.plan import ExportPlan
    from auvplan.export.waypoints import Waypoints

#: The export formats, each rendered by the module of the same name in this package.
FORMATS: Final = ("moos", "qgc", "imc", "gpx", "kml", "geojson")
#: Frames of the MOOS-IvP points (:mod:`auvplan.export.moos`); the first is the default.
MoosFrame = Literal["utm", "local"]
MOOS_FRAMES: Final = get_args(MoosFrame)
#: Default waypoint tolerance [m] (see :func:`auvplan.export.waypoints.thin_track`).
DEFAULT_TOLERANCE_M: Final = 1.0
#: Largest waypoint tolerance [m]: half the Earth's circumference, farther than any two
#: points of a plan are apart (any larger tolerance thins the same way).
MAX_TOLERANCE_M: Final = 2.0e7


def parse_formats(text: str) -> tuple[str, ...]:
    """The formats of a comma-separated list, in the order given, without repeats.

    Raises
    ------
    InputError
        If a name is not one of :data:`FORMATS` or the list is empty.

    Examples
    --------
    >>> parse_formats("gpx, kml,gpx")
    ('gpx', 'kml')
    """
    names = [name.strip().lower() for name in text.split(",") if name.strip()]
    unknown = [name for name in names if name not in FORMATS]
    if unknown or not names:
        shown = repr(unknown[0]) if unknown else "none given"
        raise InputError(f"unknown export format {shown} (choose from {', '.join(FORMATS)})")
    return tuple(dict.fromkeys(names))


def check_moos_frame(frame: str) -> None:
    """Raise InputError unless ``frame`` is one of :data:`MOOS_FRAMES`."""
    if frame not in MOOS_FRAMES:
        raise InputError(f"MOOS frame {frame!r} is not one of {', '.join(MOOS_FRAMES)}")


def check_georeference(formats: Sequence[str], moos_frame: str, terrain: str) -> None:
    """Refuse the formats that need lat/lon, for a plan on ``terrain`` without georeference.

    Only ``moos`` in the ``local`` frame (x east, y north of the plan's own frame) is written
    from north/east alone.

    Raises
    ------
    InputError
        Naming the first such format of ``formats`` and ``terrain`` (e.g. ``"the synthetic
        bank"``).

    Examples
    --------
    >>> check_georeference(["moos"], "local", "the synthetic bank")
    >>> check_georeference(["moos", "gpx"], "local", "the synthetic bank")
    Traceback (most recent call last):
    ...
    auvplan.errors.InputError: gpx export needs lat/lon, but the synthetic bank has no geog...
    """
    for name in formats:
        if name == "moos" and moos_frame == "local":
            continue
        hint = " (or export moos with --moos-frame local)" if name == "moos" else ""
        raise InputError(
            f"{name} export needs lat/lon, but {terrain} has no geographic reference: "
            f"plan on a georeferenced bathymetry file{hint}"
        )


def check_tolerance(tolerance: float) -> None:
    """Raise InputError unless ``tolerance`` [m] is a number from 0 to :data:`MAX_TOLERANCE_M`.

    Examples
    --------
    >>> check_tolerance(1e300)
    Traceback (most recent call last):
    ...
    auvplan.errors.InputError: waypoint tolerance must be >= 0 and <= 2e+07 m, got 1e+300
    """
    if not 0.0 <= tolerance <= MAX_TOLERANCE_M:  # False for NaN
        raise InputError(
            f"waypoint tolerance must be >= 0 and <= {MAX_TOLERANCE_M:g} m, got {tolerance:g}"
        )


def render_exports(
    plan: ExportPlan,
    formats: Sequence[str],
    *,
    tolerance: float = DEFAULT_TOLERANCE_M,
    moos_frame: MoosFrame = "utm",
) -> dict[str, str]:
    """The text of every export file, by file name.

    Parameters
    ----------
    plan : ExportPlan
        The finished plan.
    formats : sequence of str
        Names from :data:`FORMATS`.
    tolerance : float
        Waypoint tolerance [m].
    moos_frame : {"utm", "local"}
        The frame of the MOOS-IvP ``points`` (:mod:`auvplan.export.moos`).

    Returns
    -------
    dict of str to str
        File name (no folder) to its text.

    Raises
    ------
    InputError
        If ``moos_frame`` or ``tolerance`` is out of its range, a format is unknown, or a
        format needs lat/lon the plan does not have (:func:`check_georeference`).
    """
    from auvplan.export import geojson, gpx, imc, kml, moos, qgc
    from auvplan.export.waypoints import thin_track

    check_moos_frame(moos_frame)
    check_tolerance(tolerance)
    names = parse_formats(",".join(formats))
    if not plan.is_georeferenced:
        check_georeference(names, moos_frame, "the plan's terrain")
    renderers: dict[str, Callable[[ExportPlan, list[Waypoints]], dict[str, str]]] = {
        "moos": functools.partial(moos.render, frame=moos_frame),
        "qgc": qgc.render,
        "imc": imc.render,
        "gpx": gpx.render,
        "kml": kml.render,
        "geojson": geojson.render,
    }
    fleet = [thin_track(track, tolerance) for track in plan.tracks]
    files: dict[str, str] = {}
    for name in names:
        files.update(renderers[name](plan, fleet))
    return files


def write_exports(
    plan: ExportPlan,
    directory: Path,
    formats: Sequence[str],
    *,
    tolerance: float = DEFAULT_TOLERANCE_M,
    moos_frame: MoosFrame = "utm",
) -> list[Path]:
    """Write :func:`render_exports` into ``directory`` (created) and return the paths."""
    from auvplan.io.results import write_text_files

    files = render_exports(plan, formats, tolerance=tolerance, moos_frame=moos_frame)
    return write_text_files(directory, files)


__all__ = [
    "DEFAULT_TOLERANCE_M",
    "FORMATS",
    "MAX_TOLERANCE_M",
    "MOOS_FRAMES",
    "MoosFrame",
    "check_georeference",
    "check_moos_frame",
    "check_tolerance",
    "parse_formats",
    "render_exports",
    "write_exports",
]
