"""The mission's no-go zones and operating area in the map frame.

``[[obstacle]]`` tables give circles, polygons (``[north, east]`` [m] or ``{ lat, lon }``
[deg] vertices) or GIS files of polygons (:func:`auvplan.io.zones.read_zones`: GeoJSON, and
with the ``gis`` extra Shapefile, GeoPackage, KML, reprojected from any CRS); ``[area]``
gives the operating area as a polygon or a file of one polygon. Every planner sees them as
obstacles (:mod:`auvplan.planning.obstacles`): the area as an
:class:`~auvplan.planning.OperatingArea`, whose no-go region is its outside and whose
distance from a point inside is the distance to its boundary, so that pre-planning blocks
cells outside it or within ``r_c`` of its boundary, the replay check keeps every sample
``>= r_c`` inside it, and the optimiser tracks the routes that do, as it does for every polygon.
"""

from __future__ import annotations

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError, InputError
from auvplan.io.zones import Zone, read_zones
from auvplan.mission.config import AREA_NAME, AreaConfig, MissionConfig
from auvplan.mission.tables import Position, Vertex, check_simple_polygon, polygon_frame
from auvplan.planning import CircleObstacle, Obstacle, OperatingArea, PolygonObstacle
from auvplan.terrain import BathymetryGrid


def resolve_position(position: Position, grid: BathymetryGrid, what: str) -> tuple[float, float]:
    """``north, east`` [m] of a local or geographic position on ``grid``."""
    first, second = position.coordinates
    if not position.is_geographic:
        return first, second
    if grid.projection is None:
        raise InputError(f"{what} is given in lat/lon but the terrain has no geographic reference")
    north, east = grid.projection.to_local(np.array([first]), np.array([second]))
    return float(north[0]), float(east[0])


def resolve_vertices(vertices: tuple[Vertex, ...], grid: BathymetryGrid, what: str) -> FloatArray:
    """``(n, 2)`` ``north, east`` [m] of a polygon's vertices, checked to bound a simple polygon.

    Raises InputError naming ``what`` when lat/lon vertices meet terrain without a geographic
    reference, or bound no simple polygon in the map frame.
    """
    geographic, pairs = polygon_frame(vertices)
    if not geographic:
        return np.array(pairs, dtype=np.float64)
    if grid.projection is None:
        raise InputError(f"{what} is given in lat/lon but the terrain has no geographic reference")
    lat, lon = np.array(pairs, dtype=np.float64).T
    north, east = grid.projection.to_local(lat, lon)
    local = np.column_stack((north, east))
    try:
        check_simple_polygon(tuple(map(tuple, local)))
    except ValueError as error:
        raise InputError(f"{what}: {error}") from None
    return local


def resolve_obstacles(
    config: MissionConfig, grid: BathymetryGrid
) -> tuple[tuple[Obstacle, ...], tuple[str, ...]]:
    """The mission's obstacles in the map frame, then its operating area; and their labels.

    Raises
    ------
    InputError
        Lat/lon on terrain without a geographic reference; labels of file zones that repeat
        a vehicle's or another obstacle's name.
    DataFormatError
        A GIS file that cannot be read or holds an invalid polygon (:func:`read_zones`).
    """
    obstacles: list[Obstacle] = []
    labels: list[str] = []
    for obstacle, name in zip(config.obstacles, config.obstacle_names, strict=True):
        if obstacle.file is not None:
            for zone in read_zones(obstacle.file, grid.projection, layer=obstacle.layer):
                obstacles.append(_polygon(zone))
                labels.append(f"{name} {zone.label}")
        elif obstacle.polygon is not None:
            obstacles.append(PolygonObstacle(resolve_vertices(obstacle.polygon, grid, name)))
            labels.append(name)
        else:
            north, east = resolve_position(obstacle.circle[0], grid, f"{name} center")
            obstacles.append(CircleObstacle(north, east, obstacle.circle[1]))
            labels.append(name)
    if config.area is not None:
        obstacles.append(OperatingArea(resolve_area(config.area, grid)))
        labels.append(AREA_NAME)
    names = [vehicle.name for vehicle in config.vehicles] + labels
    repeated = sorted({label for label in names if names.count(label) > 1})
    if repeated:
        raise InputError(f"vehicle and obstacle names must be unique: {', '.join(repeated)}")
    return tuple(obstacles), tuple(labels)


def resolve_area(area: AreaConfig, grid: BathymetryGrid) -> PolygonObstacle:
    """The operating area's polygon in the map frame (a file must hold exactly one)."""
    if area.polygon is not None:
        return PolygonObstacle(resolve_vertices(area.polygon, grid, AREA_NAME))
    assert area.file is not None  # one of them: AreaConfig's validator
    zones = read_zones(area.file, grid.projection, layer=area.layer)
    if len(zones) != 1:
        raise DataFormatError(
            f"{area.file.name}: an operating area is one polygon, the file holds {len(zones)} "
            f"({', '.join(zone.label for zone in zones[:5])}{', ...' if len(zones) > 5 else ''})"
        )
    return _polygon(zones[0])


def _polygon(zone: Zone) -> PolygonObstacle:
    return PolygonObstacle(zone.exterior, holes=zone.holes)


__all__ = ["resolve_area", "resolve_obstacles", "resolve_position", "resolve_vertices"]
