r"""The current at the mission depth: linear interpolation between the bracketing levels.

With levels at depths ``z_k < z_{k+1}`` [m, positive down] bracketing the mission depth ``d``,

.. math::

    v(d) = v_k + \frac{d - z_k}{z_{k+1} - z_k}\,(v_{k+1} - v_k).

Above the first level the first level's value is taken, below the last the last's. Levels
below the model's sea floor (fill values under a valid level of the same column) hold the
deepest valid value above them, so that a model floor shallower than the survey's does not
turn water into land; a column with no valid level (land) stays NaN (still water). Depth axes
positive up (negative depths) are read by their magnitude.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from auvplan._typing import FloatArray
from auvplan.errors import DataFormatError

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["at_depth", "vertical_dimension"]


def vertical_dimension(dataset: xr.Dataset, data: xr.DataArray, kept: set[str]) -> str | None:
    """The dimension of ``data`` (not in ``kept``) with a depth coordinate (cf_xarray ``Z``).

    HYCOM and Copernicus ``depth``, RTOFS ``Depth``/``lev``, or any 1-D coordinate with a
    ``positive`` attribute; None when there is none.
    """
    import cf_xarray  # noqa: F401  (registers the .cf accessor)
    import xarray as xr

    coordinates = {
        str(dim): dataset.variables[dim]
        for dim in data.dims
        if dim not in kept and dim in dataset.variables and dataset.variables[dim].ndim == 1
    }
    probe = xr.Dataset(coords=coordinates).cf.guess_coord_axis()
    found = [
        *probe.cf.axes.get("Z", []),
        *(name for name, variable in coordinates.items() if "positive" in variable.attrs),
    ]
    return found[0] if found else None


def at_depth(values: FloatArray, depths: FloatArray, depth: float) -> FloatArray:
    """``values`` at ``depth`` [m] (module notes), level axis first.

    Parameters
    ----------
    values : ndarray of shape (n_levels, ...)
        One component on each level.
    depths : ndarray broadcasting to ``values``
        Depth [m, positive down] of each level, increasing along axis 0 (per column for
        terrain-following levels).
    depth : float
        The mission depth [m].

    Returns
    -------
    ndarray of shape ``values.shape[1:]``

    Raises
    ------
    DataFormatError
        If a level's depth is not a finite number or two levels share a depth.
    """
    depths = np.broadcast_to(depths, values.shape)
    if not np.all(np.isfinite(depths)):
        raise DataFormatError("a depth level is not a finite number")
    if np.any(np.diff(depths, axis=0) <= 0.0):
        raise DataFormatError("two depth levels share a depth")
    if values.shape[0] == 1:
        return np.asarray(values[0], dtype=np.float64)
    levels = np.arange(values.shape[0]).reshape(-1, *([1] * (values.ndim - 1)))
    # below the floor: the index of the deepest valid level above (NaN columns keep NaN)
    valid = np.where(np.isfinite(values), levels, 0)
    values = np.take_along_axis(values, np.maximum.accumulate(valid, axis=0), axis=0)
    lower = np.clip(np.sum(depths <= depth, axis=0) - 1, 0, values.shape[0] - 2)[None]
    z_0, z_1 = (np.take_along_axis(depths, lower + k, axis=0)[0] for k in (0, 1))
    v_0, v_1 = (np.take_along_axis(values, lower + k, axis=0)[0] for k in (0, 1))
    weight = np.clip((depth - z_0) / (z_1 - z_0), 0.0, 1.0)
    result: FloatArray = np.where(np.isnan(v_0), v_1, v_0 + weight * (v_1 - v_0))
    return result  # (v_1 where a NaN lies above a valid level)
