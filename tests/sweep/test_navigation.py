"""``auvplan sweep --evaluate``: TAN along every run's plan fills the table and the Pareto files."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

from auvplan.cli.main import main
from auvplan.navigation import NavigationSettings
from auvplan.sweep import NavigationOptions, RunRecord, build_runs, mission_file_base
from auvplan.sweep.runner import execute_evaluation

#: A cheap navigation system: 3 runs of 200 particles, an update every 2 s.
FAST_NAVIGATION = ("--runs", "3", "--particles", "200", "--update-period", "2")


def _sweep(mission: Path, out: Path, *options: str) -> int:
    vary = ("--vary", "weights.terrain=0,1", "--seeds", "5")
    return main(["-q", "sweep", str(mission), "-o", str(out), *vary, "--evaluate", *options])


def _modified(out: Path, name: str) -> dict[Path, int]:
    return {path: path.stat().st_mtime_ns for path in sorted(out.glob(f"runs/*/{name}"))}


@pytest.mark.usefixtures("inprocess_cluster")
def test_sweep_evaluates_every_plan_once_and_draws_the_trade_off(
    tiny_full_mission: Path, tmp_path: Path
) -> None:
    out = tmp_path / "sweep"
    assert _sweep(tiny_full_mission, out, *FAST_NAVIGATION) == 0
    table = pd.read_csv(out / "sweep.csv")
    assert table["status"].tolist() == ["CONVERGED", "CONVERGED"]
    assert (table["tan_rmse_m"] > 0.0).all()
    assert (table["tan_pcrb_m"] > 0.0).all()
    for _, row in table.iterrows():
        document = json.loads((out / row["folder"] / "navigation.json").read_text())
        assert document["settings"]["n_runs"] == 3
        assert document["settings"]["seed"] == 5  # the row's seed
        assert document["plans"]["terrain_aware"]["rmse_m"] == pytest.approx(row["tan_rmse_m"])

    # the same numbers as `auvplan evaluate` on the run folder with the same settings
    folder = out / table.loc[1, "folder"]
    copy = tmp_path / "copy"
    copy.mkdir()
    for name in ("maps.nc", "trajectories.csv", "summary.json"):
        (copy / name).write_bytes((folder / name).read_bytes())
    assert main(["-q", "evaluate", str(copy), "--seed", "5", "--no-figure", *FAST_NAVIGATION]) == 0
    alone = json.loads((copy / "navigation.json").read_text())
    assert alone["plans"]["terrain_aware"]["rmse_m"] == pytest.approx(table.loc[1, "tan_rmse_m"])

    assert (out / "pareto.png").stat().st_size > 0
    points = pd.read_csv(out / "pareto.csv").set_index("label")
    assert points["is_reference"].to_dict() == {0.0: True, 1.0: False}
    assert points.loc[0.0, "improvement"] == pytest.approx(0.0)
    expected = 1.0 - table.loc[1, "tan_rmse_m"] / table.loc[0, "tan_rmse_m"]
    assert points.loc[1.0, "improvement"] == pytest.approx(expected)
    assert points.loc[1.0, "energy_increase"] == pytest.approx(
        table.loc[1, "energy_J"] / table.loc[0, "energy_J"] - 1.0
    )
    assert "energy-only" in (out / "pareto.md").read_text()
    sweep = json.loads((out / "sweep.json").read_text())
    assert sweep["spec"]["navigation"]["particle_filter"]["n_particles"] == 200
    assert set(sweep["trade_off"]) == {"best_within_budget", "cheapest_reaching_target"}

    # again: nothing is planned or evaluated; other settings: evaluated again, not re-planned
    plans, evaluations = _modified(out, "summary.json"), _modified(out, "navigation.json")
    assert _sweep(tiny_full_mission, out, *FAST_NAVIGATION) == 0
    assert _modified(out, "navigation.json") == evaluations
    assert _sweep(tiny_full_mission, out, *FAST_NAVIGATION, "--drift", "0.5") == 0
    assert _modified(out, "summary.json") == plans
    changed = _modified(out, "navigation.json")
    assert all(changed[path] != evaluations[path] for path in evaluations)

    # an evaluation that cannot run is the record's note; the plan stays
    base = mission_file_base(tiny_full_mission)
    run = build_runs(["weights.terrain=1"], [None], lambda _seed: base, stage="full")[1][0]
    record = RunRecord(run.run_id, run.values, None, "CONVERGED", folder=folder)
    too_slow = NavigationOptions(NavigationSettings(update_period=1e5), n_runs=1)
    failed = execute_evaluation(record, run, too_slow)
    assert failed.navigation_error is not None
    assert "update period" in failed.navigation_error
    assert (folder / "trajectories.csv").is_file()
    assert _modified(out, "navigation.json") == changed


@pytest.mark.usefixtures("inprocess_cluster")
def test_seeds_evaluate_one_plan_per_mission(
    tiny_full_mission: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    caplog: pytest.LogCaptureFixture,
) -> None:
    out = tmp_path / "sweep"
    command = ["sweep", str(tiny_full_mission), "-o", str(out), "--vary", "weights.terrain=0,1",
               "--seeds", "5,6", "--evaluate", *FAST_NAVIGATION]  # fmt: skip
    assert main(command) == 0
    assert "4 runs (4 ran, 0 skipped as finished before, 0 failed), 2 planned" in (
        capsys.readouterr().out
    )  # was 4 plans: one per mission and seed
    assert "2 plans, each evaluated with every seed (4 rows)" in caplog.text
    table = pd.read_csv(out / "sweep.csv")
    assert table["seed"].tolist() == [5, 6, 5, 6]
    assert (table["status"] == "CONVERGED").all()
    for mission in (0, 2):  # the two seeds of a mission: one plan, two evaluations
        pair = table.iloc[[mission, mission + 1]]
        assert pair["energy_J"].nunique() == 1
        assert pair["tan_rmse_m"].nunique() == 2
        seeds = [
            json.loads((out / folder / "navigation.json").read_text())["settings"]["seed"]
            for folder in pair["folder"]
        ]
        assert seeds == [5, 6]
        first, second = (out / folder / "trajectories.csv" for folder in pair["folder"])
        assert first.samefile(second)
    plans = [out / folder / "trajectories.csv" for folder in table["folder"]]
    assert not plans[0].samefile(plans[2])  # each mission its own plan


def test_evaluate_needs_the_full_stage(
    tiny_full_mission: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["sweep", str(tiny_full_mission), "-o", str(tmp_path / "s"), "--stage",
                 "preplan", "--vary", "weights.terrain=0,1", "--evaluate"])  # fmt: skip
    assert code == 2
    error = capsys.readouterr().err.strip()
    assert error.count("\n") == 0
    assert "--evaluate" in error
    assert not (tmp_path / "s").exists()


def test_options_of_the_evaluation_are_checked(
    tiny_full_mission: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["sweep", str(tiny_full_mission), "-o", str(tmp_path / "s"),
                 "--vary", "weights.terrain=0,1", "--evaluate", "--runs", "0"])  # fmt: skip
    assert code == 2
    assert "--runs" in capsys.readouterr().err
