"""matplotlib's drawing notices (missing glyphs, collapsed layouts) are debug records only."""

from __future__ import annotations

import logging

import pytest
from matplotlib.figure import Figure

from auvplan.viz.report import render_figure


def test_missing_glyphs_and_a_collapsed_layout_are_logged_at_debug_level_only(
    caplog: pytest.LogCaptureFixture,
) -> None:
    figure = Figure(figsize=(0.6, 0.4), layout="constrained")  # too small for its decorations
    axes = figure.subplots(2, 2)
    axes[0, 0].set_title("蓝鲸 🐋")  # no installed font has these glyphs
    axes[1, 1].set_xlabel("progress $s_0$ of vehicle 海豚🐬号 [m]")  # mathtext's own fonts
    with caplog.at_level(logging.DEBUG):
        rendered = render_figure(figure, dpi=40)  # (a warning would fail: filterwarnings=error)
    assert rendered.data.startswith(b"\x89PNG")
    assert {record.levelno for record in caplog.records} == {logging.DEBUG}
    notices = [r.getMessage() for r in caplog.records if r.name == "auvplan.viz._notices"]
    assert any("missing from font" in notice for notice in notices)
    assert any("does not have a glyph" in notice for notice in notices)
    assert any("constrained_layout not applied" in notice for notice in notices)
    assert len(notices) == len(set(notices))  # each once
    assert logging.getLogger("matplotlib").propagate  # restored
