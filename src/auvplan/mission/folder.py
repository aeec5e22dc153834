"""The navigation model an output folder's plan was made with (``auvplan evaluate``)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from pydantic import ValidationError

from auvplan.errors import InputError
from auvplan.io.tables import one_line
from auvplan.mission.config import MissionConfig
from auvplan.mission.tables import NavigationConfig


def mission_navigation(
    mission: Mapping[str, Any], overrides: Mapping[str, Any]
) -> NavigationConfig:
    """The ``[navigation]`` table of a resolved mission document, with ``overrides`` on top.

    ``mission`` is a folder's ``mission.toml`` (:attr:`auvplan.record.PlanRecord.mission`;
    an empty mapping gives the defaults); ``overrides`` are TOML keys of the table (e.g.
    ``{"drift_percent": 0.5}``), so that ``auvplan evaluate`` flies the navigation the
    planner predicted, changed only where a flag says so.

    Raises
    ------
    InputError
        If a value (of the file or an override) is out of its range; the message names it.
    """
    table = mission.get("navigation", {})
    try:
        return NavigationConfig.model_validate(
            {**(table if isinstance(table, dict) else {}), **overrides}
        )
    except ValidationError as error:
        raise InputError(one_line(error, MissionConfig, within=("navigation",))) from None


__all__ = ["mission_navigation"]
