"""Temporal deconfliction of fixed paths in the coordination space (paper Sec. III-B).

Given one fixed path per vehicle, find time laws (waits and slow-downs only) under which no
two vehicles come closer than ``2 r_c``, certified in continuous time.
"""

from __future__ import annotations

from auvplan import _numba_cache  # noqa: F401 (damaged numba cache files heal: first)
from auvplan.deconfliction.conflicts import (
    ConflictTable,
    build_conflict_table,
    check_endpoint_clearance,
)
from auvplan.deconfliction.coordination import AstarHeuristic, deconflict
from auvplan.deconfliction.problem import CoordinationProblem, headings_along, positions_along
from auvplan.deconfliction.result import (
    CoordinationResult,
    CoordinationStatus,
    DeconflictionMethod,
    SeparationCertificate,
)
from auvplan.deconfliction.retime import retime_for_arrival
from auvplan.deconfliction.schedule import (
    arrival_times_of,
    certify_separation,
    timed_headings,
    timed_positions,
)

__all__ = [
    "AstarHeuristic",
    "ConflictTable",
    "CoordinationProblem",
    "CoordinationResult",
    "CoordinationStatus",
    "DeconflictionMethod",
    "SeparationCertificate",
    "arrival_times_of",
    "build_conflict_table",
    "certify_separation",
    "check_endpoint_clearance",
    "deconflict",
    "headings_along",
    "positions_along",
    "retime_for_arrival",
    "timed_headings",
    "timed_positions",
]
