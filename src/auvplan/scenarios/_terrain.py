"""Terrain of a generated scenario: a window of a real grid, the packaged bank, or a new bank.

Kinds (:data:`TERRAIN_KINDS`):

* ``"bank"``: the packaged synthetic volcanic bank (``synthetic = true, seed = ...``,
  800 m x 400 m at 4 m), for straight-line distances up to :data:`BANK_MAX_DISTANCE_M`;
* ``"synthetic"``: a seeded synthetic bank of any size and aspect (an elongated extent makes
  a ridge-like bank), written next to the mission as ``terrain.nc`` (metric ``north``/``east``
  coordinates and ``depth``);
* ``"monterey"``, ``"lisbon"``, ``"balanus"``: a lat/lon window of the real grids in the
  shared bathymetry folder (skipped when the file is absent).

Every terrain is returned exactly as ``auvplan plan`` will load it, with its cost map, so
poses can be checked against the same no-go cells.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any, Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.io.bathymetry import read_bathymetry
from auvplan.io.samples import SAMPLE_FILES, samples_folder
from auvplan.terrain import (
    BathymetryGrid,
    GridGeometry,
    MapParameters,
    compute_terrain_maps,
    synthetic_bank,
)

#: Real grids of the data folder, by kind (the packaged samples' files; this order draws the
#: seeded family).
REAL_GRIDS: Final = {kind: SAMPLE_FILES[kind] for kind in ("monterey", "lisbon", "balanus")}
TERRAIN_KINDS: Final = ("bank", "synthetic", *REAL_GRIDS)
#: File name of a generated terrain inside the scenario folder.
SYNTHETIC_FILE: Final = "terrain.nc"
#: Longest start-goal distance [m] placed on the packaged 800 m x 400 m bank.
BANK_MAX_DISTANCE_M: Final = 600.0
#: A start-goal distance spans at least this many cost-grid cells.
MIN_CELLS_PER_DISTANCE: Final = 5
#: Grids with cells coarser than this [m] use 1 x 1 blocks (no further downsampling).
COARSE_CELL_M: Final = 50.0
#: Largest number of nodes along a side of a generated synthetic terrain.
SYNTHETIC_MAX_NODES: Final = 400
#: Share of water (finite cost) a real-grid window must have.
MIN_WATER_FRACTION: Final = 0.6


@dataclass(frozen=True)
class DrawnTerrain:
    """A scenario's terrain as the pipeline will load it.

    ``table`` is the mission's ``[terrain]`` table (``file`` absolute for real grids,
    :data:`SYNTHETIC_FILE` for generated ones), ``block`` the ``[maps]`` block size,
    ``cost`` the shifted cost map on ``cost_geometry`` (NaN = no-go), ``synthetic`` the grid
    to write as :data:`SYNTHETIC_FILE` (None otherwise), ``label`` a short description.
    """

    kind: str
    table: dict[str, Any]
    block: tuple[int, int]
    grid: BathymetryGrid
    cost_geometry: GridGeometry
    cost: FloatArray
    synthetic: BathymetryGrid | None
    label: str

    @property
    def cell_size(self) -> float:
        """Largest cost-grid spacing [m]."""
        return max(self.cost_geometry.spacing_north, self.cost_geometry.spacing_east)


def default_data_dir() -> Path:
    """The folder of the real grids of the scenario family.

    ``$AUVPLAN_SHARED_DATA/bathymetry``; else ``../shared/data/bathymetry`` from the cwd if it
    exists; else the grids packaged with auvplan (the same files: the same family).
    """
    shared = os.environ.get("AUVPLAN_SHARED_DATA")
    if shared:
        return Path(shared) / "bathymetry"
    beside = Path("..") / "shared" / "data" / "bathymetry"
    return beside if beside.is_dir() else samples_folder()


def check_data_dir(path: Path) -> None:
    """Refuse a given data folder that holds none of the :data:`REAL_GRIDS`.

    For a folder named on purpose (``--data-dir``): a typo would otherwise silently give the
    family without real grids. The default folder (:func:`default_data_dir`) may be absent.

    Raises
    ------
    InputError
        If ``path`` is not a folder, or holds none of the real grid files (all are named).
    """
    grids = ", ".join(REAL_GRIDS.values())
    if not path.is_dir():
        state = "is not a folder" if path.exists() else "does not exist"
        raise InputError(
            f"data folder {path} {state}: it should hold the real bathymetry grids "
            f"(at least one of {grids})"
        )
    if not any((path / name).is_file() for name in REAL_GRIDS.values()):
        raise InputError(
            f"data folder {path} holds none of the real bathymetry grids: lacks {grids}"
        )


@cache
def _full_grid(path: Path) -> BathymetryGrid:
    return read_bathymetry(path)


def _block_for(spacing: float) -> tuple[int, int]:
    return (1, 1) if spacing > COARSE_CELL_M else (2, 2)


def feasible_kinds(data_dir: Path, min_distance: float, max_distance: float) -> list[str]:
    """Kinds whose extent and resolution suit start-goal distances in ``[min, max]`` [m]."""
    kinds = ["synthetic"]
    if max_distance <= BANK_MAX_DISTANCE_M:
        kinds.insert(0, "bank")
    for kind, name in REAL_GRIDS.items():
        path = data_dir / name
        if not path.is_file():
            continue
        geometry = _full_grid(path.resolve()).geometry
        spacing = max(geometry.spacing_north, geometry.spacing_east)
        cell = spacing * _block_for(spacing)[0]
        extent = min(
            geometry.n_rows * geometry.spacing_north, geometry.n_cols * geometry.spacing_east
        )
        margin = pose_margin(cell, 0.0)
        if (
            min_distance >= MIN_CELLS_PER_DISTANCE * cell
            and max_distance + 2 * margin <= 0.9 * extent
        ):
            kinds.append(kind)
    return kinds


def pose_margin(cell: float, safety_radius: float) -> float:
    """Distance [m] kept between poses and no-go cells or the map edge."""
    return 1.5 * cell + 2.0 * safety_radius


def draw_terrain(
    kind: str,
    rng: np.random.Generator,
    *,
    max_distance: float,
    safety_radius: float,
    data_dir: Path,
) -> DrawnTerrain | None:
    """A terrain of ``kind`` large enough for ``max_distance`` [m]; None if no window has water.

    Real-grid windows are drawn (size ``1.1–1.6 x`` the distance plus margins, random place)
    until one has at least :data:`MIN_WATER_FRACTION` water, at most 20 times.
    """
    if kind == "bank":
        seed = int(rng.integers(1, 1000))
        grid = synthetic_bank(seed=seed)
        return with_maps(kind, {"synthetic": True, "seed": seed}, grid, None, f"bank {seed}")
    if kind == "synthetic":
        return _synthetic(rng, max_distance, safety_radius)
    path = (data_dir / REAL_GRIDS[kind]).resolve()
    full = _full_grid(path)
    assert full.projection is not None
    geometry = full.geometry
    spacing = max(geometry.spacing_north, geometry.spacing_east)
    block = _block_for(spacing)
    side = max_distance + 2.0 * pose_margin(spacing * block[0], safety_radius)
    extent = np.array([geometry.north[-1], geometry.east[-1]])
    for _ in range(20):
        size = np.minimum(side * rng.uniform(1.1, 1.6, 2), extent)
        corner = rng.uniform(0.0, 1.0, 2) * (extent - size)
        rows = (geometry.north >= corner[0]) & (geometry.north <= corner[0] + size[0])
        cols = (geometry.east >= corner[1]) & (geometry.east <= corner[1] + size[1])
        if np.mean(np.isfinite(full.depth[np.ix_(rows, cols)])) < MIN_WATER_FRACTION:
            continue
        north = np.array([corner[0], corner[0], corner[0] + size[0], corner[0] + size[0]])
        east = np.array([corner[1], corner[1] + size[1], corner[1], corner[1] + size[1]])
        lat, lon = full.projection.to_geographic(north, east)
        south, north_edge = round(float(lat.min()), 6), round(float(lat.max()), 6)
        west, east_edge = round(float(lon.min()), 6), round(float(lon.max()), 6)
        grid = read_bathymetry(path, window_lat=(south, north_edge), window_lon=(west, east_edge))
        window = {"lat": [south, north_edge], "lon": [west, east_edge]}
        label = f"{kind} window {size[0] / 1e3:.1f} x {size[1] / 1e3:.1f} km"
        drawn = with_maps(kind, {"file": str(path), "window": window}, grid, None, label)
        if np.mean(np.isfinite(drawn.cost)) >= MIN_WATER_FRACTION:
            return drawn
    return None


def _synthetic(rng: np.random.Generator, max_distance: float, safety_radius: float) -> DrawnTerrain:
    """A seeded synthetic bank sized for ``max_distance``, random aspect, relief and texture."""
    sides = (max_distance + 40.0 + 4.0 * safety_radius) * rng.uniform(1.15, 1.7, 2)
    spacing = float(max(4, math.ceil(float(np.max(sides)) / SYNTHETIC_MAX_NODES)))
    sides = np.maximum(sides, 3.0 * pose_margin(2 * spacing, safety_radius))
    shallow = float(rng.uniform(10.0, 60.0))
    relief = float(rng.uniform(20.0, 40.0 + np.max(sides) / 20.0))
    seed = int(rng.integers(1, 2**31 - 1))
    grid = synthetic_bank(
        seed=seed,
        extent_north=spacing * round(float(sides[0]) / spacing),
        extent_east=spacing * round(float(sides[1]) / spacing),
        spacing=spacing,
        depth_range=(round(shallow, 1), round(shallow + relief, 1)),
        roughness_m=float(rng.uniform(0.8, 2.5)),
        spectral_exponent=float(rng.uniform(2.6, 3.6)),
    )
    label = f"synthetic bank {sides[0] / 1e3:.1f} x {sides[1] / 1e3:.1f} km (seed {seed})"
    return with_maps("synthetic", {"file": SYNTHETIC_FILE}, grid, grid, label)


def with_maps(
    kind: str,
    table: dict[str, Any],
    grid: BathymetryGrid,
    synthetic: BathymetryGrid | None,
    label: str,
) -> DrawnTerrain:
    """``grid`` with its cost map as ``auvplan plan`` computes it (block by its spacing)."""
    geometry = grid.geometry
    block = _block_for(max(geometry.spacing_north, geometry.spacing_east))
    maps = compute_terrain_maps(grid, MapParameters(block=block))
    return DrawnTerrain(
        kind, table, block, grid, maps.cost_geometry, maps.shifted_cost, synthetic, label
    )


def write_synthetic_terrain(grid: BathymetryGrid, path: Path) -> None:
    """Write a metric grid as NetCDF-3 (``north``, ``east`` [m], ``depth`` positive down)."""
    import xarray as xr

    geometry = grid.geometry

    def axis(name: str, values: FloatArray) -> xr.Variable:
        return xr.Variable(
            (name,), values, {"units": "m", "long_name": f"distance {name} of the origin"}
        )

    dataset = xr.Dataset(
        {
            "depth": xr.Variable(
                ("north", "east"),
                grid.depth,
                {"units": "m", "positive": "down", "long_name": "depth of the sea floor"},
            )
        },
        coords={
            "north": axis("north", geometry.north),
            "east": axis("east", geometry.east),
        },
        attrs={"title": grid.name, "source": "auvplan.scenarios (synthetic, seeded)"},
    )
    dataset.to_netcdf(path, engine="scipy")
