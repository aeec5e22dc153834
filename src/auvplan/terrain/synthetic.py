r"""The embedded default terrain: a seeded synthetic volcanic bank.

No public grid of the paper's site (D. João de Castro bank, Azores) exists at its resolution
(SPEC §6), so the default mission runs on a synthetic bank of the same size and relief: an
800 m (east) x 400 m (north) map, 4 m spacing, depths about 20–60 m, with

* a volcanic cone whose summit is cut by a **crater** ringed by an irregular **crater rim**,
* **flanks** falling off to the surrounding plain,
* **radial gullies** cut into the flanks,
* fractal **roughness** with a power-law spectrum :math:`P(k) \propto k^{-\beta}`
  (synthesised by filtering white noise with numpy's FFT).

The bank is centred at ``(north, east) = (200, 335) m`` with a mean rim radius of 110 m, so its
**eastern rim** runs through ``east ≈ 420–480 m`` for ``north ≈ 100–300 m``: the demo mission
sends two vehicles from south to north across it, as in the paper's Fig. 6.
"""

from __future__ import annotations

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.terrain.grid import BathymetryGrid, GridGeometry
from auvplan.terrain.resample import check_grid_size

#: Centre of the crater [m] (north, east) on the default 400 m x 800 m map.
BANK_CENTRE_NORTH = 200.0
BANK_CENTRE_EAST = 340.0
#: Semi-axes [m] of the mean crater-rim ellipse (north, east).
RIM_SEMI_AXIS_NORTH = 150.0
RIM_SEMI_AXIS_EAST = 110.0


def synthetic_bank(
    *,
    seed: int = 7,
    extent_north: float = 400.0,
    extent_east: float = 800.0,
    spacing: float = 4.0,
    depth_range: tuple[float, float] = (20.0, 60.0),
    roughness_m: float = 1.4,
    spectral_exponent: float = 3.2,
) -> BathymetryGrid:
    r"""A seeded synthetic volcanic bank (the embedded default terrain).

    Parameters
    ----------
    seed : int
        Seed of the :class:`numpy.random.Generator` that draws the rim shape, the gullies and
        the roughness. The same seed always gives the same grid.
    extent_north, extent_east : float
        Map size [m]; the grid has ``round(extent / spacing) + 1`` nodes per axis, the first
        at 0. Defaults: 400 m north x 800 m east (101 x 201 nodes).
    spacing : float
        Node spacing [m], the same along north and east.
    depth_range : tuple of float
        ``(shallowest, deepest)`` depth [m]; the relief is scaled to span exactly this range.
    roughness_m : float
        Standard deviation [m] of the fractal roughness before the final scaling.
    spectral_exponent : float
        Exponent :math:`\beta` of the roughness power spectrum :math:`P(k) \propto k^{-\beta}`
        (2-D; :math:`\beta = 2H + 2` for Hurst exponent :math:`H`, so 3.2 means H = 0.6).

    Returns
    -------
    BathymetryGrid
        Depth [m], positive down, no NaN cells, ``projection=None``, origin at the south-west
        node, name ``"synthetic volcanic bank (seed <seed>)"``.

    Raises
    ------
    InputError
        If the seed is not a non-negative integer, a size, the spacing or the depth range is
        not positive / ordered, or the grid would exceed
        :data:`~auvplan.terrain.resample.MAX_GRID_NODES`.

    Notes
    -----
    The relief is a sum of radial profiles in the polar coordinates :math:`(\rho, \theta)`
    about the crater centre: a Gaussian rim ring at radius :math:`R(\theta)` (the mean radius
    plus a few random low angular harmonics), a bowl-shaped crater floor inside it, and flanks
    decaying as :math:`\exp(-((\rho - R)/L)^{1.4})` outside it. Gullies are narrow troughs
    :math:`\cos^{16}` in angle about random azimuths, deepening down the flank. The roughness is
    white noise filtered by :math:`k^{-\beta/2}` in the Fourier domain.

    Examples
    --------
    >>> bank = synthetic_bank(seed=7)
    >>> bank.depth.shape
    (101, 201)
    >>> round(float(bank.depth.min()), 6), round(float(bank.depth.max()), 6)
    (20.0, 60.0)
    """
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise InputError(f"synthetic bank seed must be an integer >= 0, got {seed!r}")
    if not (extent_north > 0.0 and extent_east > 0.0 and spacing > 0.0):
        raise InputError(
            f"synthetic bank extents and spacing must be positive, got "
            f"{extent_north} x {extent_east} m at {spacing} m"
        )
    shallow, deep = (float(v) for v in depth_range)
    if not 0.0 <= shallow < deep:
        raise InputError(
            f"depth_range must be (shallow, deep) with 0 <= shallow < deep, got {depth_range}"
        )
    n_rows = round(extent_north / spacing) + 1
    n_cols = round(extent_east / spacing) + 1
    if n_rows < 8 or n_cols < 8:
        raise InputError(f"synthetic bank needs at least 8 x 8 nodes, got {n_rows} x {n_cols}")
    check_grid_size(n_rows, n_cols, spacing, spacing)
    geometry = GridGeometry(n_rows, n_cols, spacing, spacing)
    rng = np.random.default_rng(seed)

    # Scale the bank with the map so that other extents keep the same layout.
    scale_north, scale_east = extent_north / 400.0, extent_east / 800.0
    centre_north = BANK_CENTRE_NORTH * scale_north
    centre_east = BANK_CENTRE_EAST * scale_east
    semi_north = RIM_SEMI_AXIS_NORTH * scale_north
    semi_east = RIM_SEMI_AXIS_EAST * scale_east

    north, east = np.meshgrid(geometry.north, geometry.east, indexing="ij")
    d_north, d_east = (north - centre_north) / semi_north, (east - centre_east) / semi_east
    radius = np.hypot(d_north, d_east)  # 1 on the mean rim ellipse
    azimuth = np.arctan2(d_east, d_north)  # clockwise from north, like a heading

    height = _cone_height(radius, azimuth, rng)
    height -= _gullies(radius, azimuth, rng)
    height += _fractal_roughness(geometry.shape, spacing, spectral_exponent, rng) * roughness_m

    # Height above the plain -> depth, scaled to span the requested range exactly.
    relief = (height - height.min()) / (height.max() - height.min())
    depth = deep - (deep - shallow) * relief
    return BathymetryGrid(
        np.ascontiguousarray(depth, dtype=np.float64),
        geometry,
        None,
        None,
        f"synthetic volcanic bank (seed {seed})",
        {"seed": str(seed), "source": "auvplan.terrain.synthetic.synthetic_bank"},
    )


def _cone_height(radius: FloatArray, azimuth: FloatArray, rng: np.random.Generator) -> FloatArray:
    """Height [m] above the plain of the cone, crater and rim (before roughness).

    ``radius`` is the elliptical radius normalised so that the mean rim is at 1.
    """
    # Irregular rim: radius 1 plus angular harmonics 2..4 of a few per cent.
    rim = np.ones_like(azimuth)
    for order in (2, 3, 4):
        amplitude = rng.uniform(0.02, 0.05) / (order - 1)
        rim += amplitude * np.cos(order * azimuth + rng.uniform(0.0, 2.0 * np.pi))
    crest = 36.0 + 3.0 * np.cos(azimuth - rng.uniform(0.0, 2.0 * np.pi))
    scaled = radius / rim  # 1 on the rim crest
    ring = crest * np.exp(-(((scaled - 1.0) / 0.2) ** 2))
    # Crater floor: a bowl about 15 m below the mean crest, rising steeply to the crest.
    floor = 21.0 + (crest - 21.0) * np.clip(scaled, 0.0, 1.0) ** 2.5
    # Flanks: long decay outside the rim.
    flank = crest * np.exp(-((np.clip(scaled - 1.0, 0.0, None) / 0.9) ** 1.2))
    result: FloatArray = np.where(scaled < 1.0, np.maximum(floor, ring), np.maximum(flank, ring))
    return result


def _gullies(radius: FloatArray, azimuth: FloatArray, rng: np.random.Generator) -> FloatArray:
    """Depth [m] of radial gullies cut into the flanks (zero inside the crater)."""
    n_gullies = int(rng.integers(10, 15))
    centres = rng.uniform(0.0, 2.0 * np.pi, n_gullies)
    depths = rng.uniform(4.0, 8.0, n_gullies)
    # Gullies start just outside the rim crest, deepen, then fade on the plain.
    along = np.clip(radius - 1.08, 0.0, None)
    profile = (along / 0.5) * np.exp(1.0 - along / 0.5)
    cut = np.zeros_like(radius)
    for centre, depth in zip(centres, depths, strict=True):
        trough = np.cos(0.5 * (azimuth - centre)) ** 500  # about ±6° wide at half depth
        cut = np.maximum(cut, depth * trough * profile)
    return cut


def _fractal_roughness(
    shape: tuple[int, int], spacing: float, spectral_exponent: float, rng: np.random.Generator
) -> FloatArray:
    r"""Zero-mean, unit-variance Gaussian field with power spectrum :math:`\propto k^{-\beta}`."""
    noise = rng.standard_normal(shape)
    k_north = np.fft.fftfreq(shape[0], d=spacing)
    k_east = np.fft.rfftfreq(shape[1], d=spacing)
    wavenumber = np.hypot(k_north[:, None], k_east[None, :])
    wavenumber[0, 0] = np.inf  # no mean
    field = np.fft.irfft2(np.fft.rfft2(noise) * wavenumber ** (-0.5 * spectral_exponent), s=shape)
    field -= field.mean()
    std = field.std()
    result: FloatArray = field / std if std > 0.0 else field
    return result
