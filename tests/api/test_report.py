"""``report.html``: valid HTML, figures embedded, status, tables and warnings, escaped text."""

from __future__ import annotations

import json
from pathlib import Path

from auvplan.viz.html import render_report

from ._html import parse_html
from .conftest import NAMES


def test_report_embeds_every_figure_and_states_the_plan(saved_folder: Path) -> None:
    text = (saved_folder / "report.html").read_text(encoding="utf-8")
    page = parse_html(text)
    figures = sorted(saved_folder.glob("*.png"))
    assert len(figures) == 7
    assert sorted(page.ids) == sorted(path.stem for path in figures)
    assert [kind for kind, _ in page.images] == ["image/png"] * len(figures)
    embedded = {data for _, data in page.images}
    assert embedded == {path.read_bytes() for path in figures}  # the files themselves
    words = " ".join(page.text)
    summary = json.loads((saved_folder / "summary.json").read_text())
    assert "plan CONVERGED" in words
    assert f"iterations {summary['optimization']['n_iter']}" in " ".join(words.split())
    assert summary["deconfliction"]["method"] in words
    assert "Navigation (predicted TAN error, 1-σ radial)" in words
    for name in NAMES:  # shown as written, escaped in the source
        assert name in words
    assert "blue &lt;1&gt;" in text
    assert "r&amp;d" in text
    assert "blue <1>" not in text
    n_history = len(summary["optimization"]["history"])
    assert text.count("<td>NEWTON</td>") + text.count("<td>CONVEXIFIED</td>") == n_history
    assert summary["warnings"] == []
    assert "report.html" in words  # the folder's files are listed


def test_report_lists_warnings_and_works_without_figures(saved_folder: Path) -> None:
    summary = json.loads((saved_folder / "summary.json").read_text())
    summary["warnings"] = ["retime: vehicle <a> & b keeps its replayed law"]
    summary["optimization"]["plan_status"] = "COLLISION"
    page = parse_html(render_report(summary, {}))
    words = " ".join(page.text)
    assert "retime: vehicle <a> & b keeps its replayed law" in words
    assert "plan COLLISION" in words
    assert "None (written without figures)." in words
    assert page.images == []
