"""Validation shared by the navigation models' parameters."""

from __future__ import annotations

import math

from auvplan.errors import InputError


def require_nonnegative(what: str, value: float) -> None:
    """Raise InputError naming ``what`` unless ``value`` is finite and >= 0.

    Examples
    --------
    >>> require_nonnegative("sensor map_variance", -1.0)
    Traceback (most recent call last):
    ...
    auvplan.errors.InputError: sensor map_variance must be finite and >= 0, got -1.0
    """
    if not (math.isfinite(value) and value >= 0.0):
        raise InputError(f"{what} must be finite and >= 0, got {value}")
