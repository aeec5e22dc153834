"""The information reward: exact derivatives on the stacked state, and its sign and scale."""

from __future__ import annotations

import numpy as np

from auvplan.io.vehicles import load_vehicle
from auvplan.mission.fleet import FleetLayout
from auvplan.mission.reward import information_reward
from auvplan.terrain import MapParameters, compute_terrain_maps, synthetic_bank
from auvplan.vehicle import build_vehicle_model


def _reward_and_states() -> tuple:
    model = build_vehicle_model(load_vehicle("medusa"), propeller_order=3)
    layout = FleetLayout(("a", "b"), (model, model))
    maps = compute_terrain_maps(synthetic_bank(seed=3), MapParameters())
    reward = information_reward(layout, maps, 40.0)
    rng = np.random.default_rng(0)
    states = rng.normal(size=(25, layout.n_x))
    for i in range(2):
        rows = layout.state_slice(i)
        states[:, rows.start + model.index("north")] = rng.uniform(50, 350, 25)
        states[:, rows.start + model.index("east")] = rng.uniform(50, 750, 25)
    return reward, states, maps


def test_derivatives_match_finite_differences() -> None:
    reward, states, _ = _reward_and_states()
    assert reward is not None
    value, gradient, hessian = reward.derivatives(states)
    np.testing.assert_allclose(value, reward.values(states))
    step = 1e-4
    for column in range(states.shape[1]):
        shift = np.zeros(states.shape[1])
        shift[column] = step
        up, down = reward.derivatives(states + shift), reward.derivatives(states - shift)
        np.testing.assert_allclose((up[0] - down[0]) / (2 * step), gradient[:, column], atol=1e-6)
        np.testing.assert_allclose((up[1] - down[1]) / (2 * step), hessian[:, :, column], atol=1e-6)


def test_reward_is_minus_weight_times_the_surface_sum_and_off_when_weight_is_zero() -> None:
    reward, states, maps = _reward_and_states()
    assert reward is not None
    north, east = reward.positions[:, 0], reward.positions[:, 1]
    surface = sum(
        reward.surface.evaluate(states[:, n], states[:, e])[:, 0]
        for n, e in zip(north, east, strict=True)
    )
    np.testing.assert_allclose(reward.values(states), -40.0 * surface)
    assert np.all(reward.values(states) <= 0.0)  # information is >= 0
    model = build_vehicle_model(load_vehicle("medusa"), propeller_order=3)
    assert information_reward(FleetLayout(("a",), (model,)), maps, 0.0) is None
