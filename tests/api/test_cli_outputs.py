"""``auvplan plan``/``maps`` with figure options and progress lines, ``-q`` after the verb."""

from __future__ import annotations

from pathlib import Path

import pytest

from auvplan.cli.main import build_parser, main

from ._html import parse_html
from .test_figures import png_size


def test_plan_writes_pdf_figures_a_report_and_plain_progress(
    mission_file: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    caplog: pytest.LogCaptureFixture,
) -> None:
    out = tmp_path / "out"
    code = main(
        ["plan", str(mission_file), "-o", str(out), "--figure-format", "pdf", "--dpi", "40"]
    )
    captured = capsys.readouterr()
    assert code == 0, captured.err
    pdfs = sorted(path.stem for path in out.glob("*.pdf"))
    assert pdfs == sorted(
        [
            "maps",
            "paths",
            "paths_cost",
            "coordination",
            "time_series",
            "separation",
            "navigation_predicted",
        ]
    )
    assert not list(out.glob("*.png"))
    assert all(path.read_bytes().startswith(b"%PDF-") for path in out.glob("*.pdf"))
    page = parse_html((out / "report.html").read_text(encoding="utf-8"))
    previews = dict(zip(page.ids, page.images, strict=True))
    assert previews["paths"][0] == "image/png"
    assert png_size(previews["paths"][1]) == (9 * 40, round(5.5 * 40))  # the figure at --dpi
    assert str(out / "report.html") in captured.out
    # stderr is not a terminal here: progress comes as plain log lines, no control codes
    assert "\x1b[" not in captured.err
    assert "\r" not in captured.err
    err = "\n".join(record.getMessage() for record in caplog.records)
    assert "A* 1/2: blue <1> (" in err
    assert "A* 2/2: r&d (" in err
    for line in ("A*: done in", "preplan: done in", "deconflict: done in", "optimize: done in"):
        assert line in err
    assert "optimize: barrier level 1/5 (ε = 1e+00) at iteration 0" in err


def test_maps_figure_options_and_quiet_after_the_verb(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "maps"
    arguments = ["maps", "synthetic", "-o", str(out), "--figure-format", "svg", "--dpi", "30"]
    assert main([*arguments, "-q"]) == 0
    assert capsys.readouterr() == ("", "")
    assert sorted(path.name for path in out.iterdir()) == ["maps.nc", "maps.svg"]


@pytest.mark.parametrize("verb", [["plan", "m.toml", "-o", "x"], ["demo"]])
def test_verbosity_and_figure_options_before_or_after_the_verb(verb: list[str]) -> None:
    parser = build_parser()
    after = parser.parse_args([*verb, "-q", "--figure-format", "svg", "--dpi", "300"])
    assert (after.quiet, after.verbose, after.figure_format, after.dpi) == (True, False, "svg", 300)
    before = parser.parse_args(["-v", *verb])
    assert (before.quiet, before.verbose, before.figure_format, before.dpi) == (
        False, True, "png", 150,
    )  # fmt: skip


@pytest.mark.parametrize("dpi", ["0", "72.5", "lots"])
def test_bad_dpi_is_a_usage_error(dpi: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["demo", "--dpi", dpi])
    assert exit_info.value.code == 2
    assert "--dpi: expected an integer from 10 to 2400" in capsys.readouterr().err
