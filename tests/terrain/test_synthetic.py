"""The embedded synthetic volcanic bank: size, relief, rim position, roughness spectrum."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from auvplan.errors import InputError
from auvplan.terrain.synthetic import _fractal_roughness, synthetic_bank


def test_default_bank_geometry_and_depth_range() -> None:
    bank = synthetic_bank()
    g = bank.geometry
    assert bank.depth.shape == (101, 201)
    assert (g.spacing_north, g.spacing_east, g.origin_north, g.origin_east) == (4.0, 4.0, 0, 0)
    assert g.north[-1] == 400.0
    assert g.east[-1] == 800.0
    assert np.isfinite(bank.depth).all()
    assert bank.depth.min() == pytest.approx(20.0)
    assert bank.depth.max() == pytest.approx(60.0)
    assert bank.projection is None
    assert "seed 7" in bank.name


def test_deterministic_per_seed() -> None:
    np.testing.assert_array_equal(synthetic_bank(seed=3).depth, synthetic_bank(seed=3).depth)
    assert not np.allclose(synthetic_bank(seed=3).depth, synthetic_bank(seed=4).depth)


@pytest.mark.parametrize("seed", [7, 1, 2, 3])
def test_eastern_rim_lies_where_the_demo_crosses(seed: int) -> None:
    bank = synthetic_bank(seed=seed)
    g = bank.geometry
    band = (g.east >= 380.0) & (g.east <= 560.0)
    for north in range(100, 301, 20):
        row = int(g.to_index(np.array([float(north)]), np.array([0.0]))[0][0])
        crest_east = g.east[band][np.argmin(bank.depth[row, band])]
        assert 405.0 <= crest_east <= 480.0, (north, crest_east)
        # The crest is a ridge: deeper both inside (crater) and outside (flank).
        assert bank.depth[row, g.east == crest_east - 60.0] > bank.depth[row, g.east == crest_east]
        assert bank.depth[row, g.east == crest_east + 80.0] > bank.depth[row, g.east == crest_east]


def test_flanks_deepen_away_from_the_bank() -> None:
    bank = synthetic_bank(seed=7)
    # Along the row through the crater centre, east of the eastern crest.
    row = 50
    east = bank.geometry.east
    means = [bank.depth[row, (east >= a) & (east < a + 60)].mean() for a in range(460, 760, 60)]
    assert all(np.diff(means) > 0.0), means


def test_terrain_is_rough_not_smooth() -> None:
    depth = synthetic_bank(seed=7).depth
    residual = depth - gaussian_filter(depth, 2.0)
    assert 0.05 < residual.std() < 2.0


def test_roughness_has_the_requested_power_law(rng: np.random.Generator) -> None:
    beta = 3.2
    field = _fractal_roughness((256, 256), 4.0, beta, rng)
    assert field.mean() == pytest.approx(0.0, abs=1e-12)
    assert field.std() == pytest.approx(1.0)
    power = np.abs(np.fft.fft2(field)) ** 2
    k = np.hypot(*np.meshgrid(np.fft.fftfreq(256, 4.0), np.fft.fftfreq(256, 4.0), indexing="ij"))
    bins = np.geomspace(k[k > 0].min() * 2, k.max() * 0.6, 12)
    centres, levels = [], []
    for low, high in itertools.pairwise(bins):
        ring = (k >= low) & (k < high)
        centres.append(np.sqrt(low * high))
        levels.append(power[ring].mean())
    slope = np.polyfit(np.log(centres), np.log(levels), 1)[0]
    assert slope == pytest.approx(-beta, abs=0.25)


@pytest.mark.parametrize(
    "kwargs",
    [{"spacing": 0.0}, {"extent_north": -1.0}, {"depth_range": (60.0, 20.0)}, {"spacing": 100.0}],
)
def test_bad_arguments(kwargs: dict[str, object]) -> None:
    with pytest.raises(InputError):
        synthetic_bank(**kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize("seed", [-1, 1.5, True, "7"])
def test_seed_must_be_a_non_negative_integer(seed: object) -> None:
    with pytest.raises(InputError, match="seed must be an integer >= 0"):
        synthetic_bank(seed=seed)  # type: ignore[arg-type]
