"""Sweeps on real clusters (slow): a separately started scheduler + 2 workers, a LocalCluster.

Both use the demo mission at a 2 s control interval, the cheapest mission that still
optimises (about 5-15 s per run on one core).
"""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pandas as pd
import pytest

from auvplan.cli.main import main
from auvplan.sweep import RunOptions, build_runs, mission_file_base, run_sweep
from auvplan.sweep.runner import WORKER_DIED

pytestmark = pytest.mark.slow

SRC = Path(__file__).parents[2] / "src"
DASK = Path(sys.executable).parent / "dask"


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@pytest.fixture
def scheduler_address(tmp_path: Path) -> Iterator[str]:
    """``dask scheduler`` and two ``dask worker`` processes (1 thread each) on free ports."""
    distributed = pytest.importorskip("distributed")
    if not DASK.is_file():
        pytest.skip(f"dask command not found at {DASK}")
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")]),
    }
    logs = [(tmp_path / f"dask_{name}.log").open("w") for name in ("scheduler", "w1", "w2")]
    commands = [
        [str(DASK), "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
        *(
            [str(DASK), "worker", address, "--nthreads", "1", "--nworkers", "1",
             "--no-dashboard", "--name", name, "--local-directory", str(tmp_path / name)]
            for name in ("w1", "w2")
        ),
    ]  # fmt: skip
    processes: list[subprocess.Popen[bytes]] = []
    try:
        for command, log in zip(commands, logs, strict=True):
            processes.append(subprocess.Popen(command, env=env, stdout=log, stderr=log))
            if not processes[1:]:
                time.sleep(1.0)  # let the scheduler bind before the workers dial it
        with distributed.Client(address, timeout=60) as client:
            client.wait_for_workers(2, timeout=120)
        yield address
    finally:
        for process in reversed(processes):
            process.terminate()
        for process in processes:
            try:
                process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
        for log in logs:
            log.close()


def _energy_grows_with_weight(table: pd.DataFrame) -> None:
    """Per edge model: the energy-only plan (weight 0) spends the least energy."""
    for _, group in table.groupby("planner.edge_model"):
        least = group.loc[group["energy_J"].idxmin(), "weights.terrain"]
        assert least == 0.0, group[["weights.terrain", "energy_J"]]


def test_sweep_on_a_separately_started_scheduler(
    fast_demo_mission: Path, tmp_path: Path, scheduler_address: str
) -> None:
    out = tmp_path / "sweep"
    code = main([
        "-q", "sweep", str(fast_demo_mission), "-o", str(out), "--scheduler", scheduler_address,
        "--vary", "weights.terrain=0,1", "--vary", "planner.edge_model=paper,crossed",
    ])  # fmt: skip
    assert code == 0
    table = pd.read_csv(out / "sweep.csv")
    assert len(table) == 4
    assert (table["status"] == "CONVERGED").all(), table[["run_id", "status", "reason"]]
    assert (table["energy_J"] > 0).all()
    assert table["terrain_information"].between(0, 1).all()
    _energy_grows_with_weight(table)
    workers = {
        json.loads((out / folder / "sweep_run.json").read_text())["worker"]["pid"]
        for folder in table["folder"]
    }
    assert os.getpid() not in workers
    assert len(workers) == 2
    assert (out / "pareto.png").stat().st_size > 10_000


def test_ten_plans_on_a_local_cluster(
    fast_demo_mission: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("distributed")
    out = tmp_path / "sweep"
    started = time.perf_counter()
    code = main([
        "sweep", str(fast_demo_mission), "-o", str(out), "--workers", "2", "--seeds", "0,1",
        "--vary", "weights.terrain=0,0.1,0.3,1,3", "--vary", "planner.edge_model=paper,crossed",
    ])  # fmt: skip
    wall = time.perf_counter() - started
    assert code == 0
    # a mission file's seeds do not change its plan: 10 missions, 10 plans (not 20)
    expected = "10 runs (10 ran, 0 skipped as finished before, 0 failed), 10 planned"
    assert expected in capsys.readouterr().out
    table = pd.read_csv(out / "sweep.csv")
    assert len(table) == 10
    assert table["seed"].isna().all()
    assert (table["status"] == "CONVERGED").all()
    assert table["peak_rss_mb"].gt(50).all()
    _energy_grows_with_weight(table)
    document = json.loads((out / "sweep.json").read_text())
    assert 0 < document["wall_time_s"] <= wall
    assert len(document["pareto"]) == 10  # 5 weights x 2 edge models
    assert any(point["on_front"] for point in document["pareto"])
    assert (out / "pareto.png").stat().st_size > 10_000


def _die_for_weight_one(result: object, folder: Path) -> list[Path]:
    """A figure writer that kills its worker process for the run of weight 1 (a hard crash)."""
    if "weights.terrain=1.0" in folder.name:
        os._exit(70)
    return []


def test_a_run_that_kills_its_worker_is_a_row(tiny_mission: Path, tmp_path: Path) -> None:
    cloudpickle = pytest.importorskip("cloudpickle")
    cloudpickle.register_pickle_by_value(sys.modules[__name__])  # workers need not import us
    base = mission_file_base(tiny_mission)
    _, runs = build_runs(["weights.terrain=0,1"], [None], lambda _seed: base, stage="preplan")
    options = RunOptions(stage="preplan", write_figures=_die_for_weight_one)
    try:
        records = run_sweep(runs, tmp_path / "sweep", options=options, n_workers=1)
    finally:
        cloudpickle.unregister_pickle_by_value(sys.modules[__name__])
    assert [record.status for record in records] == ["PREPLANNED", WORKER_DIED]
    assert records[1].failed
    assert records[1].folder is None
    assert [path.name for path in (tmp_path / "sweep" / "runs").iterdir()] == [runs[0].run_id]
