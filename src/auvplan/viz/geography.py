"""Latitude/longitude axes and a scale bar on map panels of georeferenced terrain.

Map panels are drawn in the local frame (east [m] to the right, north [m] up). On terrain with
a geographic reference (:class:`~auvplan.terrain.LocalProjection`) :func:`add_geographic_axes`
adds longitude [deg] on a secondary top axis and latitude [deg] on a secondary right axis, and
a scale bar in metres. The secondary axes read the longitude along the panel's middle row and
the latitude along its middle column: the local frame is a transverse Mercator centred on the
map, whose meridians and parallels are straight to within the meridian convergence (about
``1e-4`` rad per kilometre off the central meridian, a few metres over a 10 km map).
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.axes import Axes
from matplotlib.ticker import MaxNLocator, ScalarFormatter
from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar
from numpy.typing import ArrayLike

from auvplan._typing import FloatArray
from auvplan.terrain.projection import LocalProjection

#: Target length of the scale bar as a fraction of the panel width.
SCALE_BAR_FRACTION = 0.2


def nice_length(length: float) -> float:
    """The largest of 1, 2 or 5 times a power of ten that is ``<= length`` (``length > 0``).

    Examples
    --------
    >>> nice_length(173.0), nice_length(0.43), nice_length(2000.0)
    (100.0, 0.2, 2000.0)
    """
    exponent = math.floor(math.log10(length))
    base = 10.0**exponent
    mantissa = max(m for m in (1.0, 2.0, 5.0, 10.0) if m * base <= length * (1.0 + 1e-12))
    return float(f"{mantissa * base:.12g}")


def add_scale_bar(axes: Axes, *, fontsize: str = "small") -> float:
    """A scale bar in metres in the lower right corner of a panel whose data units are metres.

    Returns
    -------
    float
        The bar's length [m] (:func:`nice_length` of a fifth of the panel width).
    """
    west, east = axes.get_xlim()
    length = nice_length(SCALE_BAR_FRACTION * abs(east - west))
    label = f"{length / 1000:g} km" if length >= 1000.0 else f"{length:g} m"
    bar = AnchoredSizeBar(
        axes.transData, length, label, loc="lower right", pad=0.4, borderpad=0.6, sep=3,
        frameon=True, size_vertical=0, fontproperties={"size": fontsize},
    )  # fmt: skip
    bar.patch.set_alpha(0.75)
    axes.add_artist(bar)
    return length


def add_geographic_axes(
    axes: Axes, projection: LocalProjection, *, latitude: bool = True, scale_bar: bool = True
) -> None:
    """Longitude on top (and latitude on the right) of a north/east panel, and a scale bar.

    Call it after the panel's limits are set.

    Parameters
    ----------
    axes : matplotlib.axes.Axes
        A panel drawn with east [m] on x and north [m] on y.
    projection : LocalProjection
        The panel's local frame.
    latitude : bool
        Also add the latitude axis on the right (leave it out where a colour bar sits close).
    scale_bar : bool
        Also draw :func:`add_scale_bar`.
    """
    south, north = axes.get_ylim()
    west, east = axes.get_xlim()
    middle_north, middle_east = 0.5 * (south + north), 0.5 * (west + east)
    lat_0, lon_0 = (float(v[0]) for v in projection.to_geographic(
        np.array([middle_north]), np.array([middle_east])
    ))  # fmt: skip

    def to_lon(east_m: ArrayLike) -> FloatArray:
        east_m = np.asarray(east_m, dtype=np.float64)
        return projection.to_geographic(np.full_like(east_m, middle_north), east_m)[1]

    def from_lon(lon: ArrayLike) -> FloatArray:
        lon = np.asarray(lon, dtype=np.float64)
        return projection.to_local(np.full_like(lon, lat_0), lon)[1]

    top = axes.secondary_xaxis("top", functions=(to_lon, from_lon))
    top.xaxis.set_major_locator(MaxNLocator(nbins=4))
    top.xaxis.set_major_formatter(_degrees())
    top.set_xlabel("longitude [deg]")
    if latitude:

        def to_lat(north_m: ArrayLike) -> FloatArray:
            north_m = np.asarray(north_m, dtype=np.float64)
            return projection.to_geographic(north_m, np.full_like(north_m, middle_east))[0]

        def from_lat(lat: ArrayLike) -> FloatArray:
            lat = np.asarray(lat, dtype=np.float64)
            return projection.to_local(lat, np.full_like(lat, lon_0))[0]

        right = axes.secondary_yaxis("right", functions=(to_lat, from_lat))
        right.yaxis.set_major_locator(MaxNLocator(nbins=5))
        right.yaxis.set_major_formatter(_degrees())
        right.set_ylabel("latitude [deg]")
    if scale_bar:
        add_scale_bar(axes)


def _degrees() -> ScalarFormatter:
    """Plain decimal degrees (no offset: ``36.795``, not ``+3.679e1``)."""
    formatter = ScalarFormatter(useOffset=False)
    formatter.set_scientific(False)
    return formatter


__all__ = ["add_geographic_axes", "add_scale_bar", "nice_length"]
