"""Independent plan checks: the reference model agrees with the planner's; corruption is caught."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from auvplan.cli.main import main
from auvplan.io.results import write_trajectories_csv
from auvplan.scenarios import check, generate
from auvplan.scenarios._model import ReferenceModel
from auvplan.scenarios._vehicle_file import read_reference_model

DT = 0.5
N_STEPS = 120
SAFETY_RADIUS = 5.0


@pytest.mark.parametrize(
    ("vehicle", "order"), [("medusa", 0), ("medusa", 3), ("medusa", None), ("remus100", None)]
)
def test_independent_model_matches_the_planner_model(vehicle: str, order: int | None) -> None:
    from auvplan.io.vehicles import load_vehicle  # the only use of the planner's model
    from auvplan.vehicle import build_vehicle_model

    planner = build_vehicle_model(load_vehicle(vehicle), propeller_order=order)
    independent = read_reference_model(vehicle, propeller_order=order)
    assert independent.state_names == planner.state_names
    assert independent.input_names == planner.input_names
    assert independent.limits == pytest.approx(dict(planner.state_limits), rel=1e-12)
    rng = np.random.default_rng(11)
    limits = np.array([limit for _, limit in planner.state_limits])
    for _ in range(20):
        state = np.concatenate(
            [
                rng.uniform(-500.0, 500.0, 2),
                rng.uniform(-4.0, 4.0, 1),
                rng.uniform(-1.5, 1.5, 1),
                rng.uniform(-0.5, 0.5, 2),
                rng.uniform(-1.0, 1.0, limits.size) * limits,
            ]
        )
        command = rng.uniform(-2.0, 2.0, planner.n_u)
        expected = np.asarray(planner.dynamics(state, command)).ravel()
        np.testing.assert_allclose(
            independent.derivative(state, command), expected, rtol=1e-9, atol=1e-9
        )
    at_rest = np.zeros(planner.n_x)
    np.testing.assert_allclose(
        independent.derivative(at_rest, np.zeros(planner.n_u)),
        np.asarray(planner.dynamics(at_rest, np.zeros(planner.n_u))).ravel(),
        atol=1e-12,
    )


def _fly(model: ReferenceModel, start: np.ndarray, inputs: np.ndarray) -> np.ndarray:
    """States at every step, each step integrated with its input held."""
    states = [start]
    for command in inputs:
        step = solve_ivp(
            lambda _t, x, c=command: model.derivative(x, c),
            (0.0, DT),
            states[-1],
            method="DOP853",
            rtol=1e-12,
            atol=1e-12,
        )
        states.append(step.y[:, -1])
    return np.array(states)


def _write_plan(
    folder: Path,
    tracks: dict[str, tuple[np.ndarray, np.ndarray]],
    mission_extra: str = "",
    types: dict[str, str] | None = None,
) -> Path:
    """A plan output folder (summary.json, trajectories.csv) and its mission file.

    ``types`` maps vehicle names to their types (default ``medusa``).
    """
    types = {name: (types or {}).get(name, "medusa") for name in tracks}
    folder.mkdir(parents=True, exist_ok=True)
    mission = folder / "mission.toml"
    mission.write_text(f"[fleet]\nsafety_radius_m = {SAFETY_RADIUS}\n{mission_extra}")
    models = [read_reference_model(types[name], propeller_order=3) for name in tracks]
    with (folder / "trajectories.csv").open("w", newline="", encoding="utf-8") as handle:
        write_trajectories_csv(
            handle,
            list(tracks),
            DT * np.arange(N_STEPS + 1),
            [states for states, _ in tracks.values()],
            [inputs for _, inputs in tracks.values()],
            [np.full(N_STEPS + 1, 40.0) for _ in tracks],
            state_names=[model.state_names for model in models],
            input_names=[model.input_names for model in models],
        )
    summary = {
        "mission": str(mission),
        "fleet": {"safety_radius_m": SAFETY_RADIUS},
        "solver": {"dt": DT, "propeller_order": 3},
        "vehicles": [
            {
                "name": name,
                "type": types[name],
                "goal": {"north": states[-1, 0], "east": states[-1, 1], "heading_rad": 0.0},
            }
            for name, (states, _) in tracks.items()
        ],
        "optimization": {"status": "CONVERGED"},
    }
    (folder / "summary.json").write_text(json.dumps(summary))
    return folder


@pytest.fixture(scope="module")
def tracks() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Two MEDUSAs 30 m apart, cruising north and weaving gently."""
    model = read_reference_model("medusa", propeller_order=3)
    time = DT * np.arange(N_STEPS)
    inputs = 0.02 * np.column_stack([np.sin(time / 8.0), -np.sin(time / 8.0)])
    result = {}
    for name, east in (("blue", 100.0), ("green", 130.0)):
        start = np.array([50.0, east, 0.0, 0.5, 0.0, 0.0, 25.0, 25.0])
        result[name] = (_fly(model, start, inputs), inputs)
    return result


@pytest.fixture(scope="module")
def remus_track() -> tuple[np.ndarray, np.ndarray]:
    """A REMUS 100 cruising north at 1.4 m/s, 40 m east of blue, weaving on its rudder."""
    model = read_reference_model("remus100", propeller_order=3)
    time = DT * np.arange(N_STEPS)
    inputs = np.column_stack([np.zeros(N_STEPS), 0.002 * np.sin(time / 8.0)])
    start = np.array([50.0, 60.0, 0.0, 1.4, 0.0, 0.0, 19.0, 0.0])
    return _fly(model, start, inputs), inputs


def test_mixed_fleet_plan_is_read_by_each_vehicle_s_own_model(
    tmp_path: Path, tracks: dict, remus_track: tuple[np.ndarray, np.ndarray]
) -> None:
    folder = _write_plan(tmp_path, {**tracks, "red": remus_track}, types={"red": "remus100"})
    header = (folder / "trajectories.csv").read_text().splitlines()[0].split(",")
    assert header[-7:] == ["n_prop", "delta_rudder", "c_ps", "c_sb", "c_prop", "c_rudder", "power"]
    report = check(folder)
    assert report.success, report.failures
    assert report.max_position_defect_m["red"] < 1e-6
    assert set(report.max_state_defect["red"]) >= {"n_prop", "delta_rudder"}
    assert 0.0 < report.max_limit_fraction["red"]["delta_rudder"] < 1.0
    assert set(report.max_limit_fraction["blue"]) == {"n_ps", "n_sb"}


def test_limit_exceeded_at_the_last_sample_fails(
    tmp_path: Path, tracks: dict, remus_track: tuple[np.ndarray, np.ndarray]
) -> None:
    model = read_reference_model("remus100", propeller_order=3)
    states, inputs = remus_track
    inputs = inputs.copy()
    inputs[-1, 1] = 1.0  # the rudder swings 0.5 s x 150 deg/s x tanh(1) = 57 deg > 15 deg
    flown = states.copy()
    flown[-1] = _fly(model, states[-2], inputs[-1:])[-1]
    report = check(_write_plan(tmp_path, {"red": (flown, inputs)}, types={"red": "remus100"}))
    assert {failure.kind for failure in report.failures} == {"state_limit"}
    assert report.max_limit_fraction["red"]["delta_rudder"] > 3.0
    assert report.max_position_defect_m["red"] < 1e-6


def _kinds(folder: Path) -> set[str]:
    return {failure.kind for failure in check(folder).failures}


def test_consistent_plan_passes(tmp_path: Path, tracks: dict) -> None:
    extra = '[[comm]]\npair = ["blue", "green"]\nmax_range_m = 40.0\n'
    report = check(_write_plan(tmp_path, tracks, extra))
    assert report.success, report.failures
    assert max(report.max_position_defect_m.values()) < 1e-6
    assert 29.0 < report.min_separation_m["blue / green"] < 31.0
    assert report.max_comm_distance_m["blue / green"] < 40.0
    assert max(report.arrival_error_m.values()) == 0.0
    assert report.to_dict()["success"] is True


def test_moved_sample_gives_a_large_defect(tmp_path: Path, tracks: dict) -> None:
    states, inputs = tracks["blue"]
    moved = states.copy()
    moved[60, 0] += 0.3
    report = check(_write_plan(tmp_path, {**tracks, "blue": (moved, inputs)}))
    assert {failure.kind for failure in report.failures} == {"defect"}
    assert report.max_position_defect_m["blue"] == pytest.approx(0.3, rel=1e-3)
    assert report.max_position_defect_m["green"] < 1e-6


def test_vehicles_pushed_together_fail_separation(tmp_path: Path, tracks: dict) -> None:
    green, green_inputs = tracks["green"]
    closer = green.copy()
    closer[:, 1] -= 30.0 - 8.0  # a translation: the dynamics still hold, only 8 m apart
    report = check(_write_plan(tmp_path, {**tracks, "green": (closer, green_inputs)}))
    assert {failure.kind for failure in report.failures} == {"separation"}
    assert report.min_separation_m["blue / green"] == pytest.approx(8.0, abs=0.5)


def test_dip_between_samples_is_caught(tmp_path: Path, tracks: dict) -> None:
    blue, blue_inputs = tracks["blue"]
    green_inputs = tracks["green"][1]
    # green crosses blue's track between two samples: both nodes 10.5 m away, the middle not
    crossing = blue.copy()
    crossing[:, 1] = blue[:, 1] + np.where(np.arange(blue.shape[0]) <= 60, -10.5, 10.5)
    crossing[:, 0] = blue[:, 0]
    report = check(
        _write_plan(tmp_path, {"blue": (blue, blue_inputs), "green": (crossing, green_inputs)})
    )
    assert "separation" in {failure.kind for failure in report.failures}
    assert report.min_separation_m["blue / green"] < 10.0


@pytest.mark.parametrize(
    "obstacle",
    [
        "[[obstacle]]\ncenter = {{ north = {n}, east = {e} }}\nradius_m = 4.0\n",
        "[[obstacle]]\npolygon = [[{n}, {e}], [{n}, {e2}], [{n2}, {e2}]]\n",
    ],
)
def test_obstacle_on_the_track_fails(tmp_path: Path, tracks: dict, obstacle: str) -> None:
    blue = tracks["blue"][0]
    north, east = blue[40, :2]
    text = obstacle.format(n=north, e=east + 2.0, e2=east + 6.0, n2=north + 4.0)
    assert _kinds(_write_plan(tmp_path, tracks, text)) == {"obstacle"}
    far = obstacle.format(n=north, e=east - 40.0, e2=east - 60.0, n2=north + 20.0)  # west
    assert _kinds(_write_plan(tmp_path / "far", tracks, far)) == set()


def test_comm_range_and_arrival_fail(tmp_path: Path, tracks: dict) -> None:
    extra = '[[comm]]\npair = ["blue", "green"]\nmax_range_m = 25.0\n'
    folder = _write_plan(tmp_path, tracks, extra)
    summary = json.loads((folder / "summary.json").read_text())
    summary["vehicles"][0]["goal"]["north"] += 2.0
    (folder / "summary.json").write_text(json.dumps(summary))
    report = check(folder)
    assert {failure.kind for failure in report.failures} == {"comm", "arrival"}
    assert report.arrival_error_m["blue"] == pytest.approx(2.0)


@pytest.mark.slow
def test_real_plan_of_a_generated_scenario_passes(tmp_path: Path) -> None:
    scenario = generate(3, data_dir=tmp_path / "no_grids")
    assert scenario.terrain == "bank"
    mission = scenario.write(tmp_path / "scenario")
    code = main(["-q", "plan", str(mission), "-o", str(tmp_path / "out"), "--no-figures"])
    assert code == 0
    report = check(tmp_path / "out", mission=mission)
    assert report.success, report.failures


def test_scenarios_verb_writes_one_folder_per_seed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("AUVPLAN_SHARED_DATA", str(tmp_path))  # empty: no real grids
    code = main(["-q", "scenarios", "3", "5", "-o", str(tmp_path)])
    assert code == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["seed_0003", "seed_0005"]
    expected = generate(5, data_dir=tmp_path).toml(tmp_path / "seed_0005")
    assert (tmp_path / "seed_0005" / "mission.toml").read_text() == expected
    with pytest.raises(SystemExit) as error:
        main(["scenarios", "x", "-o", str(tmp_path)])
    assert error.value.code == 2
