"""The one owner of the figures' look: vehicle colours, pair colours and plain tick labels.

Every figure that draws vehicles takes their colours from :func:`vehicle_colors`, indexed by
the vehicle's position in the mission, so that a vehicle has the same colour in the paths,
time-series, navigation and coordination figures. Pairs (separation curves) take theirs from
:func:`pair_colors`, a palette of its own, so that a pair's curve is never mistaken for a
vehicle's. :func:`plain_tick_labels` replaces matplotlib's scientific tick labels
(``4×10^1`` on a log axis, a ``1e6`` offset on a linear one) by plain numbers.
"""

from __future__ import annotations

from typing import Final

import numpy as np
from matplotlib import colormaps
from matplotlib.axis import Axis
from matplotlib.colors import to_hex, to_rgb
from matplotlib.figure import Figure
from matplotlib.ticker import LogFormatter, LogFormatterSciNotation, ScalarFormatter

#: Up to ten vehicles: matplotlib's ``tab10`` in this order (blue, green, orange, purple, red,
#: brown, pink, grey, olive, cyan), so that the example missions' vehicles, named after
#: colours in that order, are drawn in their colours.
_FEW: Final = "tab10"
_FEW_ORDER: Final = (0, 2, 1, 4, 3, 5, 6, 7, 8, 9)
#: Eleven to twenty vehicles: ``tab20``, the strong shades first, then the light ones.
_MORE: Final = "tab20"
#: More than twenty: evenly spaced hues of ``turbo``.
_MANY: Final = "turbo"
#: Pairs of vehicles (and vehicle-obstacle pairs): ``Dark2``, then ``Set1``.
_PAIRS: Final = ("Dark2", "Set1")


def vehicle_colors(n_vehicles: int) -> tuple[str, ...]:
    """Distinct colours (hex strings) of a fleet's vehicles, in mission order.

    The colours depend only on ``n_vehicles``, so every figure of a fleet agrees; they are
    pairwise different for any fleet size.

    Parameters
    ----------
    n_vehicles : int
        Fleet size, ``>= 0``.

    Returns
    -------
    tuple of str
        ``'#rrggbb'`` per vehicle.

    Examples
    --------
    >>> vehicle_colors(2)  # tab:blue, tab:green
    ('#1f77b4', '#2ca02c')
    >>> len(set(vehicle_colors(64)))
    64
    """
    if n_vehicles <= 10:
        values = [colormaps[_FEW](index) for index in _FEW_ORDER[:n_vehicles]]
    elif n_vehicles <= 20:
        order = [*range(0, 20, 2), *range(1, 20, 2)]  # strong shades before light ones
        values = [colormaps[_MORE](index) for index in order[:n_vehicles]]
    else:
        values = [colormaps[_MANY](value) for value in np.linspace(0.05, 0.95, n_vehicles)]
    return tuple(to_hex(value) for value in values)


def lighter(color: str, amount: float = 0.55) -> str:
    """``color`` mixed with white by ``amount`` in ``[0, 1]`` (a vehicle's secondary shade).

    Examples
    --------
    >>> lighter("#000000", 0.5)
    '#808080'
    """
    red, green, blue = (c + amount * (1.0 - c) for c in to_rgb(color))
    return to_hex((red, green, blue))


def pair_colors(n_pairs: int) -> tuple[str, ...]:
    """Colours of ``n_pairs`` separation curves (cycling after 17), disjoint from few vehicles'.

    Examples
    --------
    >>> pair_colors(1)
    ('#1b9e77',)
    """
    palette = [to_hex(c) for name in _PAIRS for c in colormaps[name].colors]  # type: ignore[attr-defined]
    palette = [color for color in dict.fromkeys(palette) if color not in vehicle_colors(10)]
    return tuple(palette[index % len(palette)] for index in range(n_pairs))


def plain_tick_labels(figure: Figure) -> Figure:
    """Plain numbers on every axis of ``figure`` that uses matplotlib's default formatter.

    Linear axes get a :class:`~matplotlib.ticker.ScalarFormatter` without offset or
    scientific notation (``4400`` rather than ``4.4`` and ``×10^3``); logarithmic axes a
    :class:`~matplotlib.ticker.LogFormatter`, which labels ``40`` rather than ``4×10^1``.
    Axes with a formatter of their own (degrees, dates, categories) are left alone.

    Returns
    -------
    matplotlib.figure.Figure
        ``figure``, for chaining.
    """
    for axes in figure.axes:
        for axis in (axes.xaxis, axes.yaxis):
            _plain(axis)
    return figure


class _PlainLogFormatter(LogFormatter):
    """Labels the ticks :class:`LogFormatter` labels, as positional numbers (``20000``)."""

    def __call__(self, x: float, pos: int | None = None) -> str:
        if not super().__call__(x, pos):
            return ""
        return np.format_float_positional(x, precision=6, trim="-")


def _plain(axis: Axis) -> None:
    if axis.get_scale() == "log":
        major, minor = axis.get_major_formatter(), axis.get_minor_formatter()
        if type(major) is LogFormatterSciNotation:
            axis.set_major_formatter(_PlainLogFormatter())
        if type(minor) is LogFormatterSciNotation:
            axis.set_minor_formatter(_PlainLogFormatter(labelOnlyBase=False))
        return
    if type(axis.get_major_formatter()) is ScalarFormatter:
        plain = ScalarFormatter(useOffset=False)
        plain.set_scientific(False)
        axis.set_major_formatter(plain)


__all__ = ["lighter", "pair_colors", "plain_tick_labels", "vehicle_colors"]
