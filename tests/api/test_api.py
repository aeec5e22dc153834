"""The notebook API: ``auvplan.plan`` / ``load`` and :class:`MissionPlan` against the files."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

import auvplan
from auvplan.io.trajectories_file import read_trajectories_netcdf

from .conftest import NAMES


def test_public_namespace_is_curated_and_lazy() -> None:
    assert set(auvplan.__all__) >= {"plan", "load", "MissionPlan", "MissionConfig", "demo_mission"}
    for name in auvplan.__all__:
        assert getattr(auvplan, name) is not None
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        _ = auvplan.nope  # type: ignore[attr-defined]
    # `import auvplan` alone loads none of the heavy packages (the CLI starts fast): the
    # version, the error types and the lazy-import hook only
    heavy = ("auvplan.", "casadi", "matplotlib", "xarray")
    code = f"import sys, auvplan; print(sorted(m for m in sys.modules if m.startswith({heavy})))"
    loaded = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    assert loaded.stdout.strip() == "['auvplan._lazy', 'auvplan._version', 'auvplan.errors']"


def test_planning_and_writing_without_figures_loads_no_matplotlib() -> None:
    """What ``plan``/``replan --no-figures`` and ``save(figures=False)`` import (the writer
    of the output folder and ``report.html``, the verbs, ``auvplan.viz`` itself): no
    matplotlib, which only drawing a figure imports."""
    modules = (
        "auvplan.api.folder", "auvplan.api.planning", "auvplan.api.replanning",
        "auvplan.cli.plan", "auvplan.cli.replan", "auvplan.viz", "auvplan.viz.html",
    )  # fmt: skip
    code = (
        f"import importlib, sys; [importlib.import_module(m) for m in {modules}]; "
        "import auvplan.viz as viz; print(viz.render_report.__module__, "
        "'matplotlib' in sys.modules); viz.plot_terrain_maps; print('matplotlib' in sys.modules)"
    )
    loaded = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    assert loaded.stdout.split() == ["auvplan.viz.html", "False", "True"]


def test_to_xarray_is_trajectories_nc(
    mission_plan: auvplan.MissionPlan, saved_folder: Path
) -> None:
    dataset = mission_plan.to_xarray()
    xr.testing.assert_identical(read_trajectories_netcdf(saved_folder / "trajectories.nc"), dataset)
    assert list(dataset["trajectory"].values) == list(NAMES)
    assert {"lat", "lon", "time", "depth"} <= set(dataset.coords)
    dataset["north"][:] = 0.0  # a copy: the plan is not changed
    assert float(np.abs(mission_plan.to_xarray()["north"]).max()) > 0.0


def test_to_dataframe_is_long_format_of_the_csv(
    mission_plan: auvplan.MissionPlan, saved_folder: Path
) -> None:
    frame = mission_plan.to_dataframe()
    dataset = mission_plan.to_xarray()
    n_vehicles, n_t = dataset["north"].shape
    assert frame.shape == (n_vehicles * n_t, 3 + 3 + 9)
    assert list(frame.columns[:6]) == ["vehicle", "time", "t", "lat", "lon", "depth"]
    # oracle: trajectories.csv, written by the CSV writer from the solver's arrays
    with (saved_folder / "trajectories.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == len(frame)
    for column in ("t", "north", "east", "u", "v", "r", "n_ps", "n_sb", "power"):
        expected = np.array([float(row[column]) for row in rows])
        np.testing.assert_allclose(frame[column].to_numpy(), expected, rtol=1e-12, atol=1e-9)
    assert list(frame["vehicle"]) == [row["vehicle"] for row in rows]
    start = pd.Timestamp("2025-03-14T09:00:00", tz="UTC")  # time zone aware, as documented
    assert str(frame["time"].dt.tz) == "UTC"
    expected_times = start + pd.to_timedelta(frame["t"].to_numpy(), unit="s")
    assert (frame["time"] - expected_times).abs().max() < pd.Timedelta(microseconds=1)


def test_figures_show_in_a_notebook_without_magics(mission_plan: auvplan.MissionPlan) -> None:
    """IPython displays an object through its ``_repr_png_``: no ``%matplotlib inline`` needed."""
    figure = mission_plan.plot()
    png = figure._repr_png_()  # type: ignore[attr-defined]
    assert png.startswith(b"\x89PNG\r\n\x1a\n")
    assert len(png) > 10_000


def test_progress_in_jupyter_without_widgets_is_log_lines(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """rich's Jupyter display needs ipywidgets (else a warning per refresh): plain lines then."""
    from rich.console import Console

    from auvplan.api import progress

    console = Console(force_jupyter=True)
    monkeypatch.setattr(progress.importlib.util, "find_spec", lambda name: None)
    with progress.ConsoleProgress(console=console) as reporter:
        assert reporter._display is None


def test_load_gives_back_the_same_plan(
    mission_plan: auvplan.MissionPlan, saved_folder: Path, tmp_path: Path
) -> None:
    loaded = auvplan.load(saved_folder)
    assert loaded.summary == mission_plan.summary
    assert loaded.summary == json.loads((saved_folder / "summary.json").read_text())
    xr.testing.assert_identical(loaded.to_xarray(), mission_plan.to_xarray())
    assert (loaded.names, loaded.status, loaded.result) == (NAMES, "CONVERGED", None)
    assert loaded.folder == saved_folder
    assert "status='CONVERGED'" in repr(loaded)
    # the mission figure from the folder is the figure of the run
    for ours, theirs in zip(
        mission_plan.plot().axes[0].lines, loaded.plot().axes[0].lines, strict=True
    ):
        np.testing.assert_allclose(ours.get_xydata(), theirs.get_xydata())
        assert ours.get_color() == theirs.get_color()
    copied = loaded.save(tmp_path / "copy")
    assert {p.name for p in copied} == {p.name for p in saved_folder.iterdir()}


def test_load_refuses_a_folder_without_summary(tmp_path: Path) -> None:
    with pytest.raises(auvplan.InputError, match="not an auvplan output folder"):
        auvplan.load(tmp_path)


def test_plan_from_a_dict_stopped_early(mission_file: Path) -> None:
    import tomllib

    document = tomllib.loads(mission_file.read_text())
    document["terrain"]["file"] = str(mission_file.parent / "ridge.nc")
    preplanned = auvplan.plan(document, stage="preplan", progress=False)
    assert preplanned.status is None
    assert preplanned.summary["stage"] == "preplan"
    assert len(preplanned.plot().axes[0].lines) >= 2  # the pre-planned paths alone
    with pytest.raises(auvplan.InputError, match="no optimised plan: the run stopped after"):
        preplanned.to_xarray()
    with pytest.raises(auvplan.InputError, match="stage must be one of"):
        auvplan.plan(document, stage="everything", progress=False)
