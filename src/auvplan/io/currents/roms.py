r"""ROMS / CROCO output: the staggered C-grid's ``u``, ``v`` as east/north at the ρ points.

On the Arakawa C-grid ``u`` (along the grid's ξ axis) sits on ``(eta_u, xi_u)`` between ρ
columns and ``v`` (along η) on ``(eta_v, xi_v)`` between ρ rows. Each is averaged onto the
interior ρ points (the two neighbours; one of them where the other is land, ``mask_u`` /
``mask_v`` = 0 or a fill value), then turned to east/north by the grid's ``angle`` ``α``
[rad] of the ξ axis from east (OpenDrift ``rotate_vectors_angle``):

.. math::

    v_E = u \cos α - v \sin α, \qquad v_N = u \sin α + v \cos α.

Depth: with ``s_rho``, ``Cs_r``, ``h``, ``hc`` (and ``Vtransform``, default 1; CROCO's
global ``VertCoordType = "NEW"`` is 2) the depth of each s-level of each column is
``z = hc s + (h - hc) C`` (Vtransform 1) or ``z = h (hc s + h C) / (hc + h)`` (2), the free
surface ζ taken as 0 (its tide moves the levels by a fraction of their spacing), and the
current is interpolated linearly to the mission depth (:mod:`.levels`); without them the
surface level (the largest ``s_rho``) is taken. The nodes are ``lat_rho``/``lon_rho``: a
curvilinear grid, resampled by :mod:`.curvilinear`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError
from auvplan.io.currents.levels import at_depth
from auvplan.io.currents.variables import Components, finite_values, velocity_values

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["rho_currents"]

#: The grid variables the conversion needs, on the ρ points.
_GRID: Final = ("lat_rho", "lon_rho", "angle")
_S_NAMES: Final = ("s_rho", "sc_r")


def rho_currents(
    dataset: xr.Dataset,
    components: Components,
    time: tuple[str, slice] | None,
    depth: float,
) -> tuple[list[FloatArray], FloatArray, FloatArray]:
    """``[v_N, v_E]`` [m/s] of shape ``(n_t, n_eta - 2, n_xi - 2)`` and their ``lat, lon`` [deg].

    Parameters
    ----------
    dataset : xarray.Dataset
        The ROMS/CROCO file (decoded scale and fill values).
    components : Components
        ``u`` and ``v`` (staggered).
    time : (str, slice) or None
        The time dimension and the slices kept.
    depth : float
        Mission depth [m].

    Raises
    ------
    DataFormatError
        Missing grid variables, u/v not on the ρ grid's staggered shapes, unexpected
        dimensions.
    """
    missing = [name for name in _GRID if name not in dataset.variables]
    if missing:
        raise DataFormatError(
            f"{components.east}/{components.north} are on a ROMS C-grid but {missing} are "
            "missing (the ρ points' lat_rho, lon_rho and the grid's angle [rad])"
        )
    lat, lon, angle = (finite_values(dataset, name) for name in _GRID)
    n_eta, n_xi = lat.shape
    u, s_dim = _load(dataset, components.east, ("eta_u", "xi_u"), (n_eta, n_xi - 1), time)
    v, _ = _load(dataset, components.north, ("eta_v", "xi_v"), (n_eta - 1, n_xi), time)
    u = _mean(u[..., 1:-1, :-1], u[..., 1:-1, 1:])  # (n_t, n_s, n_eta - 2, n_xi - 2)
    v = _mean(v[..., :-1, 1:-1], v[..., 1:, 1:-1])
    interior = (slice(1, -1), slice(1, -1))
    depths = _level_depths(dataset, s_dim, interior)
    if depths is None:  # the surface level
        surface = int(np.argmax(dataset[s_dim].values)) if s_dim in dataset.variables else -1
        u, v = u[:, surface], v[:, surface]
    else:  # levels from the bottom up: depths decrease along s
        u, v = (at_depth(np.moveaxis(c, 1, 0)[::-1], depths[::-1, None], depth) for c in (u, v))
    alpha = angle[interior]
    east = u * np.cos(alpha) - v * np.sin(alpha)
    north = u * np.sin(alpha) + v * np.cos(alpha)
    return [north, east], lat[interior], lon[interior]


def _load(
    dataset: xr.Dataset,
    name: str,
    horizontal: tuple[str, str],
    shape: tuple[int, int],
    time: tuple[str, slice] | None,
) -> tuple[FloatArray, str | None]:
    """``name`` as ``(n_t, n_s, rows, cols)`` in m/s (land NaN), and its s dimension."""
    data = dataset[name]
    if time is not None:
        data = data.isel({time[0]: time[1]})
    others = [str(d) for d in data.dims if d not in horizontal and (time is None or d != time[0])]
    s_dims = [d for d in others if d.startswith("s_") or d in _S_NAMES]
    extra = [d for d in others if d not in s_dims and data.sizes[d] > 1]
    if extra or len(s_dims) > 1 or any(d not in data.dims for d in horizontal):
        raise DataFormatError(
            f"{name} has dimensions {tuple(map(str, data.dims))}, not (time, s_rho, "
            f"{', '.join(horizontal)})"
        )
    s_dim = s_dims[0] if s_dims else None
    order = [d for d in (time[0] if time else None, s_dim, *horizontal) if d]
    values = velocity_values(
        data, data.squeeze([d for d in others if d not in order]).transpose(*order)
    )
    if time is None:
        values = values[None]
    if s_dim is None:
        values = values[:, None]
    if values.shape[-2:] != shape:
        raise DataFormatError(
            f"{name} on {horizontal} is {values.shape[-2]}×{values.shape[-1]}, not "
            f"{shape[0]}×{shape[1]} of the ρ grid's lat_rho/lon_rho"
        )
    mask = f"mask_{horizontal[0].split('_')[1]}"
    if mask in dataset.variables and dataset[mask].shape == shape:
        values[..., np.asarray(dataset[mask].values) == 0] = np.nan
    return values, s_dim


def _mean(a: FloatArray, b: FloatArray) -> FloatArray:
    """``(a + b) / 2``; where one of them is NaN (land), the other."""
    return np.where(np.isnan(a), b, np.where(np.isnan(b), a, 0.5 * (a + b)))


def _level_depths(
    dataset: xr.Dataset, s_dim: str | None, interior: tuple[slice, slice]
) -> FloatArray | None:
    """Depth [m, positive down] of each s-level at the interior ρ points (module notes)."""
    names = [n for n in _S_NAMES if n in dataset.variables and dataset[n].dims == (s_dim,)]
    if s_dim is None or not names or not all(n in dataset.variables for n in ("Cs_r", "h", "hc")):
        return None
    s = finite_values(dataset, names[0])[:, None, None]
    stretching = finite_values(dataset, "Cs_r")[:, None, None]
    h = finite_values(dataset, "h")[interior][None]
    hc = float(finite_values(dataset, "hc"))
    if "Vtransform" in dataset.variables:
        transform = int(dataset["Vtransform"].values)
    else:
        transform = 2 if str(dataset.attrs.get("VertCoordType", "")).upper() == "NEW" else 1
    with np.errstate(divide="ignore", invalid="ignore"):  # a zero h + hc: non-finite depths,
        if transform == 2:  # which at_depth refuses in one line
            return -h * (hc * s + h * stretching) / (hc + h)
        return -(hc * s + (h - hc) * stretching)
