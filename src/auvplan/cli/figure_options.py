"""``--figure-format`` and ``--dpi``: how the figures of a verb are written."""

from __future__ import annotations

import argparse

from auvplan._figures import DEFAULT_DPI, FIGURE_FORMATS


def dots_per_inch(text: str) -> int:
    """A resolution in dots per inch, an integer from 10 to 2400 (argparse type)."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if not 10 <= value <= 2400:
        raise argparse.ArgumentTypeError(f"expected an integer from 10 to 2400, got {text!r}")
    return value


def add_figure_options(parser: argparse.ArgumentParser) -> None:
    """Add ``--figure-format png|svg|pdf`` and ``--dpi N`` to a verb that draws figures."""
    parser.add_argument(
        "--figure-format",
        choices=tuple(FIGURE_FORMATS),
        default="png",
        help="file format of the figures (default png; svg and pdf are vector graphics)",
    )
    parser.add_argument(
        "--dpi",
        type=dots_per_inch,
        default=DEFAULT_DPI,
        help=f"resolution of raster figures [dots per inch] (default {DEFAULT_DPI})",
    )
