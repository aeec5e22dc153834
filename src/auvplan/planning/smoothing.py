r"""Smoothing a staircase grid path into a C² curve, resampled at uniform arc length.

:func:`smooth_path` fits a parametric cubic smoothing spline (FITPACK ``splprep``; quadratic
for three points) to the grid polyline, parametrised by chord length, and shrinks the
smoothing locally until (after dropping zig-zags smaller than half the bound with
Douglas–Peucker)

1. the curve stays within ``max_deviation`` of the polyline and the polyline within
   ``max_deviation`` of the curve (a two-sided Hausdorff bound, checked conservatively on
   dense samples), and
2. no dense sample of the curve, nor of the straight chords between the returned samples,
   lies in a no-go cell (``is_blocked``).

If no smoothing factor passes (e.g. a path that squeezes diagonally between two blocked
cells), the polyline itself is returned, resampled. The result passes exactly through the
first and last polyline points and has equal arc-length steps of ``L / n`` with
``n = max(1, round(L / spacing))`` (the closest step to ``spacing`` that divides ``L``).
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Callable

import numpy as np
from scipy.interpolate import splev, splprep
from scipy.spatial import cKDTree

from auvplan._typing import BoolArray, FloatArray
from auvplan.errors import InputError

logger = logging.getLogger(__name__)

#: Number of spline fits tried before falling back to the polyline.
_N_TRIALS = 40
#: Largest data weight of the spline fit (also the weight of the two end points).
_MAX_WEIGHT = 1e3


def path_length(points: FloatArray) -> float:
    r"""Length [m] of a polyline.

    Parameters
    ----------
    points : ndarray of shape (n_points, 2)
        ``[north, east]`` [m].

    Returns
    -------
    float
        :math:`\sum_i \|p_{i+1} - p_i\|`.

    Examples
    --------
    >>> path_length(np.array([[0.0, 0.0], [3.0, 4.0], [3.0, 5.0]]))
    6.0
    """
    return float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1)))


def path_headings(points: FloatArray) -> FloatArray:
    r"""Heading :math:`\psi` [rad] of the tangent at every point (from north, clockwise).

    Parameters
    ----------
    points : ndarray of shape (n_points, 2)
        ``[north, east]`` [m], ``n_points >= 2``, consecutive points distinct.

    Returns
    -------
    ndarray of shape (n_points,)
        :math:`\psi = \operatorname{atan2}(\dot e, \dot n)` from second-order finite
        differences (one-sided at the ends), unwrapped (continuous, may leave
        :math:`(-\pi, \pi]`).

    Examples
    --------
    >>> np.degrees(path_headings(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])))
    array([  0.,  45., 135., 180.])
    """
    if points.ndim != 2 or points.shape[1] != 2 or points.shape[0] < 2:
        raise InputError(f"points must have shape (n >= 2, 2), got {points.shape}")
    d_north = np.gradient(points[:, 0])
    d_east = np.gradient(points[:, 1])
    return np.asarray(np.unwrap(np.arctan2(d_east, d_north)))


def smooth_path(
    points: FloatArray,
    *,
    spacing: float,
    max_deviation: float,
    is_blocked: Callable[[FloatArray, FloatArray], BoolArray] | None = None,
) -> FloatArray:
    r"""Smooth a grid polyline into a C² curve resampled at uniform arc length.

    Parameters
    ----------
    points : ndarray of shape (n_points, 2)
        ``[north, east]`` [m] of the grid path (e.g. :attr:`Route.points`), ``n_points >= 2``.
    spacing : float
        Target arc-length step [m] of the output, ``> 0``.
    max_deviation : float
        Largest allowed distance [m] between the curve and the polyline (both ways),
        ``> 0``; typically half a cell.
    is_blocked : callable or None
        ``is_blocked(north, east) -> bool array``, true at no-go points (e.g.
        :func:`~auvplan.planning.route.blocked_lookup`); ``None`` to skip the check.

    Returns
    -------
    ndarray of shape (n_samples, 2)
        ``[north, east]`` [m], first and last rows exactly ``points[0]`` and ``points[-1]``,
        consecutive samples ``L / round(L / spacing)`` apart along the curve.

    Notes
    -----
    FITPACK's smoothing condition is :math:`\sum_i w_i^2 \|p_i - s(u_i)\|^2 \le S`, with
    chord-length parameters :math:`u_i` of the data points: the polyline simplified by
    Douglas–Peucker (tolerance :math:`\delta / 2`, :math:`\delta` = ``max_deviation``) and
    resampled every :math:`\delta`. We start at :math:`S = n \delta^2` with unit weights (end
    points :math:`10^3`, so that the curve starts and ends on them) and, where a check fails,
    multiply the weights of the nearest data points by 4 (dividing :math:`S` by 4 once they
    reach :math:`10^3`), so the curve is pulled towards the polyline only where it must be.

    Examples
    --------
    >>> staircase = np.array([[0.0, 0.0], [0.0, 1.0], [1.0, 2.0], [1.0, 3.0], [2.0, 4.0]])
    >>> curve = smooth_path(staircase, spacing=0.5, max_deviation=0.5)
    >>> curve[[0, -1]].tolist()
    [[0.0, 0.0], [2.0, 4.0]]
    >>> steps = np.linalg.norm(np.diff(curve, axis=0), axis=1)
    >>> bool(np.ptp(steps) < 1e-3)
    True
    """
    points = _clean(points)
    if not (np.isfinite(spacing) and spacing > 0.0):
        raise InputError(f"spacing must be finite and > 0, got {spacing!r} m")
    if not (np.isfinite(max_deviation) and max_deviation > 0.0):
        raise InputError(f"max_deviation must be finite and > 0, got {max_deviation!r} m")
    resolution = 0.1 * min(max_deviation, spacing)
    grid_path = points
    # fit to the simplified polyline, resampled every max_deviation so that the spline has
    # data along the straight stretches (not only at their corners)
    fit_points = resample_polyline(_simplify(grid_path, 0.5 * max_deviation), max_deviation)
    if len(fit_points) >= 3:
        curve = _fit_within_bounds(
            fit_points,
            resample_polyline(grid_path, resolution),
            spacing,
            max_deviation,
            resolution,
            is_blocked,
        )
        if curve is not None:
            return curve
        logger.info("smooth_path: no spline passed the checks; returning the polyline")
    return resample_at_spacing(grid_path, spacing)


def _fit_within_bounds(
    fit_points: FloatArray,
    polyline_dense: FloatArray,
    spacing: float,
    max_deviation: float,
    resolution: float,
    is_blocked: Callable[[FloatArray, FloatArray], BoolArray] | None,
) -> FloatArray | None:
    """Smoothing spline refined locally until it passes the checks, or ``None``.

    Where the curve violates a check, the weights of the nearest data points are multiplied by
    4 (up to :data:`_MAX_WEIGHT`), which pulls the curve towards the polyline there only; when
    those weights are already at the cap, the global smoothing factor is divided by 4.
    """
    chord = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(fit_points, axis=0), axis=1))))
    weights = np.ones(len(fit_points))
    weights[[0, -1]] = _MAX_WEIGHT
    smoothing = len(fit_points) * max_deviation**2
    data_tree = cKDTree(fit_points)
    polyline_tree = cKDTree(polyline_dense)
    limit = max_deviation - resolution  # see _violations
    for _ in range(_N_TRIALS):
        with warnings.catch_warnings():  # FITPACK's "s too small" notice: checked below
            warnings.simplefilter("ignore", RuntimeWarning)
            tck, _u = splprep(
                fit_points.T,
                u=chord,
                w=weights,
                s=smoothing,
                k=min(3, len(fit_points) - 1),
                quiet=2,
            )
        dense = _resample_spline(tck, chord[-1], fit_points, resolution)
        n_steps = max(1, round(path_length(dense) / spacing))
        curve = _resample_spline(tck, chord[-1], fit_points, resolution, n_steps=n_steps)
        # the straight chords between output samples must avoid no-go cells too
        chords = resample_polyline(curve, resolution)
        bad = np.vstack(
            (
                dense[polyline_tree.query(dense)[0] > limit],
                polyline_dense[cKDTree(dense).query(polyline_dense)[0] > limit],
                _blocked_points(dense, is_blocked),
                _blocked_points(chords, is_blocked),
            )
        )
        if len(bad) == 0:
            return curve
        near = np.unique(data_tree.query(bad, k=min(3, len(fit_points)))[1])
        if np.all(weights[near] >= _MAX_WEIGHT):
            smoothing *= 0.25
        weights[near] = np.minimum(4.0 * weights[near], _MAX_WEIGHT)
    return None


def _simplify(points: FloatArray, tolerance: float) -> FloatArray:
    """Douglas–Peucker: keep the vertices needed to stay within ``tolerance`` [m] of the polyline.

    Removes the grid's zig-zags smaller than the tolerance before the spline fit, so that a
    global smoothing factor is not held back by them. The deviation check in
    :func:`smooth_path` still uses the original polyline.
    """
    keep = np.zeros(len(points), dtype=np.bool_)
    keep[[0, -1]] = True
    stack = [(0, len(points) - 1)]
    while stack:
        first, last = stack.pop()
        if last - first < 2:
            continue
        inner = points[first + 1 : last]
        a, b = points[first], points[last]
        ab = b - a
        length2 = float(ab @ ab)
        t = np.clip((inner - a) @ ab / length2, 0.0, 1.0) if length2 > 0.0 else 0.0
        distance = np.linalg.norm(inner - (a + np.multiply.outer(t, ab)), axis=1)
        worst = int(np.argmax(distance))
        if distance[worst] > tolerance:
            split = first + 1 + worst
            keep[split] = True
            stack.extend(((first, split), (split, last)))
    return points[keep]


def _clean(points: FloatArray) -> FloatArray:
    """Validate and drop consecutive duplicate points."""
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 2 or points.shape[0] < 2:
        raise InputError(f"points must have shape (n >= 2, 2), got {points.shape}")
    if not np.all(np.isfinite(points)):
        raise InputError("points must be finite")
    keep = np.concatenate(([True], np.any(np.diff(points, axis=0) != 0.0, axis=1)))
    keep[-1] = True
    cleaned = points[keep]
    if len(cleaned) >= 2 and np.all(cleaned[-1] == cleaned[-2]):
        cleaned = np.delete(cleaned, -2, axis=0)
    if len(cleaned) < 2:
        raise InputError("points must contain at least two distinct positions")
    return cleaned


def _uniform_steps(length: float, resolution: float, n_steps: int | None) -> FloatArray:
    """Arc-length stations ``0 … length``, ``n_steps`` equal steps (or steps <= resolution)."""
    if n_steps is None:
        n_steps = max(1, int(np.ceil(length / resolution)))
    return np.linspace(0.0, length, n_steps + 1)


def resample_at_spacing(points: FloatArray, spacing: float) -> FloatArray:
    """A polyline at equal arc-length steps ``L / n``, ``n = max(1, round(L / spacing))``.

    The steps closest to ``spacing`` [m] that divide the length ``L`` (as :func:`smooth_path`
    samples its curves); exact vertices at both ends.
    """
    n_steps = max(1, round(path_length(points) / spacing))
    return resample_polyline(points, 0.0, n_steps=n_steps)


def resample_polyline(
    points: FloatArray, resolution: float, *, n_steps: int | None = None
) -> FloatArray:
    """Points at equal arc-length steps along a polyline (exact vertices at both ends)."""
    station = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))))
    target = _uniform_steps(float(station[-1]), resolution, n_steps)
    out = np.column_stack(
        (np.interp(target, station, points[:, 0]), np.interp(target, station, points[:, 1]))
    )
    out[0], out[-1] = points[0], points[-1]
    return out


def _resample_spline(
    tck: tuple[object, ...],
    u_end: float,
    points: FloatArray,
    resolution: float,
    *,
    n_steps: int | None = None,
) -> FloatArray:
    """Points of the spline at equal arc-length steps, ends pinned to the polyline ends.

    ``n_steps`` equal steps, or else steps of at most ``resolution`` [m]. The arc length is
    tabulated on a parameter grid 5 times finer than ``resolution`` (in chord length) and
    inverted by linear interpolation.
    """
    n_fine = max(2000, int(np.ceil(5.0 * u_end / resolution)))
    u_fine = np.linspace(0.0, u_end, n_fine)
    fine = np.column_stack(splev(u_fine, tck))
    station = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(fine, axis=0), axis=1))))
    target = _uniform_steps(float(station[-1]), resolution, n_steps)
    u_target = np.interp(target, station, u_fine)
    out = np.column_stack(splev(u_target, tck))
    out[0], out[-1] = points[0], points[-1]
    return out


def _blocked_points(
    points: FloatArray, is_blocked: Callable[[FloatArray, FloatArray], BoolArray] | None
) -> FloatArray:
    """The rows of ``points`` that are no-go (none when ``is_blocked`` is ``None``).

    Deviations are measured from dense samples to dense samples: that over-estimates the
    point-to-curve distance, and points between samples are within ``resolution / 2`` of one,
    hence the acceptance limit ``max_deviation - resolution``.
    """
    if is_blocked is None:
        return np.empty((0, 2))
    return np.asarray(points[np.asarray(is_blocked(points[:, 0], points[:, 1]), dtype=bool)])
