r"""Skirting discs: detour a path around circles it must not enter, along their rims.

A vehicle parked at its goal can be passed by no schedule closer than ``2 r_c``, so each
other vehicle's path must stay outside that disc. On a cost grid coarser than ``2 r_c`` the
route's cells cannot express such a disc (A* would have to block the whole cell, often the
vehicle's own goal with it). :func:`skirt_discs` repairs the smoothed path instead.

The discs (each a polygon circumscribing its circle, so that its edges stay outside) are
merged into their union (shapely); discs of a rendezvous overlap. Where the path first
enters a component :math:`P` of the union and where it last leaves it, at arc lengths
:math:`s_\text{in} < s_\text{out}`, the part between is replaced by the shorter way round
the boundary of :math:`P` between the two points, or the longer way if the shorter one is
blocked. The boundary of one component never enters another, so one pass per component
clears the path.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Final

import numpy as np
from shapely import LineString, Point, Polygon
from shapely.ops import substring, unary_union

from auvplan._typing import BoolArray, FloatArray

__all__ = ["skirt_discs"]

#: Polygon vertices per quarter circle (edges of ``π/32`` rad: a 24 m disc has 2.4 m edges).
_QUAD_SEGS: Final = 16
#: Radius of the circumscribing polygon's vertices per disc radius.
_CIRCUMSCRIBE: Final = 1.0 / math.cos(math.pi / (4 * _QUAD_SEGS))


def skirt_discs(
    path: FloatArray,
    centres: FloatArray,
    radii: FloatArray,
    *,
    is_blocked: Callable[[FloatArray, FloatArray], BoolArray] | None = None,
) -> FloatArray:
    """``path`` detoured round the union of the discs along its boundary (module notes).

    Parameters
    ----------
    path : ndarray of shape (n, 2)
        ``[north, east]`` [m]; its two ends lie outside every disc (a path that starts or
        ends inside one is returned unchanged).
    centres : ndarray of shape (k, 2)
        Disc centres ``[north, east]`` [m].
    radii : ndarray of shape (k,)
        Disc radii [m], ``> 0``.
    is_blocked : callable or None
        ``is_blocked(north, east) -> bool array``; a detour through a blocked point is not
        taken (the other way round is tried, else that crossing is left as it was).

    Returns
    -------
    ndarray of shape (m, 2)
        The repaired path; ``path`` itself (the same object) when it enters no disc.

    Examples
    --------
    >>> line = np.array([[0.0, -10.0], [0.0, 10.0]])
    >>> out = skirt_discs(line, np.array([[1.0, 0.0]]), np.array([3.0]))
    >>> bool(np.all(np.hypot(out[:, 0] - 1.0, out[:, 1]) >= 3.0))
    True
    >>> float(out[:, 0].min()) < -1.9  # the shorter way: south, the side the line passes
    True
    """
    if len(centres) == 0:
        return path
    union = unary_union(
        [Point(float(c[0]), float(c[1])).buffer(float(r) * _CIRCUMSCRIBE, quad_segs=_QUAD_SEGS)
         for c, r in zip(centres, radii, strict=True)]
    )  # fmt: skip
    parts = union.geoms if hasattr(union, "geoms") else [union]  # discs too small vanish
    components = [part for part in parts if isinstance(part, Polygon) and not part.is_empty]
    if any(component.contains(Point(*end)) for component in components for end in path[[0, -1]]):
        return path
    out = path
    tried: set[int] = set()
    while True:
        line = LineString(out)
        crossings = [
            (_span(line, component), k)
            for k, component in enumerate(components)
            if k not in tried and line.intersects(component.exterior)
        ]
        if not crossings:
            return out
        (s_in, s_out), k = min(crossings)
        tried.add(k)
        detour = _round_boundary(line, components[k], s_in, s_out, is_blocked)
        if detour is not None:
            out = _splice(out, s_in, s_out, detour)


def _span(line: LineString, component: Polygon) -> tuple[float, float]:
    """Arc lengths [m] along ``line`` where it first enters and last leaves ``component``."""
    crossings = line.intersection(component.exterior)
    points = getattr(crossings, "geoms", [crossings])
    stations = [line.project(Point(xy)) for point in points for xy in point.coords]
    return min(stations), max(stations)


def _round_boundary(
    line: LineString,
    component: Polygon,
    s_in: float,
    s_out: float,
    is_blocked: Callable[[FloatArray, FloatArray], BoolArray] | None,
) -> FloatArray | None:
    """The boundary of ``component`` from the entry point to the exit point, or ``None``.

    Both ways round are walked on the ring laid out twice (so no walk wraps); the shorter
    is returned unless it passes a blocked point, then the longer one.
    """
    ring = LineString(component.exterior.coords)
    twice = LineString(np.concatenate([ring.coords, ring.coords[1:]]))
    length = ring.length
    a = ring.project(line.interpolate(s_in))
    b = ring.project(line.interpolate(s_out))
    forward = substring(twice, a, b if b >= a else b + length)
    backward = substring(twice, a + length, b + length if b <= a else b)
    for way in sorted((forward, backward), key=lambda walk: walk.length):
        points = np.asarray(way.coords)
        if is_blocked is None or not np.any(is_blocked(points[:, 0], points[:, 1])):
            return points
    return None


def _splice(path: FloatArray, s_in: float, s_out: float, detour: FloatArray) -> FloatArray:
    """``path`` with its part between arc lengths ``s_in`` and ``s_out`` [m] replaced."""
    station = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))))
    return np.concatenate((path[station < s_in], detour, path[station > s_out]))
