"""Speed and acceleration ranges derived from the vehicle model."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from auvplan.errors import InputError
from auvplan.io.vehicles import load_vehicle
from auvplan.vehicle import (
    build_vehicle_model,
    energy_per_metre,
    max_surge_acceleration,
    minimum_useful_speed,
    optimal_cruise_speed,
    regulator_floor,
    trim_surge,
)
from auvplan.vehicle.limits import ACCELERATION_SHARE, USEFUL_ENERGY_FACTOR

MODEL = build_vehicle_model(load_vehicle("medusa"), propeller_order=3)


def test_minimum_useful_speed_costs_twice_the_optimum_per_metre() -> None:
    speed = minimum_useful_speed(MODEL)
    cruise = optimal_cruise_speed(MODEL)
    assert 0.0 < speed < cruise.speed
    ratio = energy_per_metre(MODEL, speed) / cruise.energy_per_metre
    assert ratio == pytest.approx(USEFUL_ENERGY_FACTOR, rel=1e-5)
    assert energy_per_metre(MODEL, 0.9 * speed) > USEFUL_ENERGY_FACTOR * cruise.energy_per_metre


def test_max_surge_acceleration_is_a_share_of_full_thrust_from_rest() -> None:
    state = np.zeros(MODEL.n_x)
    for name in ("n_ps", "n_sb"):
        state[MODEL.index(name)] = MODEL.params.n_max
    full = float(np.asarray(MODEL.dynamics(state, np.zeros(MODEL.n_u)))[MODEL.index("u"), 0])
    assert max_surge_acceleration(MODEL) == pytest.approx(ACCELERATION_SHARE * full, rel=1e-9)


def test_regulator_floor_is_the_trim_of_the_minimum_useful_speed() -> None:
    floor = regulator_floor(MODEL)
    expected = trim_surge(MODEL, minimum_useful_speed(MODEL)).n
    assert floor == {"n_ps": pytest.approx(expected), "n_sb": pytest.approx(expected)}


def test_too_weak_vehicle_has_no_cruise_speed_but_a_clear_error() -> None:
    weak = dataclasses.replace(load_vehicle("medusa"), n_max=0.5)
    with pytest.raises(InputError, match="tops out at"):
        optimal_cruise_speed(build_vehicle_model(weak, propeller_order=3))
