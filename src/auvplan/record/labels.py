"""The one spelling of what a plan is judged on: a pair of vehicles, or a vehicle and a thing.

Separations, obstacle clearances, communication ranges and state limits are all measured
between a vehicle and something else; :class:`Pair` names them once, is written ``"a / b"``
in every file, figure and message, and is read back by :meth:`Pair.parse`, so no module
splits strings on its own.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final

#: Between the two names of a pair, as written.
SEPARATOR: Final = " / "
#: The name of the operating area (``[area]``) as the second of a pair: its clearance is the
#: distance to its boundary from inside.
AREA_NAME: Final = "operating area"


@dataclass(frozen=True, order=True)
class Pair:
    """A vehicle (``first``) and another vehicle, an obstacle or a state (``second``).

    Examples
    --------
    >>> str(Pair("blue", "green")), Pair.parse("blue / rock 1")
    ('blue / green', Pair(first='blue', second='rock 1'))
    >>> Pair.of_vehicles(["blue", "green"], "green", "blue")
    Pair(first='blue', second='green')
    """

    first: str
    second: str

    def __str__(self) -> str:
        return f"{self.first}{SEPARATOR}{self.second}"

    @classmethod
    def parse(cls, text: str) -> Pair:
        """The pair written as ``text`` (``"a / b"``); a name may itself hold a slash."""
        first, separator, second = text.partition(SEPARATOR)
        if not separator:
            raise ValueError(f"{text!r} is not a pair 'a{SEPARATOR}b'")
        return cls(first, second)

    @classmethod
    def of_vehicles(cls, names: Sequence[str], a: str, b: str) -> Pair:
        """Vehicles ``a`` and ``b`` in the order of ``names`` (the mission's)."""
        first, second = sorted((a, b), key=names.index)
        return cls(first, second)


__all__ = ["SEPARATOR", "Pair"]
