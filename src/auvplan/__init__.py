"""auvplan: cooperative, energy-optimal, collision-free trajectories for marine vehicle fleets.

Implements (and extends) Häusler, Saccon, Pascoal, Hauser & Aguiar, "Cooperative AUV motion
planning using terrain information", OCEANS 2013: terrain-information maps and A* pre-planning,
temporal deconfliction in the coordination space, and PRONTO trajectory optimisation of the
MEDUSA vehicle model with approximate-barrier collision constraints.
"""

from __future__ import annotations

from auvplan.errors import AuvplanError, DataFormatError, InfeasibleError, InputError, SolverError

__version__ = "0.1.0"

__all__ = [
    "AuvplanError",
    "DataFormatError",
    "InfeasibleError",
    "InputError",
    "SolverError",
    "__version__",
]
