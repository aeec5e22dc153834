"""Exceptions raised by auvplan.

Every error a user can cause is a subclass of :class:`AuvplanError`; the command-line
interface turns these into a one-line message on stderr and a non-zero exit code.
"""

from __future__ import annotations


class AuvplanError(Exception):
    """Base class of every error auvplan raises on purpose."""


class InputError(AuvplanError, ValueError):
    """A user-supplied value is malformed or out of range (names the value)."""


class DataFormatError(AuvplanError):
    """A data file (bathymetry, vehicle, mission) cannot be read or has the wrong layout."""


class InfeasibleError(AuvplanError):
    """The problem has no solution (unreachable goal, timing conflict, too-short horizon)."""


class SolverError(AuvplanError):
    """A numerical solver failed in a way the user must know about."""


class WriteError(AuvplanError):
    """A file cannot be written: full disk, file too large, read-only file system (names it)."""


__all__ = [
    "AuvplanError",
    "DataFormatError",
    "InfeasibleError",
    "InputError",
    "SolverError",
    "WriteError",
]
