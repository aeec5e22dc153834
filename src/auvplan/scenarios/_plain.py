r"""Synthetic terrain of a transit scenario: a plain with rough features beside the lines.

The vehicles fly straight, parallel lines (:class:`Corridor`). The plain around them is
featureless: depth :math:`d_0 + s\,(\mathbf g \cdot \mathbf x)` with a regional slope
:math:`s \le` :data:`MAX_REGIONAL_SLOPE` along a random direction :math:`\mathbf g`; every
depth of the plain lies in :data:`PLAIN_DEPTH_RANGE_M`. Beside features the plain also
undulates (two long plane waves, slope below :data:`MAX_UNDULATION_SLOPE`). A flat plain is
an exact plane: the information map is normalised by the grid's steepest slope
(:func:`auvplan.terrain.compute_information_map`), which would stretch any undulation of a
plane into full contrast and send the pre-planner's paths after it.

Unless the plain is flat, one or two rough features (:class:`Feature`) rise from it on one
side of the lines. Each fills a capsule-shaped footprint (a segment of half-length ``a``
swept by a disc of radius ``R``, a disc when ``a = 0``) and is exactly zero outside it:

* ``"seamount"``: a disc with relief :math:`h \cos^2(\pi q / 2)` of the normalised distance
  :math:`q = \rho / R` from the axis, and a fine random texture;
* ``"ridge"``: an elongated capsule with the same cross profile and texture;
* ``"rough patch"``: random hummocks (white noise smoothed by a Gaussian of a few cells),
  tapered to zero over the outer half of the footprint.

The relief is scaled so that its steepest slope is a drawn value in
:data:`FEATURE_SLOPE_RANGE`, unless that would raise it above :data:`MAX_RELIEF_FRACTION` of
the plain's depth there (the slope is then lower). A feature's offset is the perpendicular
distance from the nearest vehicle line on its side to its footprint.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Final

import numpy as np
from scipy import ndimage

from auvplan._typing import FloatArray
from auvplan.terrain import BathymetryGrid, GridGeometry

#: Depths [m] of the plain (without features).
PLAIN_DEPTH_RANGE_M: Final = (40.0, 150.0)
#: Steepest regional slope of the plain [m/m] (0.5 %).
MAX_REGIONAL_SLOPE: Final = 0.005
#: Steepest slope of the plain's undulation [m/m] (0.1 %).
MAX_UNDULATION_SLOPE: Final = 0.001
#: Wavelengths [m] of the undulation's plane waves.
UNDULATION_WAVELENGTH_M: Final = (1500.0, 4000.0)
#: Node spacings [m] drawn (integers), before any coarsening to :data:`MAX_NODES`.
SPACING_RANGE_M: Final = (10, 25)
#: Largest number of nodes along a side of the grid.
MAX_NODES: Final = 1000
#: Plain kept beyond the first start and the last goal, along the lines [m].
END_CLEARANCE_M: Final = (300.0, 700.0)
#: Plain kept beside the outermost line or feature, on each side [m].
SIDE_CLEARANCE_M: Final = (300.0, 700.0)
FEATURE_KINDS: Final = ("seamount", "ridge", "rough patch")
#: Perpendicular offsets [m] of a feature's footprint from the nearest line on its side.
FEATURE_OFFSET_RANGE_M: Final = (0.0, 800.0)
#: Steepest slope [m/m] a feature's relief is scaled to (5–30 %).
FEATURE_SLOPE_RANGE: Final = (0.05, 0.30)
#: A feature rises at most this fraction of the plain's depth under it.
MAX_RELIEF_FRACTION: Final = 0.7
#: Share of featured plains with two features (else one).
TWO_FEATURE_SHARE: Final = 0.35
#: Radius ``R`` [m] of a seamount's disc, a ridge's half-width, a rough patch's radius.
FEATURE_RADIUS_M: Final = {
    "seamount": (150.0, 500.0),
    "ridge": (80.0, 250.0),
    "rough patch": (200.0, 500.0),
}
#: Half-length ``a`` [m] of a feature's axis (0 for a seamount's disc).
FEATURE_HALF_LENGTH_M: Final = {
    "seamount": (0.0, 0.0),
    "ridge": (250.0, 900.0),
    "rough patch": (0.0, 300.0),
}
#: A feature's radius spans at least this many grid cells.
MIN_FEATURE_CELLS: Final = 5
#: Where features are centred along the lines: fraction-of-length slots, by feature count.
ALONG_SLOTS: Final = {1: ((0.1, 0.9),), 2: ((0.1, 0.5), (0.5, 0.9))}


@dataclass(frozen=True)
class Corridor:
    """Straight parallel lines of ``length_m`` [m] along the unit vector ``direction``.

    Line ``i`` starts at ``origin + stagger[i] direction + lanes[i] across`` [m] (north,
    east), where ``across`` points to the right of ``direction``.
    """

    origin: FloatArray
    direction: FloatArray
    length_m: float
    lanes: FloatArray
    stagger: FloatArray

    @property
    def across(self) -> FloatArray:
        """Unit vector (north, east) to the right of :attr:`direction`."""
        return np.array([-self.direction[1], self.direction[0]])

    def point(self, along: FloatArray | float, across: FloatArray | float) -> FloatArray:
        """Points ``(..., 2)`` (north, east) [m] at corridor coordinates ``along, across`` [m]."""
        along_, across_ = np.broadcast_arrays(np.asarray(along, float), np.asarray(across, float))
        return np.asarray(
            self.origin + along_[..., None] * self.direction + across_[..., None] * self.across
        )

    @property
    def starts(self) -> FloatArray:
        """Start points ``(n_lines, 2)`` [m]."""
        return self.point(self.stagger, self.lanes)

    @property
    def goals(self) -> FloatArray:
        """Goal points ``(n_lines, 2)`` [m]."""
        return self.point(self.stagger + self.length_m, self.lanes)

    def across_of(self, north: FloatArray, east: FloatArray) -> FloatArray:
        """Signed across coordinate [m] of points (positive right of the lines)."""
        return np.asarray(
            (north - self.origin[0]) * self.across[0] + (east - self.origin[1]) * self.across[1]
        )

    def moved(self, shift: FloatArray) -> Corridor:
        """The same corridor translated by ``shift`` (north, east) [m]."""
        return replace(self, origin=self.origin + shift)


@dataclass(frozen=True)
class Feature:
    """A rough feature of a transit plain.

    ``axis`` holds the two end points ``(2, 2)`` (north, east) [m] of the footprint's axis,
    ``radius_m`` its radius [m]; ``side`` is +1 right of the lines, -1 left; ``offset_m``
    the perpendicular distance [m] from the nearest line on that side to the footprint;
    ``height_m`` the largest absolute relief [m] and ``max_slope`` the steepest slope of the
    relief alone [m/m] (both 0 until the feature is rasterised).
    """

    kind: str
    axis: FloatArray
    radius_m: float
    side: int
    offset_m: float
    height_m: float = 0.0
    max_slope: float = 0.0

    def axis_distance(self, north: FloatArray, east: FloatArray) -> FloatArray:
        """Distance [m] of points to the axis segment."""
        a, b = self.axis
        segment = b - a
        length_sq = float(segment @ segment)
        t = (
            np.zeros_like(north)
            if length_sq == 0.0
            else np.clip(
                ((north - a[0]) * segment[0] + (east - a[1]) * segment[1]) / length_sq, 0, 1
            )
        )
        return np.asarray(np.hypot(north - a[0] - t * segment[0], east - a[1] - t * segment[1]))

    def footprint_distance(self, north: FloatArray, east: FloatArray) -> FloatArray:
        """Distance [m] of points to the footprint (0 inside)."""
        return np.maximum(self.axis_distance(north, east) - self.radius_m, 0.0)

    def moved(self, shift: FloatArray) -> Feature:
        """The same feature translated by ``shift`` (north, east) [m]."""
        return replace(self, axis=self.axis + shift)


def draw_features(
    rng: np.random.Generator, corridor: Corridor, n_features: int, *, spacing: float
) -> tuple[Feature, ...]:
    """``n_features`` (1 or 2) features on one random side of ``corridor``'s lines.

    Each is centred in its :data:`ALONG_SLOTS` slot (shrunk to stay inside it), at an angle
    to the lines drawn uniformly, its footprint at a drawn offset in
    :data:`FEATURE_OFFSET_RANGE_M` [m] from the nearest line on that side.
    """
    side = 1 if rng.uniform() < 0.5 else -1
    edge = float(np.max(side * corridor.lanes))  # outermost line on that side, from the origin
    features = []
    for low, high in ALONG_SLOTS[n_features]:
        kind = str(rng.choice(FEATURE_KINDS))
        radius = max(float(rng.uniform(*FEATURE_RADIUS_M[kind])), MIN_FEATURE_CELLS * spacing)
        half_length = float(rng.uniform(*FEATURE_HALF_LENGTH_M[kind]))
        angle = float(rng.uniform(0.0, math.pi))
        offset = float(rng.uniform(*FEATURE_OFFSET_RANGE_M))
        centre = rng.uniform(low + 0.2 * (high - low), high - 0.2 * (high - low))
        room = min(centre - low, high - centre) * corridor.length_m
        cos_a, sin_a = abs(math.cos(angle)), abs(math.sin(angle))
        if radius >= room:
            radius, half_length = room, 0.0
        elif half_length * cos_a + radius > room:
            half_length = (room - radius) / cos_a
        across = side * (edge + offset + half_length * sin_a + radius)
        middle = corridor.point(centre * corridor.length_m, across)
        reach = half_length * (
            math.cos(angle) * corridor.direction + math.sin(angle) * corridor.across
        )
        axis = np.array([middle - reach, middle + reach])
        features.append(Feature(kind, axis, round(radius, 2), side, round(offset, 1)))
    return tuple(features)


def extent(
    rng: np.random.Generator, corridor: Corridor, features: tuple[Feature, ...]
) -> tuple[FloatArray, FloatArray]:
    """South-west and north-east corners (north, east) [m] of the terrain to generate.

    The rectangle along the lines that holds them, every feature and the drawn
    :data:`END_CLEARANCE_M` / :data:`SIDE_CLEARANCE_M`, as an axis-aligned box.
    """
    along = [float(corridor.stagger.min()), float(corridor.stagger.max()) + corridor.length_m]
    across = [float(corridor.lanes.min()), float(corridor.lanes.max())]
    for feature in features:
        for end in feature.axis:
            offset = float(corridor.across_of(end[0], end[1]))
            across += [offset - feature.radius_m, offset + feature.radius_m]
    ends = rng.uniform(*END_CLEARANCE_M, 2)
    sides = rng.uniform(*SIDE_CLEARANCE_M, 2)
    corners = corridor.point(
        np.array([along[0] - ends[0], along[1] + ends[1]])[:, None],
        np.array([min(across) - sides[0], max(across) + sides[1]])[None, :],
    ).reshape(-1, 2)
    return corners.min(axis=0), corners.max(axis=0)


def plain_depth(
    rng: np.random.Generator, north: FloatArray, east: FloatArray, *, undulating: bool
) -> tuple[FloatArray, float, float]:
    """The featureless plain at nodes ``(north, east)`` [m] (2-D, broadcast).

    Returns the depth [m], its regional slope [m/m] and mean depth [m]; an exact plane unless
    ``undulating``.
    """
    corners_n = np.array([north.min(), north.max()])
    corners_e = np.array([east.min(), east.max()])
    angle = rng.uniform(0.0, 2.0 * math.pi)
    gradient = np.array([math.cos(angle), math.sin(angle)])
    slope = float(rng.uniform(0.0, MAX_REGIONAL_SLOPE))
    centre = np.array([corners_n.mean(), corners_e.mean()])
    span = float(np.ptp(np.add.outer(corners_n * gradient[0], corners_e * gradient[1])))
    undulation = np.zeros(np.broadcast_shapes(north.shape, east.shape))
    amplitudes = []
    for _ in range(2 if undulating else 0):
        wavelength = float(rng.uniform(*UNDULATION_WAVELENGTH_M))
        amplitude = float(rng.uniform(0.3, 1.0)) * 0.5 * MAX_UNDULATION_SLOPE * wavelength
        amplitude /= 2.0 * math.pi
        heading = rng.uniform(0.0, 2.0 * math.pi)
        phase = rng.uniform(0.0, 2.0 * math.pi)
        wavenumber = 2.0 * math.pi / wavelength
        along = north * math.cos(heading) + east * math.sin(heading)
        undulation = undulation + amplitude * np.sin(wavenumber * along + phase)
        amplitudes.append(amplitude)
    low, high = PLAIN_DEPTH_RANGE_M
    room = high - low - 2.0 * sum(amplitudes)
    slope = min(slope, room / max(span, 1.0))
    half = 0.5 * slope * span + sum(amplitudes)
    mean = float(rng.uniform(low + half, high - half))
    regional = slope * ((north - centre[0]) * gradient[0] + (east - centre[1]) * gradient[1])
    return np.asarray(mean + regional + undulation), slope, mean


def _slope(relief: FloatArray, spacing: float) -> FloatArray:
    """Slope magnitude [m/m] of a grid (central differences, one-sided at the border)."""
    d_north, d_east = np.gradient(relief, spacing)
    return np.asarray(np.hypot(d_north, d_east))


def raster_feature(
    rng: np.random.Generator,
    feature: Feature,
    depth: FloatArray,
    spacing: float,
) -> tuple[FloatArray, Feature]:
    """Raise ``feature`` from ``depth`` (nodes ``spacing`` [m] apart from the origin).

    Returns the new depth [m] and the feature with its height and steepest slope.
    """
    lows = feature.axis.min(axis=0) - feature.radius_m - 2.0 * spacing
    highs = feature.axis.max(axis=0) + feature.radius_m + 2.0 * spacing
    first = np.maximum(np.floor(lows / spacing).astype(int), 0)
    last = np.minimum(np.ceil(highs / spacing).astype(int), np.array(depth.shape) - 1)
    rows, cols = np.arange(first[0], last[0] + 1), np.arange(first[1], last[1] + 1)
    north, east = np.meshgrid(rows * spacing, cols * spacing, indexing="ij")
    q = feature.axis_distance(north, east) / feature.radius_m
    inside = q < 1.0
    texture_cells = rng.uniform(1.5, 3.0) if feature.kind != "rough patch" else rng.uniform(2, 5)
    texture = ndimage.gaussian_filter(rng.standard_normal(north.shape), texture_cells)
    texture /= max(float(np.std(texture)), 1e-12)
    if feature.kind == "rough patch":
        taper = np.where(q <= 0.5, 1.0, np.cos(np.pi * np.clip(q - 0.5, 0.0, 0.5)) ** 2)
        relief = np.where(inside, texture * taper, 0.0)
    else:
        dome = np.where(inside, np.cos(0.5 * np.pi * np.clip(q, 0.0, 1.0)) ** 2, 0.0)
        relief = dome * (1.0 + rng.uniform(0.05, 0.15) * texture)
    target = float(rng.uniform(*FEATURE_SLOPE_RANGE))
    steepest = float(_slope(relief, spacing).max())
    tallest = float(np.abs(relief).max())
    window = depth[np.ix_(rows, cols)]
    scale = target / steepest
    limit = MAX_RELIEF_FRACTION * float(window[inside].min())
    if scale * tallest > limit:
        scale = limit / tallest
    raised = depth.copy()
    raised[np.ix_(rows, cols)] = window - scale * relief
    height, max_slope = round(scale * tallest, 2), round(scale * steepest, 4)
    return raised, replace(feature, height_m=height, max_slope=max_slope)


def draw_plain(
    rng: np.random.Generator, corridor: Corridor, *, flat: bool
) -> tuple[BathymetryGrid, Corridor, tuple[Feature, ...], str]:
    """A transit plain around ``corridor`` (flat, or with 1–2 features beside its lines).

    Returns the grid (origin at its south-west node, no projection), the corridor and
    features moved into its frame, and a short label.
    """
    spacing = float(rng.integers(SPACING_RANGE_M[0], SPACING_RANGE_M[1] + 1))
    n_features = 0 if flat else 1 + int(rng.uniform() < TWO_FEATURE_SHARE)
    features = draw_features(rng, corridor, n_features, spacing=spacing) if n_features else ()
    south_west, north_east = extent(rng, corridor, features)
    sides = north_east - south_west
    spacing = max(spacing, float(math.ceil(float(sides.max()) / (MAX_NODES - 1))))
    n_rows, n_cols = (int(n) + 1 for n in np.ceil(sides / spacing))
    shift = -south_west
    corridor = corridor.moved(shift)
    features = tuple(feature.moved(shift) for feature in features)
    north = (np.arange(n_rows, dtype=np.float64) * spacing)[:, None]
    east = (np.arange(n_cols, dtype=np.float64) * spacing)[None, :]
    depth, slope, mean = plain_depth(rng, north, east, undulating=not flat)
    raised = []
    for feature in features:
        depth, feature_ = raster_feature(rng, feature, depth, spacing)
        raised.append(feature_)
    size = f"{n_rows * spacing / 1e3:.1f} x {n_cols * spacing / 1e3:.1f} km at {spacing:g} m"
    label = f"plain {size}, depth {mean:.0f} m, slope {100 * slope:.2f} %"
    name = f"transit plain ({'flat' if flat else f'{n_features} features'})"
    grid = BathymetryGrid(depth, GridGeometry(n_rows, n_cols, spacing, spacing), name=name)
    return grid, corridor, tuple(raised), label
