"""Numba helper shared by the deconfliction kernels: growable arrays."""

from __future__ import annotations

from typing import Any

import numba
import numpy as np
import numpy.typing as npt


@numba.njit(cache=True)
def grow(
    array: npt.NDArray[Any], used: int, needed: int
) -> npt.NDArray[Any]:  # pragma: no cover - compiled
    """A larger copy of a 1-D buffer: ``array[:used]``, capacity ``max(needed, 2 len + 16)``.

    Doubling keeps appending amortised O(1); entries past ``used`` are uninitialised.
    """
    bigger = np.empty(max(needed, 2 * array.shape[0] + 16), dtype=array.dtype)
    bigger[:used] = array[:used]
    return bigger
