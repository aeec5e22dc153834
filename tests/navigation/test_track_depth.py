"""A track's depth profile reaches the sensors: the altimeter's range is the altitude per sample."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from _navigation_synthetic import featured_depth, make_grid, straight_track

from auvplan.errors import InputError
from auvplan.navigation import NavigationSettings, SensorModel
from auvplan.navigation.depth import depth_at
from auvplan.navigation.prediction import predict_error
from auvplan.navigation.sensors import beam_geometry


def test_sampled_track_interpolates_its_depth() -> None:
    track = straight_track((100.0, 100.0), 0.3, 1.0, 100.0)
    profiled = dataclasses.replace(track, depth=np.linspace(10.0, 30.0, track.time.size))
    sampled = profiled.sampled(2.5)
    assert sampled.depth is not None
    np.testing.assert_allclose(sampled.depth, 10.0 + 0.2 * sampled.time)
    assert track.sampled(2.5).depth is None
    with pytest.raises(InputError, match="track depth"):
        dataclasses.replace(track, depth=np.full(track.time.size, -1.0))


def test_a_constant_profile_is_the_sensors_constant_depth_and_altitude_matters() -> None:
    grid = make_grid(featured_depth)
    track = straight_track((200.0, 150.0), 0.7, 1.0, 600.0)
    multibeam = SensorModel.multibeam()
    at_depth = NavigationSettings(sensor=dataclasses.replace(multibeam, vehicle_depth=30.0))
    constant = predict_error(grid, track, at_depth)
    profiled_track = dataclasses.replace(track, depth=np.full(track.time.size, 30.0))
    profiled = predict_error(grid, profiled_track, NavigationSettings(sensor=multibeam))
    np.testing.assert_array_equal(profiled.covariance, constant.covariance)
    surface = predict_error(grid, track, NavigationSettings(sensor=multibeam))
    assert not np.allclose(surface.covariance, constant.covariance)


def test_beam_footprints_follow_the_altitude_of_each_sample() -> None:
    grid = make_grid(featured_depth)
    positions = np.array([[300.0, 300.0], [320.0, 310.0]])
    heading = np.array([0.0, 0.0])
    depth = np.array([10.0, 40.0])
    offsets, _ = beam_geometry(
        SensorModel.multibeam(), grid, positions, heading, vehicle_depth=depth
    )
    altitude = depth_at(grid, positions[:, 0], positions[:, 1]) - depth
    # the outermost beam (45 deg to starboard, heading north) lands one altitude to the east
    np.testing.assert_allclose(offsets[:, -1, 1], altitude, rtol=1e-12)
    np.testing.assert_allclose(offsets[:, -1, 0], 0.0, atol=1e-12)
