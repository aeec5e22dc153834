"""``run_sweep(..., client=...)`` and ``sweep_to_folder(..., client=...)``: the caller's cluster."""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from auvplan.errors import InputError
from auvplan.sweep import RunOptions, build_runs, mission_file_base, run_sweep

PREPLAN = RunOptions(stage="preplan", quiet_logs=False)


@pytest.fixture
def client(monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    """A client of a one-worker in-process cluster of two threads (runs in one process take
    turns: two NetCDF writers at once crash HDF5); the sweep may not make a cluster of its own."""
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(
            n_workers=1, threads_per_worker=2, processes=False, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as caller,
    ):

        def no_cluster(*args: Any, **kwargs: Any) -> None:
            raise AssertionError("the sweep made a LocalCluster instead of using the client")

        monkeypatch.setattr(distributed, "LocalCluster", no_cluster)
        yield caller


def test_run_sweep_uses_the_callers_client_and_leaves_it_open(
    tiny_mission: Path, tmp_path: Path, client: Any
) -> None:
    base = mission_file_base(tiny_mission)
    runs = build_runs(["weights.terrain=0,1"], [None], lambda _seed: base, stage="preplan")[1]
    records = run_sweep(runs, tmp_path / "sweep", options=PREPLAN, client=client)
    assert [record.status for record in records] == ["PREPLANNED", "PREPLANNED"]
    for record in records:
        assert record.folder is not None
        worker = json.loads((record.folder / "sweep_run.json").read_text())["worker"]
        assert worker["pid"] == os.getpid()  # the in-process worker of the caller's cluster
    assert client.status == "running"
    assert client.submit(sum, [1, 2]).result() == 3


def test_sweep_to_folder_with_a_client(tiny_mission: Path, tmp_path: Path, client: Any) -> None:
    from auvplan.api.sweep import sweep_to_folder

    out = tmp_path / "sweep"
    outcome = sweep_to_folder(
        str(tiny_mission), out, vary=["weights.terrain=0,1"], stage="preplan", client=client
    )
    assert outcome.counts["runs"] == outcome.counts["planned"] == 2
    document = json.loads((out / "sweep.json").read_text())
    assert document["spec"]["scheduler"] == client.scheduler.address
    assert client.status == "running"


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"client": "tcp://127.0.0.1:8786"}, "scheduler="),
        ({"scheduler": "tcp://127.0.0.1:8786", "n_workers": 2}, "scheduler and n_workers"),
    ],
)
def test_cluster_arguments_are_checked(
    tiny_mission: Path, tmp_path: Path, kwargs: dict[str, Any], fragment: str
) -> None:
    pytest.importorskip("distributed")
    base = mission_file_base(tiny_mission)
    runs = build_runs(["weights.terrain=1"], [None], lambda _seed: base, stage="preplan")[1]
    with pytest.raises(InputError, match=fragment):
        run_sweep(runs, tmp_path / "sweep", options=PREPLAN, **kwargs)
    assert not (tmp_path / "sweep").exists()
