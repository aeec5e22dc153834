"""Reading bathymetric grids: NetCDF, GeoTIFF, ESRI ASCII grid and XYZ point clouds.

:func:`read_bathymetry` detects the format from the file's content, reads it with the field's
libraries (xarray/netCDF4, rasterio, numpy + scipy), and returns a
:class:`~auvplan.terrain.grid.BathymetryGrid` in the local north/east frame with depth in
metres, positive down, and NaN on land / no-data cells. Geographic (lon/lat) data are
resampled onto a metric grid in a transverse Mercator frame centred on the map
(:func:`~auvplan.terrain.resample.project_geographic_grid`).
"""

from __future__ import annotations

import io
import warnings
from collections.abc import Callable, Hashable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Literal

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import AuvplanError, DataFormatError, InputError
from auvplan.terrain.grid import BathymetryGrid, GridGeometry
from auvplan.terrain.projection import LocalProjection
from auvplan.terrain.resample import grid_scattered_points, project_geographic_grid

if TYPE_CHECKING:
    import xarray as xr

Vertical = Literal["auto", "elevation", "depth"]
XyzCoordinates = Literal["auto", "geographic", "metric"]
BathymetryFormat = Literal["netcdf", "geotiff", "ascii", "xyz"]

#: A coordinate step below this many units is taken as degrees, not metres, when a file does
#: not say (no CRS / units): 0.05 deg is 5.5 km, and no metric survey has 5 cm spacing.
_GEOGRAPHIC_STEP_LIMIT = 0.05

_LAT_NAMES = ("lat", "latitude", "y")
_LON_NAMES = ("lon", "longitude", "x")
_DATA_NAMES = ("depth", "elevation", "z", "Band1", "topo", "height", "bathymetry", "altitude")


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
        ``depth`` variable such as auvplan's own ``maps.nc``), GeoTIFF (geographic or projected
        CRS), ESRI ASCII grid, or XYZ text (columns ``lon lat z`` or ``east north z``,
        whitespace or comma separated, ``#`` comments). The format is detected from the
        content, not the suffix.
    window_north, window_east : tuple of float, optional
        Crop ``(low, high)`` [m] in the frame of the grid as read (after any lat/lon window);
        the result is re-originated at its south-west node.
    window_lat, window_lon : tuple of float, optional
        Crop ``(south, north)`` / ``(west, east)`` [deg], applied to geographic data before
        projection (to metric data with a known projection via its bounding box).
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
        is set for geographic sources (and for metric files that record one) so lat/lon poses
        convert; ``attributes`` records the source file, format and CRS.

    Raises
    ------
    DataFormatError
        If the file is missing, of unknown format, lacks the needed variables, has irregular
        coordinates, or has no water cell left.
    InputError
        If a window is empty or outside the map, or a lat/lon window is given for a grid
        without a geographic reference.

    Notes
    -----
    XYZ point clouds that form a regular lattice (possibly with holes) are read as that grid
    exactly; other clouds are gridded with
    :func:`~auvplan.terrain.resample.grid_scattered_points`.
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


@dataclass(frozen=True)
class _Raster:
    """A raster as read, before conversion: rows along ``axis_north``, columns along east."""

    values: FloatArray
    axis_north: FloatArray  # lat [deg] or north [m], increasing
    axis_east: FloatArray  # lon [deg] or east [m], increasing
    is_geographic: bool
    is_depth: bool | None  # None: decide from the values
    projection: LocalProjection | None = None
    to_native: Callable[[FloatArray, FloatArray], tuple[FloatArray, FloatArray]] | None = None
    attributes: dict[str, str] = field(default_factory=dict)


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
            raster = _read_netcdf(path)
        elif kind in ("geotiff", "ascii"):
            raster = _read_rasterio(path)
        else:
            raster = _read_xyz(path, xyz_coordinates)
    except (ValueError, KeyError, TypeError, IndexError, RuntimeError) as error:
        # Anything the libraries raise on a malformed file that the readers did not foresee.
        if isinstance(error, AuvplanError):
            raise
        raise DataFormatError(f"malformed {kind} file ({_first_line(error)})") from None
    raster = replace(
        raster, attributes={"source_file": str(path), "format": kind, **raster.attributes}
    )
    raster = _crop_geographic(raster, window_lat, window_lon)
    depth = _to_depth(raster, vertical, min_depth)
    if raster.is_geographic and raster.attributes.get("scattered") == "yes":
        return _geographic_scattered(raster, depth, path.name)
    if raster.is_geographic:
        return project_geographic_grid(
            depth, raster.axis_north, raster.axis_east, name=path.name, attributes=raster.attributes
        )
    return _metric_grid(depth, raster, path.name)


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


# --- NetCDF --------------------------------------------------------------------------------


def _read_netcdf(path: Path) -> _Raster:
    import xarray as xr

    try:
        dataset = xr.open_dataset(path, decode_times=False, cache=False)
    except (OSError, ValueError, RuntimeError, TypeError, KeyError) as error:
        raise DataFormatError(f"unreadable NetCDF ({_first_line(error)})") from None
    with dataset:
        names = set(dataset.variables)
        if {"north", "east"} <= names:
            lat_name, lon_name, is_geographic = "north", "east", False
        else:
            lat_name = next((n for n in _LAT_NAMES if n in names), "")
            lon_name = next((n for n in _LON_NAMES if n in names), "")
            if not lat_name or not lon_name:
                raise DataFormatError(
                    "no lat/lon (or north/east) coordinate variables; "
                    f"has {sorted(map(str, names))}"
                )
            units = str(dataset[lon_name].attrs.get("units", "")).lower()
            is_geographic = "deg" in units or (
                units in ("", "1")
                and _looks_geographic(dataset[lat_name].values, dataset[lon_name].values)
            )
        lat_var, lon_var = dataset[lat_name], dataset[lon_name]
        if lat_var.ndim != 1 or lon_var.ndim != 1:
            raise DataFormatError(f"coordinates {lat_name}/{lon_name} must be 1-D")
        lat_dim, lon_dim = lat_var.dims[0], lon_var.dims[0]
        data_name = _pick_data_variable(dataset, lat_dim, lon_dim)
        data = dataset[data_name].squeeze(drop=True)
        if set(data.dims) != {lat_dim, lon_dim}:
            raise DataFormatError(
                f"variable {data_name} has dimensions {data.dims}, not ({lat_dim}, {lon_dim})"
            )
        values = np.asarray(data.transpose(lat_dim, lon_dim).values, dtype=np.float64)
        positive = str(data.attrs.get("positive", "")).lower()
        is_depth: bool | None = (
            True
            if data_name == "depth" or positive == "down"
            else False
            if data_name == "elevation" or positive == "up"
            else None
        )
        attributes = {"variable": str(data_name)}
        for key in ("title", "source", "license"):
            if key in dataset.attrs:
                attributes[key] = _first_line(dataset.attrs[key])
        projection = _projection_from_attributes(dict(dataset.attrs)) if not is_geographic else None
        north_axis = np.asarray(lat_var.values, dtype=np.float64)
        east_axis = np.asarray(lon_var.values, dtype=np.float64)
    values, north_axis, east_axis = _increasing(values, north_axis, east_axis)
    return _Raster(
        values,
        north_axis,
        east_axis,
        is_geographic,
        is_depth,
        projection,
        None if projection is None else projection.to_local,
        attributes,
    )


def _pick_data_variable(dataset: xr.Dataset, lat_dim: Hashable, lon_dim: Hashable) -> str:
    candidates = [
        str(name)
        for name, variable in dataset.data_vars.items()
        if {lat_dim, lon_dim} <= set(variable.dims)
        and variable.size == (dataset.sizes[lat_dim] * dataset.sizes[lon_dim])
    ]
    for name in _DATA_NAMES:
        if name in candidates:
            return name
    if len(candidates) == 1:
        return candidates[0]
    raise DataFormatError(
        f"cannot tell the elevation/depth variable on ({lat_dim}, {lon_dim}) among {candidates}"
    )


def _projection_from_attributes(attributes: dict[str, object]) -> LocalProjection | None:
    """The LocalProjection recorded by :func:`auvplan.io.maps_file.write_maps_netcdf`."""
    keys = (
        "projection_lat_0",
        "projection_lon_0",
        "projection_offset_north",
        "projection_offset_east",
    )
    if not all(key in attributes for key in keys):
        return None
    lat_0, lon_0, offset_north, offset_east = (float(attributes[k]) for k in keys)  # type: ignore[arg-type]
    ellipsoid = str(attributes.get("projection_ellipsoid", "WGS84"))
    return LocalProjection(lat_0, lon_0, offset_north, offset_east, ellipsoid)


# --- GeoTIFF and ESRI ASCII grid -----------------------------------------------------------


def _read_rasterio(path: Path) -> _Raster:
    import rasterio
    from rasterio.errors import NotGeoreferencedWarning, RasterioIOError

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NotGeoreferencedWarning)
            with rasterio.open(path) as source:
                band = source.read(1, masked=True)
                transform, crs = source.transform, source.crs
    except (RasterioIOError, ValueError, IndexError) as error:
        raise DataFormatError(f"unreadable raster ({_first_line(error)})") from None
    values = np.asarray(np.ma.filled(band.astype(np.float64), np.nan))
    if transform.b != 0.0 or transform.d != 0.0:
        raise DataFormatError("rotated rasters are not supported")
    n_rows, n_cols = values.shape
    east_axis = transform.c + transform.a * (np.arange(n_cols) + 0.5)
    north_axis = transform.f + transform.e * (np.arange(n_rows) + 0.5)
    values, north_axis, east_axis = _increasing(values, north_axis, east_axis)
    attributes: dict[str, str] = {}
    to_native = None
    if crs is not None:
        attributes["crs"] = crs.to_string()
        is_geographic = bool(crs.is_geographic)
        if not is_geographic:
            from pyproj import Transformer

            transformer = Transformer.from_crs("EPSG:4326", crs, always_xy=True)

            def to_native(lat: FloatArray, lon: FloatArray) -> tuple[FloatArray, FloatArray]:
                east, north = transformer.transform(lon, lat)
                return np.asarray(north), np.asarray(east)
    else:
        is_geographic = _looks_geographic(north_axis, east_axis)
    return _Raster(values, north_axis, east_axis, is_geographic, None, None, to_native, attributes)


# --- XYZ point clouds ----------------------------------------------------------------------


def _read_xyz(path: Path, coordinates: XyzCoordinates) -> _Raster:
    try:
        text = path.read_text(encoding="utf-8", errors="strict")
        lines = [line.split("#", 1)[0].replace(",", " ") for line in text.splitlines()]
        numeric = [line for line in lines if line.strip() and _is_numeric(line)]
        table = np.loadtxt(io.StringIO("\n".join(numeric)), ndmin=2, usecols=(0, 1, 2))
    except (UnicodeDecodeError, ValueError) as error:
        raise DataFormatError(f"unreadable XYZ text ({_first_line(error)})") from None
    if table.shape[0] < 4:
        raise DataFormatError(f"XYZ file has {table.shape[0]} points, need at least 4")
    first, second, z = table[:, 0], table[:, 1], table[:, 2]
    if coordinates == "auto":
        is_geographic = _looks_geographic(second, first)
    else:
        is_geographic = coordinates == "geographic"
    lattice = _as_lattice(first, second, z)
    if lattice is not None:
        values, east_axis, north_axis = lattice
        return _Raster(values, north_axis, east_axis, is_geographic, None)
    # Scattered points: keep them as a one-row "raster" of points, gridded after conversion.
    return _Raster(z[None, :], second, first, is_geographic, None, attributes={"scattered": "yes"})


def _is_numeric(line: str) -> bool:
    try:
        [float(word) for word in line.split()]
    except ValueError:
        return False
    return True


def _as_lattice(
    east: FloatArray, north: FloatArray, z: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray] | None:
    """``(values, east_axis, north_axis)`` if the points lie on a regular lattice, else None."""
    axes = []
    for coordinate in (east, north):
        unique = np.unique(coordinate)
        if unique.size < 2:
            return None
        steps = np.diff(unique)
        step = float(np.median(steps))
        if np.max(np.abs(steps - step)) > 0.05 * step:
            return None
        axes.append(unique[0] + step * np.arange(unique.size))
    east_axis, north_axis = axes
    if east_axis.size * north_axis.size > 4 * z.size:
        return None  # too sparse to be a gridded export
    col = np.rint((east - east_axis[0]) / (east_axis[1] - east_axis[0])).astype(np.int64)
    row = np.rint((north - north_axis[0]) / (north_axis[1] - north_axis[0])).astype(np.int64)
    values = np.full((north_axis.size, east_axis.size), np.nan)
    values[row, col] = z
    return values, east_axis, north_axis


# --- Common conversion ---------------------------------------------------------------------


def _looks_geographic(lat: FloatArray, lon: FloatArray) -> bool:
    lat, lon = np.asarray(lat, dtype=np.float64), np.asarray(lon, dtype=np.float64)
    if not (np.all(np.abs(lat) <= 90.0) and np.all(lon >= -180.0) and np.all(lon <= 360.0)):
        return False
    steps = [np.diff(np.unique(a)) for a in (lat, lon)]
    step = min((float(np.median(s)) for s in steps if s.size), default=np.inf)
    return step < _GEOGRAPHIC_STEP_LIMIT


def _increasing(
    values: FloatArray, north_axis: FloatArray, east_axis: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Flip rows/columns so both coordinate axes increase (row 0 = south, col 0 = west)."""
    if north_axis.size > 1 and north_axis[1] < north_axis[0]:
        values, north_axis = values[::-1], north_axis[::-1]
    if east_axis.size > 1 and east_axis[1] < east_axis[0]:
        values, east_axis = values[:, ::-1], east_axis[::-1]
    for axis, name in ((north_axis, "north/lat"), (east_axis, "east/lon")):
        if axis.size > 1 and not np.all(np.diff(axis) > 0.0):
            raise DataFormatError(f"{name} coordinates are not monotonic")
    return np.ascontiguousarray(values), north_axis.copy(), east_axis.copy()


def _crop_geographic(
    raster: _Raster, window_lat: tuple[float, float] | None, window_lon: tuple[float, float] | None
) -> _Raster:
    """Apply a lat/lon window to the raster (in its native coordinates)."""
    if window_lat is None and window_lon is None:
        return raster
    if raster.is_geographic:
        north_range, east_range = window_lat, window_lon
    elif raster.to_native is not None:
        lat = np.array(window_lat if window_lat is not None else (-89.0, 89.0), dtype=np.float64)
        lon = np.array(window_lon if window_lon is not None else (-180.0, 180.0), dtype=np.float64)
        corner_lat, corner_lon = np.meshgrid(lat, lon, indexing="ij")
        north, east = raster.to_native(corner_lat.ravel(), corner_lon.ravel())
        north_range = (float(north.min()), float(north.max())) if window_lat is not None else None
        east_range = (float(east.min()), float(east.max())) if window_lon is not None else None
    else:
        raise InputError("a lat/lon window needs a geographic grid or a known projection")
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


def _to_depth(raster: _Raster, vertical: Vertical, min_depth: float) -> FloatArray:
    """Depth [m], positive down, NaN for no data and for depth <= ``min_depth``."""
    values = np.where(np.isfinite(raster.values), raster.values, np.nan)
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


def _metric_grid(depth: FloatArray, raster: _Raster, name: str) -> BathymetryGrid:
    if raster.attributes.get("scattered") == "yes":
        return grid_scattered_points(
            raster.axis_north,
            raster.axis_east,
            depth[0],
            projection=raster.projection,
            name=name,
            attributes={k: v for k, v in raster.attributes.items() if k != "scattered"},
        )
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
        if raster.projection is None
        else raster.projection.shifted(float(raster.axis_north[0]), float(raster.axis_east[0]))
    )
    return BathymetryGrid(depth, geometry, projection, None, name, dict(raster.attributes))


def _geographic_scattered(raster: _Raster, depth: FloatArray, name: str) -> BathymetryGrid:
    lat, lon = raster.axis_north, raster.axis_east
    centre = LocalProjection(
        float(0.5 * (lat.min() + lat.max())), float(0.5 * (lon.min() + lon.max()))
    )
    north, east = centre.to_local(lat, lon)
    attributes = {k: v for k, v in raster.attributes.items() if k != "scattered"}
    return grid_scattered_points(
        north, east, depth[0], projection=centre, name=name, attributes=attributes
    )


def _first_line(value: object) -> str:
    lines = str(value).strip().splitlines()
    return lines[0] if lines else type(value).__name__
