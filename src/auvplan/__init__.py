"""auvplan: cooperative, energy-optimal, collision-free trajectories for marine vehicle fleets.

Implements (and extends) Häusler, Saccon, Pascoal, Hauser & Aguiar, "Cooperative AUV motion
planning using terrain information", OCEANS 2013: terrain-information maps and A* pre-planning,
temporal deconfliction in the coordination space, and PRONTO trajectory optimisation of the
MEDUSA vehicle model with approximate-barrier collision constraints.

The common tasks need only this namespace::

    import auvplan

    plan = auvplan.plan("mission.toml")      # or a MissionConfig, a dict, auvplan.demo_mission()
    plan.status                              # "CONVERGED", ...
    plan.to_xarray()                         # trajectories.nc as an xarray Dataset
    plan.to_dataframe()                      # long format: vehicle, time, t, north, east, ...
    plan.plot()                              # the mission figure
    plan.summary                             # summary.json as a dict
    plan.save("out/run1")                    # the output folder of `auvplan plan`
    auvplan.load("out/run1")                 # open a folder again

The names are imported on first use, so ``import auvplan`` (and the command line) stays fast.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from auvplan._lazy import lazy_attributes
from auvplan._version import __version__
from auvplan.errors import AuvplanError, DataFormatError, InfeasibleError, InputError, SolverError

#: Public name -> the module that defines it (imported on first access).
_LAZY = {
    "MissionPlan": "auvplan.api.result",
    "load": "auvplan.api.result",
    "plan": "auvplan.api.result",
    "MissionConfig": "auvplan.mission.config",
    "demo_mission": "auvplan.mission.config",
    "load_mission": "auvplan.mission.config",
    "parse_mission": "auvplan.mission.config",
    "MissionResult": "auvplan.mission.pipeline",
    "Stage": "auvplan.mission.pipeline",
    "run_mission": "auvplan.mission.pipeline",
    "read_bathymetry": "auvplan.io.bathymetry",
}

if TYPE_CHECKING:
    from auvplan.api.result import MissionPlan, load, plan
    from auvplan.io.bathymetry import read_bathymetry
    from auvplan.mission.config import MissionConfig, demo_mission, load_mission, parse_mission
    from auvplan.mission.pipeline import MissionResult, Stage, run_mission

__all__ = [
    "AuvplanError",
    "DataFormatError",
    "InfeasibleError",
    "InputError",
    "MissionConfig",
    "MissionPlan",
    "MissionResult",
    "SolverError",
    "Stage",
    "__version__",
    "demo_mission",
    "load",
    "load_mission",
    "parse_mission",
    "plan",
    "read_bathymetry",
    "run_mission",
]


__getattr__, __dir__ = lazy_attributes(__name__, _LAZY, __all__)
