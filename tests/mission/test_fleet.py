"""FleetLayout: the one owner of how vehicles are stacked."""

from __future__ import annotations

import numpy as np

from auvplan.io.vehicles import load_vehicle
from auvplan.mission.fleet import FleetLayout
from auvplan.vehicle import build_vehicle_model, regulator_floor


def _layout(n: int = 3) -> FleetLayout:
    model = build_vehicle_model(load_vehicle("medusa"), propeller_order=3)
    return FleetLayout(names=tuple(f"v{i}" for i in range(n)), models=(model,) * n)


def test_stack_and_unstack_round_trip() -> None:
    layout = _layout()
    rng = np.random.default_rng(0)
    per_vehicle = [rng.standard_normal((5, 8)) for _ in range(3)]
    stacked = layout.stack(per_vehicle)
    assert stacked.shape == (5, layout.n_x) == (5, 24)
    for original, view in zip(per_vehicle, layout.unstack_states(stacked), strict=True):
        np.testing.assert_array_equal(original, view)
    inputs = rng.standard_normal((4, layout.n_u))
    assert [u.shape for u in layout.unstack_inputs(inputs)] == [(4, 2)] * 3
    np.testing.assert_array_equal(layout.stack(layout.unstack_inputs(inputs)), inputs)


def test_slices_and_gain_blocks_follow_the_models() -> None:
    layout = _layout()
    assert layout.state_slice(2) == slice(16, 24)
    assert layout.input_slice(1) == slice(2, 4)
    gains = np.arange(7 * 6 * 24, dtype=float).reshape(7, 6, 24)
    np.testing.assert_array_equal(layout.gains_of(gains, 1), gains[:, 2:4, 8:16])


def test_per_state_by_name_or_by_model() -> None:
    layout = _layout(2)
    model = layout.models[0]
    weights = layout.per_state({"psi": 3.0, "u": 2.0}, 0.5)
    assert weights[model.index("psi")] == weights[8 + model.index("psi")] == 3.0
    assert weights[model.index("north")] == 0.5
    floor = layout.per_state(regulator_floor, 0.0)
    assert floor[model.index("n_sb")] == regulator_floor(model)["n_sb"] > 0.0
    assert floor[8 + model.index("u")] == 0.0
