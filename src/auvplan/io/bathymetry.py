"""Reading bathymetric grids: NetCDF, GeoTIFF, ESRI ASCII grid and XYZ point clouds.

:func:`read_bathymetry` detects the format from the file's content, reads it with the field's
libraries (xarray/netCDF4, rasterio, numpy + scipy), and returns a
:class:`~auvplan.terrain.grid.BathymetryGrid` in the local north/east frame with depth in
metres, positive down, and NaN on land / no-data cells. Data in a geographic (lon/lat) or
projected (e.g. UTM) CRS (from GeoTIFF, or a CF ``grid_mapping`` in NetCDF) are resampled
onto a metric grid in the local frame, a transverse Mercator centred on the map
(:func:`~auvplan.terrain.resample.project_grid`); a grid already in such a frame (auvplan's
own ``maps.nc``) and metric grids without a CRS keep their nodes.
"""

from __future__ import annotations

import logging
from dataclasses import replace
from pathlib import Path
from typing import Final, Literal

import numpy as np
from pyproj import Transformer

from auvplan._typing import FloatArray
from auvplan.errors import AuvplanError, DataFormatError, InputError
from auvplan.io._gridded import read_netcdf, read_rasterio
from auvplan.io._raster import Raster, check_geographic_range, first_line
from auvplan.io._xyz import XyzCoordinates, read_xyz
from auvplan.terrain.grid import BathymetryGrid, GridGeometry
from auvplan.terrain.projection import GEOGRAPHIC_CRS, LocalProjection
from auvplan.terrain.resample import grid_scattered_points, project_grid

logger = logging.getLogger(__name__)

Vertical = Literal["auto", "elevation", "depth"]
BathymetryFormat = Literal["netcdf", "geotiff", "ascii", "xyz"]

#: Largest physical elevation or depth magnitude [m] (Challenger Deep 10,935 m, Everest 8,849 m);
#: values beyond it (fill values such as -32767 or -1e308 without a ``_FillValue``) are no data.
MAX_ABS_ELEVATION: Final = 12_000.0


def read_bathymetry(
    path: str | Path,
    *,
    window_north: tuple[float, float] | None = None,
    window_east: tuple[float, float] | None = None,
    window_lat: tuple[float, float] | None = None,
    window_lon: tuple[float, float] | None = None,
    min_depth: float = 0.0,
    vertical: Vertical = "auto",
    xyz_coordinates: XyzCoordinates = "auto",
) -> BathymetryGrid:
    """Read a bathymetric grid into the local north/east frame.

    Parameters
    ----------
    path : str or Path
        NetCDF-3/4 (``lon``/``lat``/``elevation`` as NOAA, GEBCO, EMODnet, with dimensions
        ``lat/lon`` or ``y/x``; or a metric file with ``north``/``east`` coordinates [m] and a
        ``depth`` variable such as auvplan's own ``maps.nc``; a CF ``grid_mapping`` gives the
        CRS, geographic or projected), GeoTIFF (geographic or projected CRS), ESRI ASCII grid,
        or XYZ text (columns ``lon lat z`` or ``east north z``, whitespace or comma separated,
        ``#`` comments). The format is detected from the content, not the suffix.
    window_north, window_east : tuple of float, optional
        Crop ``(low, high)`` [m] in the frame of the grid as read (after any lat/lon window);
        the result is re-originated at its south-west node.
    window_lat, window_lon : tuple of float, optional
        Crop ``(south, north)`` / ``(west, east)`` [deg, WGS 84], applied before the
        resampling: to geographic data directly, to projected data via the window's bounding
        box in their CRS (:meth:`pyproj.Transformer.transform_bounds`). A missing one keeps
        the data's whole extent.
    min_depth : float
        Cells with depth <= ``min_depth`` [m] (land, the surface) become NaN (no-go).
    vertical : {"auto", "elevation", "depth"}
        Sign of the values. ``"auto"``: a variable named ``depth`` or with ``positive="down"``
        is depth; otherwise values are elevation (positive up) unless no finite value is
        negative, in which case they are taken as depth (positive down).
    xyz_coordinates : {"auto", "geographic", "metric"}
        Meaning of the first two XYZ columns. ``"auto"``: ``lon lat`` when all values fit the
        lon/lat ranges and the median point spacing is below 0.05, else ``east north`` [m].

    Returns
    -------
    BathymetryGrid
        Depth [m], positive down, NaN = no-go, origin at the south-west node. ``projection``
        (whose ``crs`` is the local frame as a :class:`pyproj.CRS`) is set for every source
        with a CRS, so lat/lon poses convert; ``attributes`` records the source file, format
        and CRS (``attributes["crs"]``, the source CRS as a string pyproj reads back).

    Raises
    ------
    DataFormatError
        If the file is missing, of unknown format, lacks the needed variables, has irregular
        coordinates or latitudes/longitudes off the Earth, has no valid value or no water cell
        left, or its soundings are degenerate (collinear) or would need an absurdly large grid
        (:data:`~auvplan.terrain.resample.MAX_GRID_NODES`).
    InputError
        If a window is empty or outside the map, or a lat/lon window is given for a grid
        without a CRS.

    Notes
    -----
    XYZ point clouds that form a regular lattice (possibly with holes) are read as that grid
    exactly; other clouds are gridded with
    :func:`~auvplan.terrain.resample.grid_scattered_points`. A few stray position fixes far
    outside an XYZ survey are dropped (:func:`auvplan.io._xyz.drop_stray_fixes`), and values
    beyond ±12,000 m (:data:`MAX_ABS_ELEVATION`) are no data; both are logged as warnings with
    their count.
    """
    path = Path(path)
    try:
        grid = _read(path, window_lat, window_lon, min_depth, vertical, xyz_coordinates)
        if window_north is not None or window_east is not None:
            grid = grid.window(north=window_north, east=window_east)
    except AuvplanError as error:
        raise type(error)(f"bathymetry {path}: {error}") from error
    if not np.isfinite(grid.depth).any():
        raise DataFormatError(
            f"bathymetry {path}: no water cell (depth > {min_depth:g} m) in the selected area"
        )
    return grid


def _read(
    path: Path,
    window_lat: tuple[float, float] | None,
    window_lon: tuple[float, float] | None,
    min_depth: float,
    vertical: Vertical,
    xyz_coordinates: XyzCoordinates,
) -> BathymetryGrid:
    if not path.exists():
        raise DataFormatError("file not found")
    if not path.is_file():
        raise DataFormatError("not a regular file")
    kind = detect_format(path)
    try:
        if kind == "netcdf":
            raster = read_netcdf(path)
        elif kind in ("geotiff", "ascii"):
            raster = read_rasterio(path)
        else:
            raster = read_xyz(path, xyz_coordinates)
    except (ValueError, KeyError, TypeError, IndexError, RuntimeError) as error:
        # Anything the libraries raise on a malformed file that the readers did not foresee.
        if isinstance(error, AuvplanError):
            raise
        raise DataFormatError(f"malformed {kind} file ({first_line(error)})") from None
    attributes = {"source_file": str(path), "format": kind, **raster.attributes}
    if raster.crs is not None:
        attributes["crs"] = raster.crs.to_string()
    raster = replace(raster, attributes=attributes)
    if raster.is_geographic:
        check_geographic_range(raster.axis_north, raster.axis_east)
    raster = _crop_geographic(raster, window_lat, window_lon)
    depth = _to_depth(raster, vertical, min_depth)
    try:
        if raster.attributes.get("scattered") == "yes":
            return _scattered(raster, depth, path.name)
        local = None if raster.crs is None else LocalProjection.from_crs(raster.crs)
        if raster.crs is not None and local is None:
            return project_grid(
                depth,
                raster.axis_north,
                raster.axis_east,
                raster.crs,
                name=path.name,
                attributes=raster.attributes,
            )
        return _metric_grid(depth, raster, local, path.name)
    except InputError as error:  # the file's geometry, not a user's value, is at fault
        raise DataFormatError(str(error)) from None


def detect_format(path: Path) -> BathymetryFormat:
    """The bathymetry format of ``path`` from its first bytes (magic numbers, text layout).

    Raises
    ------
    DataFormatError
        If the content matches none of the supported formats.
    """
    with path.open("rb") as stream:
        head = stream.read(4096)
    if not head:
        raise DataFormatError("empty file")
    if head.startswith((b"CDF\x01", b"CDF\x02", b"CDF\x05", b"\x89HDF\r\n\x1a\n")):
        return "netcdf"
    if head.startswith((b"II*\x00", b"MM\x00*", b"II+\x00", b"MM\x00+")):
        return "geotiff"
    try:
        text = head.decode("ascii")
    except UnicodeDecodeError:
        raise DataFormatError("unrecognised format (not NetCDF, GeoTIFF or text)") from None
    words = text.split()
    if words and words[0].lower() in ("ncols", "nrows", "xllcorner", "xllcenter"):
        return "ascii"
    for line in text.splitlines():
        stripped = line.split("#", 1)[0].replace(",", " ").split()
        if not stripped:
            continue
        try:
            [float(w) for w in stripped]
        except ValueError:
            continue  # a header line
        if len(stripped) >= 3:
            return "xyz"
        break
    raise DataFormatError("unrecognised format (text without 3 numeric columns)")


# --- Common conversion ---------------------------------------------------------------------


def _crop_geographic(
    raster: Raster, window_lat: tuple[float, float] | None, window_lon: tuple[float, float] | None
) -> Raster:
    """Apply a lat/lon window to the raster, in its native coordinates (via its CRS)."""
    if window_lat is None and window_lon is None:
        return raster
    if raster.crs is None:
        raise InputError("a lat/lon window needs a grid with a geographic or projected CRS")
    to_native = Transformer.from_crs(GEOGRAPHIC_CRS, raster.crs, always_xy=True)
    west, south, east, north = to_native.transform_bounds(
        *_window_lon_lat(raster, to_native, window_lat, window_lon), densify_pts=21
    )
    north_range = (south, north) if window_lat is not None else None
    east_range = (west, east) if window_lon is not None else None
    if raster.attributes.get("scattered") == "yes":
        keep = np.ones(raster.axis_north.size, dtype=bool)
        for axis, bounds in ((raster.axis_north, north_range), (raster.axis_east, east_range)):
            if bounds is not None:
                keep &= (axis >= min(bounds)) & (axis <= max(bounds))
        if keep.sum() < 3:
            raise InputError(
                f"window lat {window_lat} / lon {window_lon} keeps fewer than 3 points"
            )
        return replace(
            raster,
            values=raster.values[:, keep],
            axis_north=raster.axis_north[keep],
            axis_east=raster.axis_east[keep],
        )
    rows = _range(raster.axis_north, north_range, "lat" if raster.is_geographic else "north")
    cols = _range(raster.axis_east, east_range, "lon" if raster.is_geographic else "east")
    return replace(
        raster,
        values=raster.values[rows, cols],
        axis_north=raster.axis_north[rows],
        axis_east=raster.axis_east[cols],
    )


def _window_lon_lat(
    raster: Raster,
    to_native: Transformer,
    window_lat: tuple[float, float] | None,
    window_lon: tuple[float, float] | None,
) -> tuple[float, float, float, float]:
    """``(west, south, east, north)`` [deg] of the window; a missing side is the data's own."""
    west, south, east, north = to_native.transform_bounds(
        float(np.min(raster.axis_east)),
        float(np.min(raster.axis_north)),
        float(np.max(raster.axis_east)),
        float(np.max(raster.axis_north)),
        direction="INVERSE",
        densify_pts=21,
    )
    if window_lat is not None:
        south, north = float(min(window_lat)), float(max(window_lat))
    if window_lon is not None:
        west, east = float(min(window_lon)), float(max(window_lon))
    return west, south, east, north


def _range(axis: FloatArray, bounds: tuple[float, float] | None, name: str) -> slice:
    if bounds is None:
        return slice(0, axis.size)
    low, high = float(min(bounds)), float(max(bounds))
    inside = np.flatnonzero((axis >= low) & (axis <= high))
    if inside.size < 2:
        raise InputError(
            f"window {name} = [{low:g}, {high:g}] keeps fewer than 2 nodes of the grid "
            f"({axis[0]:g} … {axis[-1]:g})"
        )
    return slice(int(inside[0]), int(inside[-1]) + 1)


def _to_depth(raster: Raster, vertical: Vertical, min_depth: float) -> FloatArray:
    """Depth [m], positive down, NaN for no data, for depth <= ``min_depth`` and beyond ±12 km.

    Values whose magnitude exceeds :data:`MAX_ABS_ELEVATION` are no data (logged with their
    count); a raster without any valid value is a DataFormatError.
    """
    values = raster.values
    with np.errstate(invalid="ignore"):
        is_valid = np.abs(values) <= MAX_ABS_ELEVATION  # False for NaN and ±inf
    n_absurd = int(np.count_nonzero(np.isfinite(values) & ~is_valid))
    if not is_valid.any():
        raise DataFormatError(
            f"no valid value: all {values.size} values are no data or beyond "
            f"±{MAX_ABS_ELEVATION:g} m"
        )
    if n_absurd:
        logger.warning(
            "bathymetry %s: %d of %d values beyond ±%g m treated as no data",
            raster.attributes.get("source_file", "?"),
            n_absurd,
            values.size,
            MAX_ABS_ELEVATION,
        )
    values = np.where(is_valid, values, np.nan)
    if vertical == "depth":
        is_depth = True
    elif vertical == "elevation":
        is_depth = False
    elif raster.is_depth is not None:
        is_depth = raster.is_depth
    else:
        finite = values[np.isfinite(values)]
        is_depth = finite.size > 0 and bool(np.all(finite >= 0.0))
    depth = values if is_depth else -values
    with np.errstate(invalid="ignore"):
        depth = np.where(depth > min_depth, depth, np.nan)
    return np.asarray(depth, dtype=np.float64)


def _metric_grid(
    depth: FloatArray, raster: Raster, local: LocalProjection | None, name: str
) -> BathymetryGrid:
    """The raster's own regular lattice; ``local`` is its frame (None: no georeference)."""
    spacings = []
    for axis, label in ((raster.axis_north, "north"), (raster.axis_east, "east")):
        if axis.size < 2:
            raise DataFormatError(f"fewer than 2 nodes along {label}")
        steps = np.diff(axis)
        step = float(steps.mean())
        if np.max(np.abs(steps - step)) > 1e-3 * step:
            raise DataFormatError(
                f"irregular {label} coordinates (steps {steps.min():g} … {steps.max():g})"
            )
        spacings.append(step)
    geometry = GridGeometry(depth.shape[0], depth.shape[1], spacings[0], spacings[1])
    projection = (
        None
        if local is None
        else local.shifted(float(raster.axis_north[0]), float(raster.axis_east[0]))
    )
    return BathymetryGrid(depth, geometry, projection, None, name, dict(raster.attributes))


def _scattered(raster: Raster, depth: FloatArray, name: str) -> BathymetryGrid:
    """Grid scattered soundings; lon/lat ones in the local frame centred on the survey."""
    attributes = {k: v for k, v in raster.attributes.items() if k != "scattered"}
    north, east = raster.axis_north, raster.axis_east
    projection = None
    if raster.is_geographic:
        projection = LocalProjection(
            float(0.5 * (north.min() + north.max())), float(0.5 * (east.min() + east.max()))
        )
        north, east = projection.to_local(north, east)
    return grid_scattered_points(
        north, east, depth[0], projection=projection, name=name, attributes=attributes
    )
