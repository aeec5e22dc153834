"""Dead reckoning: the simulated drift has the CEP it is configured with; the filter's noise."""

from __future__ import annotations

import numpy as np
import pytest

from auvplan.errors import InputError
from auvplan.navigation import (
    DeadReckoningModel,
    dead_reckon,
    process_noise_sigma,
    simulate_odometry,
)


def test_straight_leg_drift_has_the_configured_cep(rng: np.random.Generator) -> None:
    model = DeadReckoningModel(drift_fraction=0.02, velocity_noise=0.0)
    steps = np.tile([0.6, 0.8], (100, 1))  # 100 m north-north-east
    ends = np.array(
        [
            dead_reckon(np.zeros(2), simulate_odometry(model, steps, np.ones(100), rng))[-1]
            for _ in range(4000)
        ]
    )
    radius = np.linalg.norm(ends - steps.sum(axis=0), axis=1)
    # CEP = median radial error = drift * distance (5 % sampling tolerance at 4000 runs)
    assert np.median(radius) == pytest.approx(0.02 * 100.0, rel=0.05)
    # isotropic: along- and across-track errors have the same spread
    along = (ends - steps.sum(axis=0)) @ np.array([0.6, 0.8])
    across = (ends - steps.sum(axis=0)) @ np.array([-0.8, 0.6])
    assert np.std(along) == pytest.approx(np.std(across), rel=0.1)


def test_white_velocity_noise_is_a_random_walk(rng: np.random.Generator) -> None:
    model = DeadReckoningModel(drift_fraction=0.0, velocity_noise=0.1)
    steps = np.zeros((400, 2))
    ends = np.array(
        [simulate_odometry(model, steps, np.full(400, 0.5), rng).sum(axis=0) for _ in range(2000)]
    )
    assert np.std(ends, axis=0) == pytest.approx(np.full(2, 0.1 * 0.5 * np.sqrt(400)), rel=0.06)


def test_process_noise_follows_distance_above_the_floor() -> None:
    model = DeadReckoningModel(drift_fraction=0.01, noise_multiplier=2.0, noise_floor=0.25)
    sigma = process_noise_sigma(model, np.array([[0.0, 0.0], [30.0, 40.0]]))
    assert sigma[0] == 0.25
    assert sigma[1] == pytest.approx(2.0 * 0.01 * 50.0 / np.sqrt(2.0 * np.log(2.0)))


@pytest.mark.parametrize("field", ["drift_fraction", "velocity_noise", "noise_floor"])
def test_negative_or_nan_parameters_are_refused(field: str) -> None:
    for value in (-1.0, float("nan")):
        with pytest.raises(InputError, match=field):
            DeadReckoningModel(**{field: value})
