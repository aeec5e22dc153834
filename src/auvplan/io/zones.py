"""Polygons of GIS files (no-go zones, operating areas) in the mission's local frame.

GeoJSON (RFC 7946: longitude, latitude on WGS 84, EPSG:4326; a legacy ``crs`` member is
honoured) is read with :mod:`json` and :func:`shapely.geometry.shape`. Shapefiles,
GeoPackages, KML and every other vector format GDAL reads go through pyogrio (the optional
extra ``auvplan[gis]``), in the CRS the file declares. Every polygon and every part of a
multipolygon becomes one :class:`Zone`, its holes kept; other geometries (points, lines) are
skipped. The coordinates are reprojected with pyproj from the file's CRS to the local
transverse-Mercator frame (:class:`~auvplan.terrain.projection.LocalProjection`): ``x = east``,
``y = north`` [m].

Every problem is one line naming the file and, for a geometry, the feature's index (0-based,
in file order) and its id: a missing extra, an unreadable file, no CRS, no polygon, a
non-finite coordinate, or an invalid polygon (:func:`shapely.validation.explain_validity`,
e.g. ``Self-intersection[5 5]``, ``Hole lies outside shell``).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final

import numpy as np
from pyproj import CRS, Transformer
from pyproj.exceptions import CRSError

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.io.text import read_json
from auvplan.terrain.projection import GEOGRAPHIC_CRS, LocalProjection

#: File suffixes read as GeoJSON with the standard library (others go through pyogrio).
GEOJSON_SUFFIXES: Final = (".geojson", ".json")
#: The optional extra that installs pyogrio.
GIS_EXTRA: Final = "pip install 'auvplan[gis]'"


@dataclass(frozen=True)
class Zone:
    """One polygon of a GIS file in the local frame.

    ``label`` is ``"feature K"`` (``K`` its 0-based index in the file) or ``"feature K.P"``
    for part ``P`` of a multipolygon; ``exterior`` ``(n, 2)`` and each of ``holes``
    ``(n_k, 2)`` hold ``north, east`` [m] of a ring's vertices (closing vertex dropped).
    """

    label: str
    exterior: FloatArray
    holes: tuple[FloatArray, ...]


def read_zones(
    path: Path, projection: LocalProjection | None, *, layer: str | None = None
) -> tuple[Zone, ...]:
    """Every polygon of a GIS file, reprojected to the local frame of ``projection``.

    Parameters
    ----------
    path : Path
        GeoJSON (``.geojson``, ``.json``), or any vector file GDAL reads (Shapefile ``.shp``,
        GeoPackage ``.gpkg``, KML ``.kml``) with the ``gis`` extra.
    projection : LocalProjection or None
        The mission's local frame (None: terrain without geographic reference, refused).
    layer : str, optional
        The layer of a multi-layer file (default: the first).

    Returns
    -------
    tuple of Zone
        In file order, at least one.

    Raises
    ------
    DataFormatError
        The file cannot be read, has no CRS or no polygon, or a polygon is invalid (one line
        naming the file, the feature and the problem).
    InputError
        The terrain has no geographic reference, pyogrio is missing, or a GeoJSON is given a
        ``layer``.
    """
    name = path.name
    if path.suffix.lower() in GEOJSON_SUFFIXES:
        if layer is not None:
            raise InputError(f"{name}: a GeoJSON file has no layers; remove layer = {layer!r}")
        crs, features = _geojson_features(path)
    else:
        crs, features = _ogr_features(path, layer)
    if projection is None:
        raise InputError(
            f"{name}: zones in a GIS file need terrain with a geographic reference (a grid "
            "with a CRS); give polygon = [[north, east], ...] on this terrain"
        )
    transformer = Transformer.from_crs(crs, projection.crs, always_xy=True)
    zones: list[Zone] = []
    for index, ident, geometry in features:
        named = ident is not None and ident != index
        where = f"{name}: feature {index}" + (f" (id {ident!r})" if named else "")
        zones += _zones(geometry, transformer, index, where)
    if not zones:
        raise DataFormatError(f"{name}: no polygon or multipolygon feature found")
    return tuple(zones)


Feature = tuple[int, Any, Any]  # index, id (or None), shapely geometry (or None)


def _geojson_features(path: Path) -> tuple[CRS, list[Feature]]:
    """The CRS and features of a GeoJSON document (a collection, a feature or a geometry)."""
    from shapely.geometry import shape

    document = read_json(path, what="zones file")
    if not isinstance(document, dict):
        raise DataFormatError(f"{path.name}: not a GeoJSON object")
    crs = _geojson_crs(document, path.name)
    if document.get("type") == "FeatureCollection":
        items = document.get("features")
        if not isinstance(items, list):
            raise DataFormatError(f"{path.name}: a FeatureCollection without a features list")
    elif document.get("type") == "Feature":
        items = [document]
    else:
        items = [{"type": "Feature", "geometry": document}]
    features: list[Feature] = []
    for index, item in enumerate(items):
        if not isinstance(item, dict) or item.get("type") != "Feature":
            raise DataFormatError(f"{path.name}: feature {index} is not a GeoJSON Feature")
        ident = item.get("id")
        geometry = item.get("geometry")
        try:
            with warnings.catch_warnings():  # NaN coordinates: refused below, in one line
                warnings.simplefilter("ignore", RuntimeWarning)
                features.append((index, ident, None if geometry is None else shape(geometry)))
        except Exception as error:  # noqa: BLE001  (shapely raises several types on bad input)
            raise DataFormatError(
                f"{path.name}: feature {index}: not a GeoJSON geometry ({error})"
            ) from None
    return crs, features


def _geojson_crs(document: dict[str, Any], name: str) -> CRS:
    """EPSG:4326 (RFC 7946), or the CRS a legacy ``crs`` member names."""
    member = document.get("crs")
    if member is None:
        return CRS(GEOGRAPHIC_CRS)
    try:
        crs = CRS.from_user_input(member["properties"]["name"])
    except (CRSError, KeyError, TypeError) as error:
        raise DataFormatError(f"{name}: unreadable crs member ({error})") from None
    # OGC CRS84 and EPSG:4326 are both read longitude first (always_xy)
    return crs


def _ogr_features(path: Path, layer: str | None) -> tuple[CRS, list[Feature]]:
    """The CRS and features of a vector file read by pyogrio (GDAL/OGR)."""
    try:
        import pyogrio
    except ImportError:
        raise InputError(
            f"{path.name}: reading {path.suffix or 'this'} files needs pyogrio: {GIS_EXTRA} "
            "(or use GeoJSON)"
        ) from None
    import shapely

    if not path.exists():
        raise DataFormatError(f"zones file {path}: file not found")
    try:
        meta, fids, wkb, _ = pyogrio.raw.read(
            path, layer=0 if layer is None else layer, return_fids=True
        )
    except Exception as error:  # noqa: BLE001  (pyogrio's errors: DataSourceError, DataLayerError, ...)
        message = str(error).splitlines()[0] if str(error) else type(error).__name__
        raise DataFormatError(f"{path.name}: cannot read ({message})") from None
    if not meta.get("crs"):
        raise DataFormatError(
            f"{path.name}: the file declares no CRS (a shapefile needs its .prj); write it with one"
        )
    try:
        crs = CRS.from_user_input(meta["crs"])
    except CRSError as error:
        raise DataFormatError(f"{path.name}: unreadable CRS ({error})") from None
    geometries = shapely.from_wkb(wkb)
    ids = [None] * len(geometries) if fids is None else [int(fid) for fid in fids]
    return crs, list(zip(range(len(geometries)), ids, geometries, strict=True))


def _zones(geometry: Any, transformer: Transformer, index: int, where: str) -> list[Zone]:
    """The polygons of one feature's geometry, checked and in the local frame."""
    from shapely.geometry import MultiPolygon, Polygon

    if isinstance(geometry, Polygon):
        return [_zone(f"feature {index}", geometry, transformer, where)]
    if isinstance(geometry, MultiPolygon):
        return [
            _zone(f"feature {index}.{k}", part, transformer, f"{where} part {k}")
            for k, part in enumerate(geometry.geoms)
        ]
    return []  # points, lines, empty or missing geometries are no zones


def _zone(label: str, polygon: Any, transformer: Transformer, where: str) -> Zone:
    """One shapely polygon as a :class:`Zone`, refused when invalid (``where`` names it)."""
    from shapely.validation import explain_validity

    if polygon.is_empty:
        raise DataFormatError(f"{where}: invalid polygon (empty)")
    rings = [polygon.exterior, *polygon.interiors]
    coordinates = [np.asarray(ring.coords, dtype=np.float64)[:-1, :2] for ring in rings]
    if not all(np.all(np.isfinite(c)) for c in coordinates):
        raise DataFormatError(f"{where}: a coordinate is not finite")
    if not polygon.is_valid or polygon.area <= 0.0:
        problem = explain_validity(polygon) if not polygon.is_valid else "zero area"
        raise DataFormatError(f"{where}: invalid polygon ({problem})")
    local = [_to_local(transformer, c, where) for c in coordinates]
    return Zone(label, local[0], tuple(local[1:]))


def _to_local(transformer: Transformer, ring: FloatArray, where: str) -> FloatArray:
    """A ring ``(n, 2)`` of ``x, y`` in the file's CRS as ``north, east`` [m]."""
    east, north = transformer.transform(ring[:, 0], ring[:, 1])
    local = np.column_stack((north, east)).astype(np.float64)
    if not np.all(np.isfinite(local)):
        raise DataFormatError(f"{where}: coordinates outside the file's CRS (not projectable)")
    return local


__all__ = ["GEOJSON_SUFFIXES", "GIS_EXTRA", "Zone", "read_zones"]
