"""``examples/notebook_api.py`` runs top to bottom (fast suite: CI keeps the example working)."""

from __future__ import annotations

import runpy
from pathlib import Path
from typing import Any

import pytest

import auvplan

EXAMPLE = Path(__file__).parents[2] / "examples" / "notebook_api.py"


def test_notebook_api_example_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    namespace = runpy.run_path(str(EXAMPLE), run_name="__main__")
    plan = namespace["plan"]
    assert isinstance(plan, auvplan.MissionPlan)
    assert plan.status == "CONVERGED"
    assert (tmp_path / "out" / "notebook_api_paths.png").is_file()
    assert (tmp_path / "out" / "notebook_api" / "report.html").is_file()
    svg = {path.stem for path in (tmp_path / "out" / "notebook_api").glob("*.svg")}
    assert svg == {
        "maps", "paths", "paths_cost", "coordination", "time_series", "separation",
        "navigation_predicted",
    }  # fmt: skip


def _notebook(script: Path) -> Any:
    """The percent-format script as a Jupyter notebook: ``# %%`` code cells and
    ``# %% [markdown]`` cells (the Jupytext convention the example follows)."""
    nbformat = pytest.importorskip("nbformat")
    cells = []
    for chunk in script.read_text(encoding="utf-8").split("# %%")[1:]:
        header, _, body = chunk.partition("\n")
        if header.strip() == "[markdown]":
            text = "\n".join(
                line.removeprefix("# ").removeprefix("#") for line in body.splitlines()
            )
            cells.append(nbformat.v4.new_markdown_cell(text.strip()))
        else:
            cells.append(nbformat.v4.new_code_cell(body.strip()))
    return nbformat.v4.new_notebook(cells=cells)


@pytest.mark.slow
def test_the_example_runs_as_a_notebook(tmp_path: Path) -> None:
    """Executed headless by nbclient in a real kernel: the figure is an ``image/png`` output
    without ``%matplotlib inline``, and no cell writes to stderr (no warnings)."""
    nbclient = pytest.importorskip("nbclient")
    notebook = _notebook(EXAMPLE)
    client = nbclient.NotebookClient(
        notebook,
        timeout=600,
        kernel_name="python3",
        resources={"metadata": {"path": str(tmp_path)}},
    )
    client.execute()
    outputs = [
        output for cell in notebook.cells if cell.cell_type == "code" for output in cell.outputs
    ]
    assert any("image/png" in output.get("data", {}) for output in outputs)
    stderr = [output.text for output in outputs if output.get("name") == "stderr"]
    assert stderr == []
    assert (tmp_path / "out" / "notebook_api" / "report.html").is_file()
