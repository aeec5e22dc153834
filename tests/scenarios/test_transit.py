"""The transit kind of the scenario family, and the reliability kind left as it was."""

from __future__ import annotations

import contextlib
import hashlib
import io
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from auvplan.cli.main import main
from auvplan.errors import InputError
from auvplan.io.bathymetry import read_bathymetry
from auvplan.mission.config import load_mission
from auvplan.mission.pipeline import run_preplan
from auvplan.scenarios import Scenario, generate
from auvplan.scenarios._plain import (
    FEATURE_OFFSET_RANGE_M,
    FEATURE_SLOPE_RANGE,
    MAX_NODES,
    MAX_REGIONAL_SLOPE,
    MAX_UNDULATION_SLOPE,
    SPACING_RANGE_M,
)
from auvplan.scenarios.transit import (
    DISTANCE_RANGE_M,
    FLEET_SIZES,
    HORIZON_RANGE_S,
    LINE_SPEED_RANGE,
)
from auvplan.terrain import compute_gradient_magnitude

NO_DATA = Path("/nonexistent")
#: The first 40 transit seeds without the real grids (plains only), generated once.
SEEDS = range(40)
#: Slope [m/m] above which a cell counts as rough (the plain stays below 0.6 %).
ROUGH_SLOPE = 0.02
#: Seeds whose pre-planning takes about a second: flat (1 vehicle), features (1), Balanus.
FAST_SEEDS = (3, 14)
REAL_SEED = 8

#: SHA-256 of the reliability missions' text (real-grid paths as <data>) as before the transit
#: kind, and the generated terrain's shape, spacing and depth range [m].
RELIABILITY_NO_DATA = {
    0: (
        "6ce5e026d1a2c2dad8d7e726c5c283144613fcfec9aa2cc6e22589ce97f269fb",
        (360, 337, 8.0, 56.8, 210.4),
    ),
    1: (
        "c3eb2b73562690f6fcb1d78d712590aa40bf080cd55624f80cd37ee551ee6f88",
        (395, 317, 5.0, 47.7, 131.4),
    ),
    3: ("680e08535c2f2151d89759ec3579940f414aa5ac5bccc07839316d1c10fd2af1", None),
    4: (
        "b224ac477fd2452d6fd9049e2661fc530eee00c1dae96ae66f6cdbf76e917651",
        (350, 398, 19.0, 33.9, 224.6),
    ),
}
RELIABILITY_WITH_DATA = {
    0: "3ae1437da48a3ea203e6d936e81eb79ce3434ed87ecb43705c13b9f510695851",
    1: "2be44032d3094bb87467bd0c3064779b05b63915da86fc26edb68518ce4c0bd1",
    2: "3f18e1fa9b3f8e37ff791de615d2ed2111b1678ef0c16123c00d80d0b8d23157",
    5: "4af4fa9f1f6fc47023fda03f87f7080ec2b6d09aa7b90f2d3abae705e6652f1a",
}


@pytest.fixture(scope="module")
def plains() -> dict[int, Scenario]:
    return {seed: generate(seed, data_dir=NO_DATA, kind="transit") for seed in SEEDS}


def _digest(scenario: Scenario, data_dir: Path | None = None) -> str:
    text = scenario.toml()
    if data_dir is not None:
        text = text.replace(str(data_dir.resolve()), "<data>")
    return hashlib.sha256(text.encode()).hexdigest()


def _lines(scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """Starts and goals (north, east) [m] of a scenario on a plain."""
    vehicles = scenario.mission["vehicle"]
    starts = np.array([[v["start"]["north"], v["start"]["east"]] for v in vehicles])
    goals = np.array([[v["goal"]["north"], v["goal"]["east"]] for v in vehicles])
    return starts, goals


def _preplan_exit_code(mission: Path, output: Path) -> tuple[int, str]:
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr):
        code = main(
            ["-q", "plan", str(mission), "-o", str(output), "--stage", "preplan", "--no-figures"]
        )
    return code, stderr.getvalue()


@pytest.mark.parametrize("seed", sorted(RELIABILITY_NO_DATA))
def test_reliability_kind_unchanged_without_real_grids(seed: int) -> None:
    digest, terrain = RELIABILITY_NO_DATA[seed]
    scenario = generate(seed, data_dir=NO_DATA)
    assert _digest(scenario) == digest
    assert generate(seed, data_dir=NO_DATA, kind="reliability").toml() == scenario.toml()
    assert scenario.kind == "reliability"
    assert scenario.features is None
    if terrain is not None:
        grid = scenario.synthetic_terrain
        assert grid is not None
        depths = (round(float(grid.depth.min()), 3), round(float(grid.depth.max()), 3))
        assert (*grid.depth.shape, grid.geometry.spacing_north, *depths) == terrain


@pytest.mark.parametrize("seed", sorted(RELIABILITY_WITH_DATA))
def test_reliability_kind_unchanged_with_real_grids(seed: int, bathymetry_dir: Path) -> None:
    scenario = generate(seed, data_dir=bathymetry_dir)
    assert _digest(scenario, bathymetry_dir) == RELIABILITY_WITH_DATA[seed]


def test_unknown_kind_is_refused() -> None:
    with pytest.raises(InputError, match="transit"):
        generate(0, data_dir=NO_DATA, kind="survey")


@pytest.mark.parametrize("seed", [0, 3, REAL_SEED])
def test_same_seed_gives_identical_transit(seed: int, bathymetry_dir: Path) -> None:
    first = generate(seed, data_dir=bathymetry_dir, kind="transit")
    second = generate(seed, data_dir=bathymetry_dir, kind="transit")
    assert first.toml() == second.toml()
    assert first.description == second.description
    assert first.feature_offsets_m == second.feature_offsets_m
    if first.synthetic_terrain is not None:
        assert second.synthetic_terrain is not None
        np.testing.assert_array_equal(first.synthetic_terrain.depth, second.synthetic_terrain.depth)


def test_transit_seeds_differ(plains: dict[int, Scenario]) -> None:
    assert len({scenario.toml() for scenario in plains.values()}) == len(plains)


def test_transit_ranges(plains: dict[int, Scenario]) -> None:
    for seed, scenario in plains.items():
        mission = scenario.mission
        assert scenario.kind == "transit"
        assert scenario.features in {"flat", "offset"}  # no real grid without the data folder
        horizon = mission["fleet"]["horizon_s"]
        assert HORIZON_RANGE_S[0] <= horizon <= HORIZON_RANGE_S[1]
        assert horizon % 10 == 0
        assert mission["solver"]["dt_s"] == 2.0
        assert FLEET_SIZES[0] <= scenario.n_vehicles == len(mission["vehicle"]) <= FLEET_SIZES[1]
        assert "obstacle" not in mission
        assert "comm" not in mission
        distance = scenario.distance_m
        assert distance is not None
        assert DISTANCE_RANGE_M[0] <= distance <= DISTANCE_RANGE_M[1]
        assert LINE_SPEED_RANGE[0] <= distance / horizon <= LINE_SPEED_RANGE[1]
        starts, goals = _lines(scenario)
        lines = goals - starts
        np.testing.assert_allclose(np.hypot(*lines.T), distance, atol=0.02)
        radius = mission["fleet"]["safety_radius_m"]
        for points in (starts, goals):
            gaps = np.hypot(*(points[:, None, :] - points[None, :, :]).transpose(2, 0, 1))
            gaps[np.diag_indices(len(points))] = np.inf
            assert gaps.min() >= 2.0 * radius + max(radius, 5.0)
        bearing = math.degrees(math.atan2(lines[0, 1], lines[0, 0]))
        for vehicle in mission["vehicle"]:
            for end in ("start", "goal"):
                turn = (vehicle[end]["heading_deg"] - bearing + 180.0) % 360.0 - 180.0
                assert abs(turn) < 0.1, seed
            assert vehicle["start"]["speed"] in (
                0.0,
                round(0.05 * round(distance / horizon / 0.05), 2),
            )
        grid = scenario.synthetic_terrain
        assert grid is not None
        assert max(grid.depth.shape) <= MAX_NODES
        assert SPACING_RANGE_M[0] <= grid.geometry.spacing_north
        text = scenario.description
        assert text.startswith("transit over plain")
        assert f"distance {distance / 1e3:.2f} km" in text
        assert f"horizon {horizon / 3600:.2f} h" in text
        assert f"{scenario.n_vehicles} vehicle" in text
    shares = [scenario.features for scenario in plains.values()]
    assert 0.1 <= shares.count("flat") / len(shares) <= 0.35


def test_flat_seeds_are_flat(plains: dict[int, Scenario]) -> None:
    flat = [scenario for scenario in plains.values() if scenario.flat]
    assert len(flat) >= 4
    for scenario in flat:
        assert "flat" in scenario.description
        assert scenario.relief == ()
        assert scenario.feature_offsets_m == ()
        grid = scenario.synthetic_terrain
        assert grid is not None
        assert float(np.max(compute_gradient_magnitude(grid))) <= MAX_REGIONAL_SLOPE + 1e-9
        assert float(grid.depth.min()) >= 40.0
        assert float(grid.depth.max()) <= 150.0


def test_features_lie_at_their_offset_on_one_side(plains: dict[int, Scenario]) -> None:
    featured = [scenario for scenario in plains.values() if scenario.features == "offset"]
    assert len(featured) >= 10
    for scenario in featured:
        grid = scenario.synthetic_terrain
        assert grid is not None
        spacing = grid.geometry.spacing_north
        north, east = np.meshgrid(grid.geometry.north, grid.geometry.east, indexing="ij")
        slope = compute_gradient_magnitude(grid)
        rough = slope > ROUGH_SLOPE
        starts, goals = _lines(scenario)
        direction = (goals[0] - starts[0]) / np.hypot(*(goals[0] - starts[0]))
        across = np.array([-direction[1], direction[0]])
        lanes = starts @ across  # across coordinate of each line
        coordinate = north * across[0] + east * across[1]
        near_any = np.zeros_like(rough)
        assert len(scenario.relief) in (1, 2)
        assert scenario.feature_offsets_m == tuple(f.offset_m for f in scenario.relief)
        assert len({feature.side for feature in scenario.relief}) == 1  # all on one side
        for feature in scenario.relief:
            assert FEATURE_OFFSET_RANGE_M[0] <= feature.offset_m <= FEATURE_OFFSET_RANGE_M[1]
            assert 0.04 <= feature.max_slope <= FEATURE_SLOPE_RANGE[1] + 0.01, scenario.seed
            assert f"at offset {feature.offset_m:.0f} m" in scenario.description
            near = feature.footprint_distance(north, east) <= 1.5 * spacing
            near_any |= near
            mine = rough & near
            assert mine.sum() >= 20, scenario.seed
            # beyond the nearest line on the feature's side, by the stated offset
            beyond = feature.side * coordinate[mine] - np.max(feature.side * lanes)
            assert beyond.min() >= feature.offset_m - 1.5 * spacing, scenario.seed
            assert beyond.min() <= feature.offset_m + 0.5 * feature.radius_m, scenario.seed
            assert 0.8 * feature.max_slope <= slope[near].max() <= feature.max_slope + 0.01
        # the plain away from the features stays as flat as a featureless one
        assert slope[~near_any].max() <= MAX_REGIONAL_SLOPE + MAX_UNDULATION_SLOPE + 1e-6
        assert not rough[~near_any].any()


def test_write_makes_a_self_contained_transit_folder(
    tmp_path: Path, plains: dict[int, Scenario]
) -> None:
    scenario = plains[FAST_SEEDS[1]]
    path = scenario.write(tmp_path / "a")
    document = tomllib.loads(path.read_text(encoding="utf-8"))
    assert document["terrain"]["file"] == "terrain.nc"
    written = read_bathymetry(tmp_path / "a" / "terrain.nc")
    assert scenario.synthetic_terrain is not None
    np.testing.assert_array_equal(written.depth, scenario.synthetic_terrain.depth)


@pytest.mark.parametrize("seed", FAST_SEEDS)
def test_preplan_accepts_transit_mission(seed: int, tmp_path: Path) -> None:
    mission = generate(seed, data_dir=NO_DATA, kind="transit").write(tmp_path / "scenario")
    code, stderr = _preplan_exit_code(mission, tmp_path / "out")
    assert code == 0, stderr


def test_real_grid_transit_in_water_with_clear_lines(tmp_path: Path, bathymetry_dir: Path) -> None:
    scenario = generate(REAL_SEED, data_dir=bathymetry_dir, kind="transit")
    assert scenario.features == "real"
    assert scenario.terrain in {"lisbon", "balanus"}
    assert scenario.synthetic_terrain is None
    assert "real terrain" in scenario.description
    for vehicle in scenario.mission["vehicle"]:
        assert {"lat", "lon"} <= set(vehicle["start"])
        assert {"lat", "lon"} <= set(vehicle["goal"])
    config = load_mission(scenario.write(tmp_path / "scenario"))
    preplan = run_preplan(config)  # resolves lat/lon poses exactly as `plan` does
    depth, geometry = preplan.bathymetry.depth, preplan.bathymetry.geometry
    for start, goal in zip(preplan.starts[:, :2], preplan.goals[:, :2], strict=True):
        assert np.hypot(*(goal - start)) == pytest.approx(scenario.distance_m, abs=1.0)
        track = start + np.linspace(0.0, 1.0, 200)[:, None] * (goal - start)
        rows, cols = geometry.to_index(track[:, 0], track[:, 1])
        assert np.all(np.isfinite(depth[rows, cols]))
        for point in (start, goal):  # away from the edge
            row, col = geometry.to_index(point[:1], point[1:])
            assert 1 <= row[0] < geometry.n_rows - 1
            assert 1 <= col[0] < geometry.n_cols - 1


def test_without_real_grids_no_real_transit(plains: dict[int, Scenario]) -> None:
    assert {scenario.terrain for scenario in plains.values()} == {"plain"}


def test_monterey_is_too_small_for_a_transit(bathymetry_dir: Path) -> None:
    terrains = {generate(seed, data_dir=bathymetry_dir, kind="transit").terrain for seed in SEEDS}
    assert "monterey" not in terrains
    assert terrains & {"lisbon", "balanus"}


def test_cli_writes_transit_scenarios(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "empty").mkdir()
    monkeypatch.setenv("AUVPLAN_SHARED_DATA", str(tmp_path / "empty"))  # no real grids
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout):
        code = main(["scenarios", "3", "14", "-o", str(tmp_path / "out"), "--kind", "transit"])
    assert code == 0
    for seed in (3, 14):
        folder = tmp_path / "out" / f"seed_{seed:04d}"
        expected = generate(seed, data_dir=tmp_path / "none", kind="transit")
        assert (folder / "mission.toml").read_text(encoding="utf-8") == expected.toml(folder)
        assert (folder / "terrain.nc").is_file()
        assert expected.description in stdout.getvalue()


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(24))
def test_preplan_accepts_transit_mission_slow(
    seed: int, tmp_path: Path, bathymetry_dir: Path
) -> None:
    mission = generate(seed, data_dir=bathymetry_dir, kind="transit").write(tmp_path / "scenario")
    code, stderr = _preplan_exit_code(mission, tmp_path / "out")
    assert code == 0, stderr
