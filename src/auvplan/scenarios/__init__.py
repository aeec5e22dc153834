"""Seeded scenario family and independent checks of plans (reliability benchmarking).

:func:`generate` draws a valid mission from a seed (:class:`Scenario`, written with
:meth:`Scenario.write`), of the ``"reliability"`` kind (varied missions) or the ``"transit"``
kind (long transits beside rough features, :mod:`auvplan.scenarios.transit`); :func:`check`
verifies a ``plan`` output folder with its own interpolation and its own plain-numpy vehicle
model, independently of the solver's report.
"""

from __future__ import annotations

from auvplan.scenarios._terrain import check_data_dir
from auvplan.scenarios.check import CheckFailure, CheckReport, check
from auvplan.scenarios.family import Scenario, generate

__all__ = ["CheckFailure", "CheckReport", "Scenario", "check", "check_data_dir", "generate"]
