"""Generic actuator layout: MEDUSA unchanged, a new layout is a new file, files fail clearly."""

from __future__ import annotations

import math
import re
import tomllib
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import tomli_w
from _derivatives import check_derivatives

from auvplan.errors import DataFormatError, InputError
from auvplan.io.vehicles import load_vehicle, packaged_vehicle_types
from auvplan.vehicle import (
    ActuatedVehicleParams,
    VehicleParams,
    actuator_roles,
    build_vehicle_model,
    fastest_mode,
    max_surge_acceleration,
    operating_state,
    reference_states,
    regulator_floor,
    steady_turn,
    trim_surge,
)

DATA = Path(__file__).parent / "data"
MEDUSA_DOCUMENT = tomllib.loads(
    resources.files("auvplan").joinpath("data", "vehicles", "medusa.toml").read_text()
)
REMUS_DOCUMENT = tomllib.loads(
    resources.files("auvplan").joinpath("data", "vehicles", "remus100.toml").read_text()
)


def _write(tmp_path: Path, document: dict[str, Any], name: str = "boat.toml") -> Path:
    path = tmp_path / name
    path.write_text(tomli_w.dumps(document), encoding="utf-8")
    return path


def _medusa_as_thruster_list() -> dict[str, Any]:
    """medusa.toml written out as a [[thruster]] list: ps at y = -l, sb at y = +l."""
    document = {
        k: v for k, v in MEDUSA_DOCUMENT.items() if k not in ("propulsion", "propeller", "motor")
    }
    propulsion = MEDUSA_DOCUMENT["propulsion"]
    half_spacing = propulsion["l"]["value"]
    document["thruster"] = [
        {
            "name": name,
            "x": {"value": -0.25, "unit": "m"},  # the x of an axial thruster does not matter
            "y": {"value": side * half_spacing, "unit": "m"},
            "axis": {"value": 0.0, "unit": "deg"},
            "n_max": propulsion["n_max"],
            "w_c": propulsion["w_c"],
            "propeller": MEDUSA_DOCUMENT["propeller"],
            "motor": MEDUSA_DOCUMENT["motor"],
        }
        for name, side in (("ps", -1.0), ("sb", 1.0))
    ]
    return document


def test_packaged_types() -> None:
    assert packaged_vehicle_types() == ("medusa", "remus100")
    assert isinstance(load_vehicle("medusa"), VehicleParams)
    assert isinstance(load_vehicle("remus100"), ActuatedVehicleParams)


@pytest.mark.parametrize("order", [None, 3])
def test_medusa_model_is_the_pre_generic_one(order: int | None) -> None:
    """Dynamics, power, thrust and currents equal those of the MEDUSA-only model to 1e-12.

    ``data/medusa_model_d9c7c1c.npz`` was evaluated with the model of commit d9c7c1c (before
    the generic actuator layout) at 24 random states in all four propeller quadrants.
    """
    reference = np.load(DATA / "medusa_model_d9c7c1c.npz")
    key = "full" if order is None else "order3"
    model = build_vehicle_model(load_vehicle("medusa"), propeller_order=order)
    pairs = list(zip(reference["states"], reference["inputs"], strict=True))
    xdot = np.array([np.asarray(model.dynamics(x, c)).ravel() for x, c in pairs])
    power = np.array([float(model.power(x, c)) for x, c in pairs])
    thrust = np.array([[float(v) for v in model.thrust_torque(x)] for x, _ in pairs])
    current = np.array([[float(v) for v in model.current(x)] for x, _ in pairs])
    np.testing.assert_allclose(xdot, reference[f"xdot_{key}"], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(power, reference[f"power_{key}"], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(thrust, reference[f"thrust_torque_{key}"], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(current, reference[f"current_{key}"], rtol=1e-12, atol=1e-12)


def test_twin_shorthand_equals_its_thruster_list(tmp_path: Path, rng: np.random.Generator) -> None:
    shorthand = build_vehicle_model(load_vehicle("medusa"))
    generic = build_vehicle_model(load_vehicle(_write(tmp_path, _medusa_as_thruster_list())))
    assert generic.state_names == shorthand.state_names
    assert generic.input_names == shorthand.input_names
    assert generic.state_limits == shorthand.state_limits
    for _ in range(20):
        x = np.r_[rng.uniform(-9, 9, 3), rng.uniform(-1.5, 1.5, 3), rng.uniform(-75, 75, 2)]
        c = rng.uniform(-2, 2, 2)
        np.testing.assert_allclose(
            np.asarray(generic.dynamics(x, c)),
            np.asarray(shorthand.dynamics(x, c)),
            rtol=1e-12,
            atol=1e-12,
        )
        assert float(generic.power(x, c)) == pytest.approx(float(shorthand.power(x, c)), rel=1e-12)


def _third_type() -> dict[str, Any]:
    """A new layout, only data: two stern thrusters, a bow tunnel thruster, a bow canard."""
    document = _medusa_as_thruster_list()
    document["name"] = "tunnel"
    tunnel = dict(document["thruster"][0])
    tunnel.update(
        name="bow",
        x={"value": 0.5, "unit": "m"},
        y={"value": 0.0, "unit": "m"},
        axis={"value": 90.0, "unit": "deg"},
        thrust_deduction={"value": 0.2, "unit": "1"},
    )
    document["thruster"].append(tunnel)
    document["control_surface"] = [
        {
            "name": "canard",
            "x": {"value": 0.4, "unit": "m"},
            "y": {"value": 0.0, "unit": "m"},
            "area": {"value": 0.01, "unit": "m^2"},
            "lift_slope": {"value": 3.0, "unit": "1/rad"},
            "drag_slope": {"value": 1.0, "unit": "1/rad^2"},
            "delta_max": {"value": 20.0, "unit": "deg"},
            "rate_max": {"value": 60.0, "unit": "deg/s"},
        }
    ]
    return document


def test_a_third_type_is_a_new_file(tmp_path: Path, rng: np.random.Generator) -> None:
    model = build_vehicle_model(load_vehicle(_write(tmp_path, _third_type())))
    assert model.state_names[6:] == ("n_ps", "n_sb", "n_bow", "delta_canard")
    assert model.input_names == ("c_ps", "c_sb", "c_bow", "c_canard")
    hull = model.vehicle.hull
    # the tunnel thruster at rest: (1 - t) T to starboard at x = 0.5 m, nothing in surge
    state = np.zeros(model.n_x)
    state[model.index("n_bow")] = 40.0
    xdot = np.asarray(model.dynamics(state, np.zeros(4))).ravel()
    thrust = float(model.thrust_torque(state)[2])
    assert thrust > 0.0
    assert xdot[3] == pytest.approx(0.0, abs=1e-12)
    assert xdot[4] == pytest.approx(0.8 * thrust / hull.m_v, rel=1e-12)
    assert xdot[5] == pytest.approx(0.5 * 0.8 * thrust / hull.m_r, rel=1e-12)
    # a bow canard turns the other way than a stern rudder: lift to port ahead of the centre
    state = operating_state(model, u=1.0, throttle=50.0)
    state[model.index("delta_canard")] = 0.2
    xdot = np.asarray(model.dynamics(state, np.zeros(4))).ravel()
    lift = 0.5 * hull.rho * 1.0 * 0.01 * 3.0 * 0.2
    assert xdot[5] * hull.m_r == pytest.approx(-0.4 * lift, rel=1e-9)  # r = 0: no hull moment
    roles = actuator_roles(model)
    assert roles.throttle.tolist() == [1.0, 1.0, 0.0, 0.0]  # the tunnel does not push forward
    assert roles.steering.tolist() == [0.0, 0.0, 0.0, pytest.approx(-math.radians(20))]
    assert not roles.thrust_steering
    assert regulator_floor(model).keys() == {"n_ps", "n_sb"}
    assert dict(model.state_limits)["delta_canard"] == pytest.approx(math.radians(20))
    assert steady_turn(model, 0.5, 0.05).state[model.index("delta_canard")] < 0.0
    points = [
        ("random", rng.uniform(-1, 1, model.n_x) * [9, 9, 3, 1.5, 0.3, 0.5, 70, 70, 70, 0.3],
         rng.uniform(-2, 2, 4))
        for _ in range(4)
    ]  # fmt: skip
    check_derivatives(model.dynamics, points, rng)


def test_optimiser_hooks_read_the_actuator_list() -> None:
    model = build_vehicle_model(load_vehicle("remus100"))
    xdot = np.asarray(
        model.dynamics(operating_state(model, throttle=1525 / 60), np.zeros(2))
    ).ravel()
    assert max_surge_acceleration(model) == pytest.approx(0.5 * xdot[3], rel=1e-12)
    states = reference_states(model, np.zeros((2, 3)), np.array([1.0, 1.5]), np.array([0.0, 0.1]))
    assert states[:, model.index("n_prop")] == pytest.approx(
        [trim_surge(model, 1.0).n, trim_surge(model, 1.5).n], rel=1e-3
    )
    np.testing.assert_array_equal(states[:, model.index("delta_rudder")], 0.0)
    assert fastest_mode(model) > 0.0


def _replace(document: dict[str, Any], path: str, value: Any) -> dict[str, Any]:
    """A copy of ``document`` with ``path`` (``a.b.0.c``) set, or deleted when value is None."""
    copy = tomllib.loads(tomli_w.dumps(document))
    *parents, last = path.split(".")
    node: Any = copy
    for key in parents:
        node = node[int(key)] if isinstance(node, list) else node[key]
    if value is None:
        del node[last]
    else:
        node[last] = value
    return copy


@pytest.mark.parametrize(
    ("path", "value", "error", "message"),
    [
        ("thruster.0.propeller.diameter", None, DataFormatError,
         "thruster[0].propeller.diameter is required"),
        ("thruster.0.n_max", {"value": 1525, "unit": "rad"}, DataFormatError,
         "thruster[0].n_max: unit 'rad' is not 'rev/s'"),
        ("thruster.0.wake_fraction", {"value": 1.5, "unit": "1"}, InputError,
         "thruster[0].wake_fraction: Input should be less than or equal to 0.9, got 1.5"),
        ("thruster.0.wake_fractoin", {"value": 0.1, "unit": "1"}, DataFormatError,
         "unknown key 'thruster[0].wake_fractoin'"),
        ("thruster.0.name", "Prop!", InputError, "thruster name must be lowercase"),
        ("thruster.0.propeller.model", "magic", DataFormatError,
         "thruster[0].propeller.model: must be 'four_quadrant' or 'linear', got 'magic'"),
        ("control_surface.0.delta_max", {"value": 120, "unit": "deg"}, InputError,
         "control_surface[0].delta_max: Input should be less than or equal to 1.57079"),
        ("control_surface.0.name", "prop", InputError,
         "actuator names must be unique, repeated: prop"),
        ("control_surface.0.area", None, DataFormatError,
         "control_surface[0].area is required"),
        ("hull.crossflow.strips", 2.5, DataFormatError,
         "hull.crossflow.strips: Input should be a valid integer, got 2.5"),
        ("hull.added_mass_coriolis", "no", DataFormatError,
         "hull.added_mass_coriolis: Input should be a valid boolean, got 'no'"),
        ("propulsion", {"l": {"value": 0.1, "unit": "m"}}, DataFormatError,
         "'[propulsion]' belongs to the twin-thruster shorthand"),
        ("thruster", [], DataFormatError, "missing section '[propulsion]'"),
        ("thruster", "prop", DataFormatError,
         "thruster: Input should be a valid tuple, got 'prop'"),
    ],
)  # fmt: skip
def test_bad_actuator_files_name_the_key_in_one_line(
    tmp_path: Path, path: str, value: Any, error: type[Exception], message: str
) -> None:
    document = _replace(REMUS_DOCUMENT, path, value)
    if path == "thruster" and value == []:
        del document["control_surface"]
    target = _write(tmp_path, document)
    with pytest.raises(error, match=re.escape(message)) as info:
        load_vehicle(target)
    assert str(info.value).startswith(f"{target}: ")
    assert "\n" not in str(info.value)


def test_control_surfaces_need_a_thruster_list(tmp_path: Path) -> None:
    document = dict(MEDUSA_DOCUMENT, control_surface=REMUS_DOCUMENT["control_surface"])
    with pytest.raises(DataFormatError, match=re.escape("[[control_surface]] needs [[thruster]]")):
        load_vehicle(_write(tmp_path, document))
