"""ACDD-1.3 discovery attributes that ``trajectories.nc`` and ``maps.nc`` share.

Only facts of the data and of the run are computed: the extent, the dates of the run, the
version of auvplan and an ``id`` from the content. Who made the file (creator, institution,
publisher, licence) is never made up: it is the mission's ``[metadata]``
(:class:`auvplan.mission.tables.MetadataConfig`) as the user gave it, or absent.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from datetime import UTC, datetime
from typing import Any, Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan._version import __version__

#: ``standard_name_vocabulary``: the CF standard name table the variables' names are from.
STANDARD_NAME_VOCABULARY: Final = "CF Standard Name Table v93"
#: ``geospatial_bounds_vertical_crs`` of depths below the sea surface (positive down).
DEPTH_BELOW_SEA_SURFACE_CRS: Final = "EPSG:5831"


def run_attributes(metadata: Mapping[str, str] | None, created: datetime | None) -> dict[str, Any]:
    """Who made the file, when and with which auvplan: the global attributes of every file.

    Parameters
    ----------
    metadata : mapping of str to str or None
        The mission's ``[metadata]`` (ACDD attributes by name), written as given; the other
        attributes returned here take precedence over a key of the same name.
    created : datetime or None
        Time the file's content was made (time-zone aware): ``date_created``,
        ``date_modified``, ``date_issued`` and ``date_metadata_modified`` (none when not given).
    """
    return {
        **(metadata or {}),
        "product_version": __version__,
        "standard_name_vocabulary": STANDARD_NAME_VOCABULARY,
        **(_dates(created) if created is not None else {}),
    }


def content_id(*arrays: FloatArray) -> str:
    """ACDD ``id``: ``auvplan-`` and the first 16 hexadecimal digits of the SHA-256 of ``arrays``.

    The same content gives the same id; different content a different one, whatever the
    ``naming_authority``.
    """
    digest = hashlib.sha256()
    for array in arrays:
        digest.update(np.ascontiguousarray(array).tobytes())
    return f"auvplan-{digest.hexdigest()[:16]}"


def geospatial_attributes(
    lat: FloatArray | None,
    lon: FloatArray | None,
    depth: FloatArray,
    *,
    vertical_crs: str | None,
) -> dict[str, Any]:
    """ACDD ``geospatial_*`` extent of positions ``lat``, ``lon`` [deg] and ``depth`` [m].

    ``depth`` is positive down; NaN values (land) are left out, and without a finite depth
    there is no vertical extent. Latitude and longitude (``None`` on terrain without
    georeference) give the horizontal extent, its WKT polygon (``geospatial_bounds``, WGS 84)
    and, then, ``vertical_crs`` as ``geospatial_bounds_vertical_crs`` when given.
    """
    attributes: dict[str, Any] = {}
    finite = depth[np.isfinite(depth)]
    if finite.size:
        attributes.update(
            geospatial_vertical_min=float(np.min(finite)),
            geospatial_vertical_max=float(np.max(finite)),
            geospatial_vertical_units="m",
            geospatial_vertical_positive="down",
        )
    if lat is not None and lon is not None:
        attributes.update(
            geospatial_lat_min=float(np.min(lat)),
            geospatial_lat_max=float(np.max(lat)),
            geospatial_lat_units="degrees_north",
            geospatial_lon_min=float(np.min(lon)),
            geospatial_lon_max=float(np.max(lon)),
            geospatial_lon_units="degrees_east",
            geospatial_bounds=_bounds_wkt(lat, lon),
            geospatial_bounds_crs="EPSG:4326",
        )
        if vertical_crs is not None:
            attributes["geospatial_bounds_vertical_crs"] = vertical_crs
    return attributes


def _dates(created: datetime) -> dict[str, str]:
    """ACDD ``date_created``, ``_modified``, ``_issued``, ``_metadata_modified``: ISO 8601.

    The content and its metadata are made, last changed and issued at once (UTC, whole
    seconds, ``Z``).
    """
    text = created.astimezone(UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
    return {
        "date_created": text,
        "date_modified": text,
        "date_issued": text,
        "date_metadata_modified": text,
    }


def _bounds_wkt(lat: FloatArray, lon: FloatArray) -> str:
    """ACDD ``geospatial_bounds``: the WKT polygon (lat lon order) around every position."""
    south, north = float(np.min(lat)), float(np.max(lat))
    west, east = float(np.min(lon)), float(np.max(lon))
    corners = [(south, west), (north, west), (north, east), (south, east), (south, west)]
    return "POLYGON ((" + ", ".join(f"{a:.7f} {b:.7f}" for a, b in corners) + "))"
