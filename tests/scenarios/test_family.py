"""The seeded scenario family: deterministic, valid (preplan accepts it), poses in water."""

from __future__ import annotations

import contextlib
import io
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from auvplan.cli.main import main
from auvplan.errors import InputError
from auvplan.io.bathymetry import read_bathymetry
from auvplan.mission.config import load_mission
from auvplan.mission.pipeline import run_preplan
from auvplan.planning import distance_to_obstacle
from auvplan.scenarios import check_data_dir, generate
from auvplan.scenarios._terrain import REAL_GRIDS
from auvplan.scenarios.family import DT_BY_HORIZON, FLEET_SIZES, HORIZON_RANGE_S

#: Seeds whose pre-planning takes a second or less: synthetic, bank, Lisbon, Monterey terrain.
FAST_SEEDS = (2, 3, 4, 12)
TOP_SPEED = 1.48  # m/s, MEDUSA (reference/vehicle.md §2)


def _preplan_exit_code(mission: Path, output: Path) -> tuple[int, str]:
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr):
        code = main(
            ["-q", "plan", str(mission), "-o", str(output), "--stage", "preplan", "--no-figures"]
        )
    return code, stderr.getvalue()


@pytest.mark.parametrize("seed", [0, 2, 3, 9])
def test_same_seed_gives_identical_mission(seed: int, bathymetry_dir: Path) -> None:
    first, second = generate(seed, data_dir=bathymetry_dir), generate(seed, data_dir=bathymetry_dir)
    assert first.toml() == second.toml()
    assert first.description == second.description
    if first.synthetic_terrain is not None:
        assert second.synthetic_terrain is not None
        np.testing.assert_array_equal(first.synthetic_terrain.depth, second.synthetic_terrain.depth)


def test_seeds_differ(bathymetry_dir: Path) -> None:
    texts = {generate(seed, data_dir=bathymetry_dir).toml() for seed in range(8)}
    assert len(texts) == 8


def test_write_makes_a_self_contained_folder(tmp_path: Path, bathymetry_dir: Path) -> None:
    synthetic = next(
        s for seed in range(50) if (s := generate(seed, data_dir=tmp_path)).synthetic_terrain
    )
    path = synthetic.write(tmp_path / "a")
    document = tomllib.loads(path.read_text(encoding="utf-8"))
    assert document["terrain"]["file"] == "terrain.nc"
    written = read_bathymetry(tmp_path / "a" / "terrain.nc")
    assert synthetic.synthetic_terrain is not None
    np.testing.assert_array_equal(written.depth, synthetic.synthetic_terrain.depth)
    real = generate(1, data_dir=bathymetry_dir)
    assert real.terrain == "monterey"
    path = real.write(tmp_path / "deep" / "b")
    relative = tomllib.loads(path.read_text(encoding="utf-8"))["terrain"]["file"]
    assert not Path(relative).is_absolute()
    assert (path.parent / relative).resolve() == (bathymetry_dir / Path(relative).name).resolve()


@pytest.mark.parametrize("seed", FAST_SEEDS)
def test_preplan_accepts_generated_mission(seed: int, tmp_path: Path, bathymetry_dir: Path) -> None:
    mission = generate(seed, data_dir=bathymetry_dir).write(tmp_path / "scenario")
    code, stderr = _preplan_exit_code(mission, tmp_path / "out")
    assert code == 0, stderr


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(24))
def test_preplan_accepts_generated_mission_slow(
    seed: int, tmp_path: Path, bathymetry_dir: Path
) -> None:
    mission = generate(seed, data_dir=bathymetry_dir).write(tmp_path / "scenario")
    code, stderr = _preplan_exit_code(mission, tmp_path / "out")
    assert code == 0, stderr


def test_rendezvous_on_a_coarse_grid_is_timed_apart(tmp_path: Path, bathymetry_dir: Path) -> None:
    """Seed 13: six goals 43-74 m apart inside two 115 m cells of the Lisbon grid, r_c = 10 m.

    The A* routes pass within 2 r_c of other vehicles' goals (the cells cannot express the
    discs), so deconfliction used to find no schedule; the skirted paths keep clear of them.
    """
    scenario = generate(13, data_dir=bathymetry_dir)
    if scenario.terrain != "lisbon":
        pytest.skip("the Lisbon grid is not in the shared data")
    config = load_mission(scenario.write(tmp_path / "scenario"))
    stage = run_preplan(config)
    separation = 2.0 * config.fleet.safety_radius
    for i, path in enumerate(stage.paths):
        others = np.delete(stage.goals[:, :2], i, axis=0)
        gaps = np.hypot(path[:, None, 0] - others[:, 0], path[:, None, 1] - others[:, 1])
        assert gaps.min() > separation
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr):
        code = main(
            ["-q", "plan", str(tmp_path / "scenario" / "mission.toml"), "-o",
             str(tmp_path / "out"), "--stage", "deconflict", "--no-figures"]
        )  # fmt: skip
    assert code == 0, stderr.getvalue()


def test_without_real_grids_only_synthetic_terrain(tmp_path: Path) -> None:
    kinds = {generate(seed, data_dir=tmp_path).terrain for seed in range(6)}
    assert kinds <= {"bank", "synthetic"}
    mission = generate(0, data_dir=tmp_path).write(tmp_path / "scenario")
    assert _preplan_exit_code(mission, tmp_path / "out")[0] == 0


def test_check_data_dir_needs_a_folder_with_a_real_grid(tmp_path: Path) -> None:
    lacks = f"lacks {', '.join(REAL_GRIDS.values())}"
    with pytest.raises(InputError, match=f"data folder {tmp_path} holds none of .*: {lacks}"):
        check_data_dir(tmp_path)
    with pytest.raises(InputError, match="does not exist: it should hold"):
        check_data_dir(tmp_path / "bathymetyr")
    (tmp_path / "f").write_text("")
    with pytest.raises(InputError, match="is not a folder: it should hold"):
        check_data_dir(tmp_path / "f")
    (tmp_path / REAL_GRIDS["lisbon"]).write_bytes(b"")  # one grid is enough
    check_data_dir(tmp_path)


@pytest.mark.parametrize("verb", ["scenarios", "sweep"])
def test_a_mistyped_data_dir_exits_2_and_writes_nothing(
    verb: str, tmp_path: Path, bathymetry_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A typo in --data-dir gave the family without real grids, silently."""
    typo = bathymetry_dir.parent / "bathymetyr"
    out = str(tmp_path / "out")
    argv = {
        "scenarios": ["scenarios", "3", "-o", out, "--data-dir", str(typo)],
        "sweep": ["sweep", "scenarios", "--seeds", "3", "-o", out, "--data-dir", str(typo)],
    }[verb]
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2
    assert err == (
        f"auvplan: error: data folder {typo} does not exist: it should hold the real "
        f"bathymetry grids (at least one of {', '.join(REAL_GRIDS.values())})\n"
    )
    assert list(tmp_path.iterdir()) == []


def test_the_default_data_dir_may_be_absent(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setenv("AUVPLAN_SHARED_DATA", str(tmp_path / "nowhere"))
    assert main(["-q", "scenarios", "3", "-o", str(tmp_path / "out")]) == 0
    assert capsys.readouterr().err == ""
    assert generate(3).terrain in {"bank", "synthetic"}


def test_without_shared_data_the_family_reads_the_packaged_grids(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A fresh clone (no ../shared) draws the same family from the grids auvplan ships."""
    from auvplan.io.samples import samples_folder
    from auvplan.scenarios._terrain import default_data_dir

    monkeypatch.delenv("AUVPLAN_SHARED_DATA", raising=False)
    monkeypatch.chdir(tmp_path)  # no ../shared/data beside it
    assert default_data_dir() == samples_folder()
    assert {path.name for path in samples_folder().glob("*.nc")} == set(REAL_GRIDS.values())


@pytest.mark.parametrize("seed", [1, 4, 11, 18, 25])
def test_poses_in_water_away_from_no_go_cells_and_separated(
    seed: int, tmp_path: Path, bathymetry_dir: Path
) -> None:
    scenario = generate(seed, data_dir=bathymetry_dir)
    config = load_mission(scenario.write(tmp_path))
    preplan = run_preplan(config)  # resolves lat/lon poses exactly as `plan` does
    grid = preplan.bathymetry.geometry
    radius = config.fleet.safety_radius
    for points in (preplan.starts[:, :2], preplan.goals[:, :2]):
        rows, cols = grid.to_index(points[:, 0], points[:, 1])
        # the 3 x 3 bathymetry cells around every pose are water
        for row, col in zip(rows, cols, strict=True):
            patch = preplan.bathymetry.depth[max(row - 1, 0) : row + 2, max(col - 1, 0) : col + 2]
            assert patch.shape == (3, 3)
            assert np.all(np.isfinite(patch))
        gaps = np.hypot(*(points[:, None, :] - points[None, :, :]).transpose(2, 0, 1))
        gaps[np.diag_indices(len(points))] = np.inf
        assert gaps.min() >= 2.0 * radius + max(radius, 5.0) - 0.05
    for obstacle in preplan.obstacles:
        for point in (*preplan.starts[:, :2], *preplan.goals[:, :2]):
            assert float(distance_to_obstacle(obstacle, *point)) > radius


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(min_value=0, max_value=2**32 - 1))
def test_family_ranges(seed: int) -> None:
    scenario = generate(seed, data_dir=Path("/nonexistent"))
    mission = scenario.mission
    horizon = mission["fleet"]["horizon_s"]
    assert HORIZON_RANGE_S[0] <= horizon <= HORIZON_RANGE_S[1]
    dt = mission["solver"]["dt_s"]
    assert dt == next(step for longest, step in DT_BY_HORIZON if horizon <= longest)
    assert math.isclose(horizon / dt, round(horizon / dt))
    assert FLEET_SIZES[0] <= len(mission["vehicle"]) <= FLEET_SIZES[1]
    for vehicle in mission["vehicle"]:
        start, goal = vehicle["start"], vehicle["goal"]
        distance = math.hypot(goal["north"] - start["north"], goal["east"] - start["east"])
        # straight-line speed: slower than the mean speed range, far below the top speed
        assert 0.2 <= distance / horizon <= 0.6 * TOP_SPEED
        assert 0.0 <= start["speed"] <= 0.6
    names = [vehicle["name"] for vehicle in mission["vehicle"]]
    for comm in mission.get("comm", []):
        assert set(comm["pair"]) <= set(names)
