"""The verdict on an optimised plan: CONVERGED only when every constraint holds between samples.

The optimiser imposes its constraints at the solver nodes; here they are checked on the plan
flown with its tracking regulator on a grid ``CHECK_REFINEMENT`` times finer
(:mod:`auvplan.mission.evaluation`): separation ``>= 2 r_c`` between vehicles, clearance
``>= r_c`` from every obstacle's edge (and inside the operating area, from its boundary),
communication ranges, arrival within ``ARRIVAL_TOLERANCE`` of the goal and, with an
explicit ``navigation.max_error_m``, the predicted TAN error along the flown track within
the budget after ``settle_s`` (with ``NAVIGATION_TOLERANCE`` for the pre-planner's
quantisation of the error and the tracking), and, for a vehicle whose battery capacity
``C`` is known, the plan's energy ``E = ∫ P dt ≤ C (1 − f)`` with
``f`` = ``mission.reserve_fraction``.
Each violation names the vehicles or obstacle, the worst value and when, and a change to the
mission that would help.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.io.vehicle_tables import UNITS
from auvplan.mission.config import AREA_NAME, MissionConfig
from auvplan.mission.depth_profile import DepthProfile
from auvplan.mission.navigation import NavigationChoice, budget_of, smallest_budget
from auvplan.navigation.prediction import ErrorPrediction
from auvplan.optimization import ProntoResult
from auvplan.record.labels import Pair

#: Slack [m] allowed on distance limits for round-off between the plan and its replay.
DISTANCE_TOLERANCE: Final = 1e-3
#: Largest distance [m] from the goal at the horizon that still counts as arrived.
ARRIVAL_TOLERANCE: Final = 2.0
#: Relative slack on the navigation budget: the pre-planner's error bins (0.5 m) and the
#: optimiser's freedom to cut the route's corners.
NAVIGATION_TOLERANCE: Final = 0.1


class PlanStatus(enum.Enum):
    """Verdict on a plan (the optimiser's own status is kept beside it)."""

    CONVERGED = "converged"
    """The optimiser converged and every constraint holds between samples."""
    CONSTRAINT_VIOLATED = "constraint_violated"
    """The optimiser converged but a constraint fails somewhere (see the violations)."""
    NOT_CONVERGED = "not_converged"
    """The optimiser stopped early; the best plan found is reported."""


#: Joules in a watt-hour [J/Wh] (the vehicle files' unit table).
JOULES_PER_WH: Final = UNITS["J"]["Wh"]


@dataclass(frozen=True)
class Violation:
    """One constraint that does not hold: ``kind`` of constraint, who, worst value, when.

    ``value`` and ``limit`` are in ``unit``: metres for distances, joules for the energy of
    a ``"battery reserve"`` violation (``value`` the plan's energy, ``limit`` the usable
    energy ``C (1 − f)``, ``time`` when the plan has used it up).
    """

    kind: str
    who: str
    value: float
    limit: float
    time: float
    advice: str
    unit: str = "m"

    def describe(self) -> str:
        """One line for the user."""
        if self.unit == "J":
            deficit = self.value - self.limit
            return (
                f"{self.kind}: {self.who} needs {self.value:.1f} J, {deficit:.1f} J "
                f"({deficit / JOULES_PER_WH:.2f} Wh) more than the {self.limit:.1f} J it may "
                f"use (used up at t = {self.time:.0f} s); {self.advice}"
            )
        relation = ">" if self.kind in ("communication", "navigation error") else "<"
        return (
            f"{self.kind}: {self.who} at {self.value:.2f} m {relation} {self.limit:g} m "
            f"(t = {self.time:.0f} s); {self.advice}"
        )


@dataclass(frozen=True)
class PlanVerdict:
    """Status, the violations found, and the one-line message for the user."""

    status: PlanStatus
    violations: tuple[Violation, ...]
    message: str

    @property
    def success(self) -> bool:
        """True for :attr:`PlanStatus.CONVERGED`."""
        return self.status is PlanStatus.CONVERGED


@dataclass(frozen=True)
class BatteryUse:
    """The energy each vehicle has drawn from its battery over a plan, and the capacities.

    ``used[i, k]`` = ``∫₀^{time[k]} P_i dt`` [J] on the solver grid ``time`` ``(n_t,)`` [s]
    (its last column is the plan's energy); ``capacity[i]`` [J], None when unknown.
    """

    time: FloatArray
    used: FloatArray
    capacity: tuple[float | None, ...]


_TIMING_ADVICE: Final = "try a longer fleet.horizon_s or a smaller solver.dt_s"
#: The optimiser keeps inside the operating area by tracking routes planned inside it.
_AREA_ADVICE: Final = (
    "the plan leaves the area or comes within r_c of its boundary: raise weights.terrain "
    "(the plan tracks routes planned inside the area) or widen the area"
)


def _worst(distance: FloatArray, time: FloatArray, *, largest: bool) -> tuple[float, float]:
    k = int(np.argmax(distance) if largest else np.argmin(distance))
    return float(distance[k]), float(time[k])


def judge_plan(
    config: MissionConfig,
    names: tuple[str, ...],
    result: ProntoResult,
    fine_time: FloatArray,
    fine_distances: dict[Pair, FloatArray],
    arrival_error: FloatArray,
    predicted: tuple[ErrorPrediction, ...] = (),
    routes: tuple[NavigationChoice, ...] | None = None,
    battery: BatteryUse | None = None,
    depth_profiles: tuple[DepthProfile, ...] | None = None,
) -> PlanVerdict:
    """Check a plan's constraints on the fine replay and give its verdict.

    ``fine_distances`` are by :class:`~auvplan.record.labels.Pair` (two vehicles, or a vehicle
    and an obstacle);
    ``arrival_error`` ``(n_vehicles,)`` [m]; ``predicted`` the predicted TAN error of each
    vehicle along its replayed track, ``routes`` how each route was chosen (the smallest
    feasible budget, when the mission's cannot be met); ``battery`` the energy each vehicle
    has used over time and its capacity (None: no battery check); ``depth_profiles`` each
    vehicle's depth profile of ``[mission] altitude_m`` (None: a constant depth, checked by
    the pre-planner).
    """
    radius = config.fleet.safety_radius
    violations: list[Violation] = []
    for pair, distance in fine_distances.items():
        obstacle = pair.second not in names  # else two vehicles
        limit = radius if obstacle else 2.0 * radius
        value, when = _worst(distance, fine_time, largest=False)
        if value < limit - DISTANCE_TOLERANCE:
            kind = "obstacle clearance" if obstacle else "separation"
            advice = _TIMING_ADVICE
            if pair.second == AREA_NAME:  # its distance is negative outside the area
                kind, advice = AREA_NAME, _AREA_ADVICE
            violations.append(Violation(kind, str(pair), value, limit, when, advice))
    for comm in config.comms:
        pair = Pair.of_vehicles(names, *comm.pair)
        value, when = _worst(fine_distances[pair], fine_time, largest=True)
        if value > comm.max_range + DISTANCE_TOLERANCE:
            advice = "move the goals closer together or raise max_range_m"
            violations.append(
                Violation("communication", str(pair), value, comm.max_range, when, advice)
            )
    for i, error in enumerate(arrival_error):
        if error > ARRIVAL_TOLERANCE:
            advice = "try a longer fleet.horizon_s or a larger weights.terminal"
            violations.append(
                Violation(
                    "arrival",
                    names[i],
                    float(error),
                    ARRIVAL_TOLERANCE,
                    float(fine_time[-1]),
                    advice,
                )
            )
    budget = budget_of(config)
    if budget is not None:
        violations += _navigation_violations(config, names, budget, predicted, routes)
    if battery is not None:
        violations += _battery_violations(config, names, battery)
    if depth_profiles is not None:
        violations += seabed_violations(names, depth_profiles)
    if not result.success:
        status = PlanStatus.NOT_CONVERGED
        message = (
            f"optimiser stopped with {result.status.name} after {result.n_iter} iterations "
            f"({result.message}); try a larger solver.max_iter or solver.dt_s"
        )
        if violations:
            message += f"; {violations[0].describe()}"
    elif violations:
        status, message = PlanStatus.CONSTRAINT_VIOLATED, violations[0].describe()
    else:
        status, message = PlanStatus.CONVERGED, "every constraint holds between samples"
    return PlanVerdict(status, tuple(violations), message)


def seabed_violations(
    names: tuple[str, ...], profiles: tuple[DepthProfile, ...]
) -> list[Violation]:
    """Vehicles whose depth profile comes nearer the seabed than their ``min_altitude`` [m].

    The profile (:mod:`auvplan.mission.depth_profile`) keeps the bound wherever the seabed
    between neighbouring samples is at least ``min_altitude`` deep; over a shallower seabed
    it stays at the surface, closer than allowed.
    """
    violations = []
    for name, profile in zip(names, profiles, strict=True):
        value, when = _worst(profile.clearance, profile.time, largest=False)
        if value < profile.min_altitude - DISTANCE_TOLERANCE:
            advice = (
                "the seabed there is shallower than the vehicle's [vertical] min_altitude: add "
                "an obstacle over the shoal, move the start or goal, or lower min_altitude"
            )
            violations.append(
                Violation("seabed clearance", name, value, profile.min_altitude, when, advice)
            )
    return violations


def _battery_violations(
    config: MissionConfig, names: tuple[str, ...], battery: BatteryUse
) -> list[Violation]:
    """Vehicles whose energy exceeds ``C (1 − f)``, ``f`` = ``mission.reserve_fraction``."""
    reserve = config.mission.reserve_fraction
    violations = []
    for i, capacity in enumerate(battery.capacity):
        if capacity is None:
            continue
        usable = capacity * (1.0 - reserve)
        used = battery.used[i]
        if used[-1] <= usable:
            continue
        when = float(battery.time[int(np.argmax(used > usable))])
        advice = (
            f"that is battery_capacity {capacity:.1f} J x (1 - mission.reserve_fraction "
            f"{reserve:g}); to fit, fly nearer the energy-optimal cruise speed (auvplan vehicle "
            f"{config.vehicles[i].type}) by changing fleet.horizon_s, lower "
            "mission.reserve_fraction or give the vehicle a larger [power] battery_capacity"
        )
        violations.append(
            Violation("battery reserve", names[i], float(used[-1]), usable, when, advice, "J")
        )
    return violations


def _navigation_violations(
    config: MissionConfig,
    names: tuple[str, ...],
    budget: float,
    predicted: tuple[ErrorPrediction, ...],
    routes: tuple[NavigationChoice, ...] | None,
) -> list[Violation]:
    """Vehicles whose predicted error exceeds the budget [m] after ``settle_s`` (with slack)."""
    violations = []
    for i, prediction in enumerate(predicted):
        late = prediction.time - prediction.time[0] >= config.navigation.settle
        if not np.any(late):
            continue
        value, when = _worst(prediction.sigma[late], prediction.time[late], largest=True)
        if value <= budget * (1.0 + NAVIGATION_TOLERANCE):
            continue
        floor = None if routes is None else routes[i].smallest_budget_m
        advice = (
            "raise navigation.max_error_m or settle_s, or weights.terrain"
            if floor is None
            else f"no route meets it: the smallest budget any route meets is "
            f"{smallest_budget(floor):g} m; raise navigation.max_error_m or settle_s"
        )
        violations.append(Violation("navigation error", names[i], value, budget, when, advice))
    return violations
