"""Terrain maps (paper eqs. 13-15) against hand-computed grids and a loop oracle."""

from __future__ import annotations

import numpy as np
import pytest

from auvplan.errors import InputError
from auvplan.terrain import (
    BathymetryGrid,
    GridGeometry,
    MapParameters,
    compute_cost_map,
    compute_excitation_map,
    compute_gradient_magnitude,
    compute_information_map,
    compute_shifted_cost,
    compute_terrain_maps,
    synthetic_bank,
)

NAN = np.nan


def _grid(
    depth: list[list[float]] | np.ndarray, dn: float = 1.0, de: float = 1.0
) -> BathymetryGrid:
    array = np.asarray(depth, dtype=np.float64)
    return BathymetryGrid(array, GridGeometry(array.shape[0], array.shape[1], dn, de))


def _loop_gradient(depth: np.ndarray, dn: float, de: float) -> np.ndarray:
    """Slow oracle of the documented stencil (central / one-sided / NaN)."""

    def derivative(values: np.ndarray, i: int, spacing: float) -> float:
        n = values.size
        if not np.isfinite(values[i]):
            return NAN
        before = values[i - 1] if i > 0 else NAN
        after = values[i + 1] if i < n - 1 else NAN
        if np.isfinite(before) and np.isfinite(after):
            return (after - before) / (2 * spacing)
        if np.isfinite(after):
            return (after - values[i]) / spacing
        if np.isfinite(before):
            return (values[i] - before) / spacing
        return NAN

    out = np.empty_like(depth)
    for r in range(depth.shape[0]):
        for c in range(depth.shape[1]):
            gn = derivative(depth[:, c], r, dn)
            ge = derivative(depth[r, :], c, de)
            out[r, c] = np.hypot(gn, ge)
    return out


def test_plane_gradient_uses_true_anisotropic_spacing() -> None:
    # depth = 0.3 m/m * north + 0.1 m/m * east on a 2 m (N) x 5 m (E) grid.
    geometry = GridGeometry(6, 7, 2.0, 5.0)
    north, east = np.meshgrid(geometry.north, geometry.east, indexing="ij")
    grid = BathymetryGrid(20.0 + 0.3 * north + 0.1 * east, geometry)
    np.testing.assert_allclose(compute_gradient_magnitude(grid), np.hypot(0.3, 0.1), rtol=1e-12)


def test_hand_computed_small_grid_with_nan_border() -> None:
    # Row 0 (south) is land on the west; column 3 is all NaN.
    depth = [
        [NAN, 10.0, 12.0, NAN],
        [8.0, 10.0, 14.0, NAN],
        [8.0, 12.0, 18.0, NAN],
    ]
    grid = _grid(depth, dn=2.0, de=1.0)
    g = compute_gradient_magnitude(grid)
    # (0,1): north forward (10-10)/2 = 0; east: west neighbour NaN -> forward (12-10)/1 = 2.
    assert g[0, 1] == pytest.approx(2.0)
    # (1,1): north central (12-10)/4 = 0.5; east central (14-8)/2 = 3.
    assert g[1, 1] == pytest.approx(np.hypot(0.5, 3.0))
    # (1,2): north central (18-12)/4 = 1.5; east: east neighbour NaN -> backward (14-10)/1 = 4.
    assert g[1, 2] == pytest.approx(np.hypot(1.5, 4.0))
    # (1,0): north: south neighbour NaN -> forward (8-8)/2 = 0; east forward (10-8) = 2.
    assert g[1, 0] == pytest.approx(2.0)
    assert np.isnan(g[0, 0])
    assert np.isnan(g[:, 3]).all()
    information = compute_information_map(grid)
    np.testing.assert_allclose(information, g / np.nanmax(g))
    assert np.nanmax(information) == 1.0


def test_isolated_cell_along_an_axis_is_nan() -> None:
    # The middle column is water between land columns: no east derivative -> NaN.
    grid = _grid([[NAN, 5.0, NAN], [NAN, 6.0, NAN], [NAN, 7.0, NAN]])
    assert np.isnan(compute_gradient_magnitude(grid)).all()
    with pytest.raises(InputError, match="finite depth gradient"):
        compute_information_map(grid)


def test_vectorised_gradient_matches_loop_oracle(rng: np.random.Generator) -> None:
    depth = 30.0 + rng.standard_normal((17, 23)).cumsum(axis=0)
    depth[rng.random(depth.shape) < 0.25] = NAN
    grid = _grid(depth, dn=3.7, de=1.3)
    np.testing.assert_allclose(
        compute_gradient_magnitude(grid), _loop_gradient(depth, 3.7, 1.3), rtol=1e-12
    )


def test_exponent_and_normalisation(rng: np.random.Generator) -> None:
    grid = _grid(rng.standard_normal((12, 9)), dn=2.0, de=3.0)
    m1 = compute_information_map(grid)
    np.testing.assert_allclose(compute_information_map(grid, exponent=2.5), m1**2.5)
    assert m1.max() == 1.0
    assert m1.min() >= 0.0
    # Scaling the depths leaves the normalised map unchanged.
    scaled = BathymetryGrid(7.0 * grid.depth, grid.geometry)
    np.testing.assert_allclose(compute_information_map(scaled), m1, rtol=1e-12)


def test_transpose_with_swapped_spacing_transposes_the_map(rng: np.random.Generator) -> None:
    depth = rng.standard_normal((8, 11))
    a = compute_information_map(_grid(depth, dn=2.0, de=5.0))
    b = compute_information_map(_grid(depth.T, dn=5.0, de=2.0))
    np.testing.assert_allclose(a, b.T, rtol=1e-12)


def test_flat_terrain_has_zero_information() -> None:
    grid = _grid([[5.0, 5.0, 5.0], [5.0, 5.0, NAN]])
    information = compute_information_map(grid)
    np.testing.assert_array_equal(information[np.isfinite(information)], 0.0)
    assert np.isnan(information[1, 2])


def test_excitation_block_mean_drops_remainder_and_propagates_nan() -> None:
    information = np.arange(35, dtype=np.float64).reshape(5, 7)
    excitation = compute_excitation_map(information, (2, 3))
    # Rows 0-1 / 2-3 (row 4 dropped), columns 0-2 / 3-5 (column 6 dropped).
    expected = np.array(
        [
            [np.mean([0, 1, 2, 7, 8, 9]), np.mean([3, 4, 5, 10, 11, 12])],
            [np.mean([14, 15, 16, 21, 22, 23]), np.mean([17, 18, 19, 24, 25, 26])],
        ]
    )
    np.testing.assert_allclose(excitation, expected)
    assert excitation.shape == GridGeometry(5, 7, 1.0, 1.0).coarsen(2, 3).shape
    information[3, 4] = NAN
    excitation = compute_excitation_map(information, (2, 3))
    assert np.isnan(excitation[1, 1])
    assert np.isfinite(excitation[[0, 0, 1], [0, 1, 0]]).all()
    # A NaN in a dropped remainder row does not matter.
    information[3, 4] = 0.0
    information[4, 0] = NAN
    assert np.isfinite(compute_excitation_map(information, (2, 3))).all()


@pytest.mark.parametrize("block", [(0, 2), (2, 0), (6, 1), (1, 8)])
def test_excitation_rejects_bad_blocks(block: tuple[int, int]) -> None:
    with pytest.raises(InputError):
        compute_excitation_map(np.zeros((5, 7)), block)


def test_cost_and_shift_values() -> None:
    excitation = np.array([[0.0, 1.0 / 3.0], [0.5, 1.0]])
    cost = compute_cost_map(excitation)
    np.testing.assert_allclose(cost, [[1.0, np.sqrt(3.0) / 2.0], [np.sqrt(0.5), 0.0]], atol=1e-15)
    shifted = compute_shifted_cost(cost, omega=2.0, weight=10.0)
    np.testing.assert_allclose(shifted, 2.0 + 10.0 * cost)
    assert np.isnan(compute_cost_map(np.array([NAN]))).all()


@pytest.mark.parametrize(
    "kwargs",
    [
        {"exponent": 0.0},
        {"exponent": -1.0},
        {"exponent": float("nan")},
        {"block": (0, 2)},
        {"block": (2, -1)},
        {"block": (2,)},
        {"omega": 0.0},
        {"omega": -3.0},
        {"weight": -0.1},
        {"weight": float("inf")},
        {"omega": 1.7e308},
        {"weight": 1e7},
        {"exponent": 1e300},
        {"exponent": 1e-300},
    ],
)
def test_map_parameters_validation(kwargs: dict[str, object]) -> None:
    with pytest.raises(InputError):
        MapParameters(**kwargs)  # type: ignore[arg-type]


def test_small_omega_is_accepted() -> None:
    assert MapParameters(omega=0.5).omega == 0.5


def test_terrain_maps_pipeline_on_the_bank() -> None:
    bank = synthetic_bank(seed=7)
    parameters = MapParameters(exponent=1.5, block=(3, 2), omega=2.0, weight=10.0)
    maps = compute_terrain_maps(bank, parameters)
    assert maps.cost_geometry == bank.geometry.coarsen(3, 2)
    assert maps.information.shape == bank.depth.shape
    assert maps.excitation.shape == maps.cost.shape == maps.shifted_cost.shape == (33, 100)
    np.testing.assert_allclose(
        maps.excitation, compute_excitation_map(maps.information, (3, 2)), rtol=1e-15
    )
    np.testing.assert_allclose(
        maps.shifted_cost, 2.0 + 10.0 * np.cos(0.5 * np.pi * maps.excitation)
    )
    assert maps.shifted_cost.min() >= 2.0
    assert maps.shifted_cost.max() <= 12.0
    assert maps.parameters is parameters
    # The terrain-rich crater flanks are cheaper than the flat plain in the far east.
    row, col = maps.cost_geometry.to_index(np.array([200.0, 200.0]), np.array([460.0, 760.0]))
    assert maps.cost[row[0], col[0]] < 0.8 < maps.cost[row[1], col[1]]
