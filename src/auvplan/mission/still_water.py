"""What using the current saves: a still-water plan flown in the real current.

``auvplan plan --compare-no-current`` plans the mission a second time as if the water were
still, then flies that plan in the real current the way a vehicle would: with the plan's own
tracking regulator (PRONTO's last projection gains, the digital controller of
:func:`auvplan.mission.verify.replay_closed_loop`) on a grid ``CHECK_REFINEMENT`` times finer
than the solver's. The regulator fights the drift the plan did not expect, which costs energy
(and some arrival accuracy). The plan that uses the current is flown the same way, so the two
energies are measured alike: ``E = ∫ P(x(t)) dt`` by the trapezoidal rule on the fine grid.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from auvplan._typing import FloatArray
from auvplan.mission.evaluation import CHECK_REFINEMENT, OptimizedPlan
from auvplan.mission.fleet import FleetLayout
from auvplan.mission.verify import replay_closed_loop
from auvplan.ocean import CurrentField
from auvplan.vehicle import electrical_power, positions

__all__ = ["CurrentComparison", "FlownPlan", "compare_with_still_water", "fly_in_current"]


@dataclass(frozen=True)
class FlownPlan:
    """A plan flown in the current: ``energy`` ``(n_vehicles,)`` [J] and ``arrival_error`` [m]."""

    energy: FloatArray
    arrival_error: FloatArray


@dataclass(frozen=True)
class CurrentComparison:
    """The plan using the current and the still-water plan, both flown in the current.

    ``still_water_plan`` is the plan made as if in still water (its own energies are those of
    still water); ``saving`` [J] is ``still_water.energy.sum() − using_current.energy.sum()``.
    """

    using_current: FlownPlan
    still_water: FlownPlan
    still_water_plan: OptimizedPlan

    @property
    def saving(self) -> float:
        """Energy saved by planning with the current [J] (negative: it cost more)."""
        return float(np.sum(self.still_water.energy) - np.sum(self.using_current.energy))


def fly_in_current(
    plan: OptimizedPlan,
    layout: FleetLayout,
    goals: FloatArray,
    dt: float,
    current: CurrentField,
) -> FlownPlan:
    """Fly ``plan`` in ``current`` with its own regulator (module notes).

    Parameters
    ----------
    plan : OptimizedPlan
        An optimised plan (with or without the current).
    layout : FleetLayout
        Its vehicles.
    goals : ndarray of shape (n_vehicles, 3)
        Goal poses; north, east [m] are used.
    dt : float
        Solver interval of the plan [s].
    current : CurrentField
        The real current.
    """
    energies, errors = [], []
    for i, model in enumerate(layout.models):
        flown = replay_closed_loop(
            model,
            plan.states[i],
            plan.inputs[i],
            layout.gains_of(plan.result.regulator_gains, i),
            dt,
            refinement=CHECK_REFINEMENT,
            current=current,
        )
        power = electrical_power(flown, np.zeros((flown.shape[0], model.n_u)), model)
        energies.append(np.trapezoid(power, dx=dt / CHECK_REFINEMENT))
        errors.append(np.hypot(*(positions(model, flown[-1]) - goals[i, :2])))
    return FlownPlan(np.array(energies), np.array(errors))


def compare_with_still_water(
    plan: OptimizedPlan,
    still_water_plan: OptimizedPlan,
    layout: FleetLayout,
    goals: FloatArray,
    dt: float,
    current: CurrentField,
) -> CurrentComparison:
    """Both plans (solver interval ``dt`` [s]) flown in ``current`` (:func:`fly_in_current`)."""
    return CurrentComparison(
        using_current=fly_in_current(plan, layout, goals, dt, current),
        still_water=fly_in_current(still_water_plan, layout, goals, dt, current),
        still_water_plan=still_water_plan,
    )
