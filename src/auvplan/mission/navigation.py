r"""Navigation-aware pre-planning of a mission: what navigation a route buys, and its price.

Each vehicle's route comes from the belief-space search (:mod:`auvplan.planning.belief`) on
the mission's ``[navigation]`` model (:class:`~auvplan.mission.tables.NavigationConfig`, the
same model ``auvplan evaluate`` flies). Its edges cost length (times the current's time
ratio): the energy-only route is the shortest. The predicted error is the information
recursion of :mod:`auvplan.navigation.prediction` at the vehicle's nominal speed ``U``
(``U T`` metres between TAN updates; the budget applies after ``settle_s · U`` metres).

* **Budget** (``max_error_m`` given): the cheapest route whose predicted 1-σ radial error
  stays within it. If no route does, the cheapest route within the smallest budget any
  route meets (its ``smallest_budget_m``), and a warning naming where the shortest route
  breaks the budget: the plan then fails its check (exit 3) with that smallest budget.
* **Automatic** (no ``max_error_m``): the route of least predicted RMS error within
  ``max_energy_increase`` over the energy-only plan's energy (that of the straight line from
  start to goal where it is clear, which that plan flies; else of the shortest route), found
  as the Lagrangian of that problem: searches with a soft price ``λ ∫ σ² ds`` on the error
  variance, ``λ`` bisected on a log scale (:data:`PRICE_DECADES`, :data:`PRICE_STEPS`) for
  the largest price whose route is within the energy cap (the route's length grows with
  ``λ``), each search kept within the shortest route's peak error (which bounds its σ
  bins). The route of least RMS error
  among those within the cap is taken if it cuts the shortest route's RMS by at least
  ``min_error_reduction``, else the shortest route. Energy of a route of length
  ``L``: ``P(L / T) T`` with a fixed horizon ``T`` (faster on a longer route), ``e(U) L``
  at a cruise speed (``P`` the vehicle's steady power, ``e`` its energy per metre).

``weights.navigation`` [W/m²] adds ``λ σ² / U`` joules per metre to every edge (a soft
price on the predicted error variance, integrated over time).

The optimiser tracks a route (``weights.terrain``) only where it pays for navigation or has
to go around land or a polygon; a vehicle whose route is the shortest one, with a straight
line clear of both, gets the energy-optimal plan (tracking weight 0).
"""

from __future__ import annotations

import dataclasses
import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Final

import numpy as np

from auvplan._typing import FloatArray
from auvplan.mission.config import MissionConfig
from auvplan.mission.tables import NavigationConfig
from auvplan.navigation import Track, process_noise_sigma
from auvplan.navigation.prediction import ErrorPrediction, fisher_map, predict_error
from auvplan.planning import Route, path_length
from auvplan.planning.belief import BeliefModel
from auvplan.planning.route import BudgetInfeasible
from auvplan.terrain import BathymetryGrid, TerrainMaps
from auvplan.vehicle import VehicleModel, optimal_cruise_speed
from auvplan.vehicle.trim import energy_per_metre, top_speed, trim_surge

logger = logging.getLogger(__name__)

#: The automatic mode's prices ``λ`` span ``PRICE_DECADES`` decades either side of
#: ``1 / σ_rms²`` of the shortest route (the price at which its error term equals its length)
#: and are bisected ``PRICE_STEPS`` times on ``log λ`` (to 6 / 2⁸ of a decade).
PRICE_DECADES: Final = 3.0
PRICE_STEPS: Final = 8

#: One search: a belief model and whether to minimise the peak error instead of the cost.
RouteSearch = Callable[[BeliefModel, bool], Route]


@dataclass(frozen=True)
class NavigationChoice:
    """How a vehicle's route was chosen, and what it predicts (errors in metres).

    ``mode``: ``"budget"`` or ``"automatic"``; ``budget_m``: the budget the route meets
    (None: the energy-only route); ``peak_m`` / ``rms_m``: predicted peak error after settling
    and RMS error along the route; ``energy_only_*``: the same for the shortest route;
    ``energy_increase``: predicted extra energy of the route over the energy-only plan's, the
    straight line where it is clear, else the shortest route (fraction); ``searches``: the
    searches run; ``smallest_budget_m``: when no route meets the budget, the smallest one
    any route meets (the route is then within it), and ``message`` says where the shortest
    route breaks the budget; ``straight_clear``: whether the straight line from start to goal
    keeps clear of land, no-data cells and polygons (which only the routes avoid);
    ``price_w_m2``: the automatic route's price on the error variance, in the units of
    ``weights.navigation`` [W/m²] (None: not priced).
    """

    mode: str
    budget_m: float | None
    peak_m: float
    rms_m: float
    energy_only_peak_m: float
    energy_only_rms_m: float
    energy_increase: float
    searches: int
    smallest_budget_m: float | None = None
    message: str = ""
    straight_clear: bool = False
    price_w_m2: float | None = None

    @property
    def pays_for_navigation(self) -> bool:
        """Whether the route differs from the shortest one to lower the predicted error."""
        return self.rms_m < self.energy_only_rms_m

    @property
    def tracked(self) -> bool:
        """Whether the optimiser must follow the route.

        It must when the route buys navigation or the straight line is not clear (the
        optimiser itself avoids only circles and the other vehicles).
        """
        return self.pays_for_navigation or not self.straight_clear

    @property
    def budget_met(self) -> bool:
        """Whether the route meets the mission's budget (always without one)."""
        return self.smallest_budget_m is None

    def document(self) -> dict[str, Any]:
        """The ``summary.json`` entry."""
        return {
            "mode": self.mode,
            "budget_m": self.budget_m,
            "route_predicted_peak_m": self.peak_m,
            "route_predicted_rms_m": self.rms_m,
            "energy_only_route_predicted_peak_m": self.energy_only_peak_m,
            "energy_only_route_predicted_rms_m": self.energy_only_rms_m,
            "route_energy_increase": self.energy_increase,
            "searches": self.searches,
            "smallest_feasible_budget_m": self.smallest_budget_m,
            "navigation_price_w_m2": self.price_w_m2,
            "tracked_by_the_optimiser": self.tracked,
        }


@dataclass(frozen=True)
class VehicleNavigation:
    """One vehicle's belief model (no budget) and route energy, to choose its route.

    ``energy(L)`` [J] of a route of length ``L`` [m]; ``power`` [W] converts the model's
    ``error_weight`` [1/m²] to ``weights.navigation`` [W/m²]; ``straight`` [m] is the
    distance from start to goal.
    """

    name: str
    model: BeliefModel
    energy: Callable[[float], float]
    power: float
    straight: float
    max_error: float | None
    max_energy_increase: float
    min_error_reduction: float

    def route(self, search: RouteSearch, straight_clear: bool) -> tuple[Route, NavigationChoice]:
        """The vehicle's route by its budget or automatically (module notes).

        ``straight_clear``: whether the straight line from start to goal is clear, so that
        the energy-only plan flies it (the energy the route's increase is measured from:
        ``straight`` metres, else the shortest route's length).
        """
        cheapest = search(self.model, False)
        shortest = self.straight if straight_clear else path_length(cheapest.points)
        base_energy = self.energy(shortest)
        base_peak, base_rms = _peak(cheapest), route_rms(cheapest)
        searches = 1

        def choice(
            route: Route, mode: str, budget: float | None, smallest: float | None = None
        ) -> NavigationChoice:
            increase = (
                self.energy(path_length(route.points)) / base_energy - 1.0
                if route is not cheapest
                else 0.0  # the energy-only plan
            )
            message = "" if smallest is None else self._budget_message(cheapest, smallest)
            return NavigationChoice(
                mode, budget, _peak(route), route_rms(route), base_peak, base_rms, increase,
                searches, smallest, message, straight_clear,
            )  # fmt: skip

        if self.max_error is not None:
            if base_peak <= self.max_error:
                return cheapest, choice(cheapest, "budget", self.max_error)
            try:
                searches += 1
                route = search(self.with_budget(self.max_error), False)
            except BudgetInfeasible:
                lowest = search(self.model, True)
                floor = _peak(lowest)
                searches += 2
                try:  # the cheapest route within it (coarser bins may miss it: the lowest one)
                    route = search(self.with_budget(floor + self.model.bin_width), False)
                except BudgetInfeasible:
                    route = lowest
                unmet = choice(route, "budget", self.max_error, floor)
                logger.info("%s", unmet.message)  # the plan's verdict tells the user
                return route, unmet
            return route, choice(route, "budget", self.max_error)
        if base_peak <= 0.0:  # the route ends within settle_s: nothing to buy
            return cheapest, choice(cheapest, "automatic", None)
        cap = (1.0 + self.max_energy_increase) * base_energy
        scale = 1.0 / base_rms**2

        def price(exponent: float) -> float:
            """The model's price [1/m²]: its own ``error_weight`` plus ``scale 10^exponent``."""
            return float(self.model.error_weight + scale * 10.0**exponent)

        def priced(exponent: float) -> Route | None:
            """The route at :func:`price` ``(exponent)`` if it is within the cap."""
            nonlocal searches
            searches += 1
            model = dataclasses.replace(
                self.model, max_error=base_peak, error_weight=price(exponent)
            )
            try:
                found = search(model, False)
            except BudgetInfeasible:  # coarse σ bins may lose the shortest route itself
                return None
            return found if self.energy(path_length(found.points)) <= cap else None

        best, best_exponent = cheapest, None
        low, high = -PRICE_DECADES, PRICE_DECADES
        found = priced(high)
        if found is not None:  # the least error any route buys is within the cap
            best, best_exponent = found, high
        for _ in range(PRICE_STEPS if found is None else 0):
            middle = 0.5 * (low + high)
            found = priced(middle)
            if found is None:
                high = middle
                continue
            low = middle
            if route_rms(found) < route_rms(best):
                best, best_exponent = found, middle
        if best_exponent is None or route_rms(best) > (1.0 - self.min_error_reduction) * base_rms:
            return cheapest, choice(cheapest, "automatic", None)
        chosen = choice(best, "automatic", base_peak)
        return best, dataclasses.replace(chosen, price_w_m2=price(best_exponent) * self.power)

    def with_budget(self, budget: float) -> BeliefModel:
        """The model with a budget [m]."""
        return dataclasses.replace(self.model, max_error=budget)

    def _budget_message(self, cheapest: Route, floor: float) -> str:
        """One line: where the cheapest route breaks the budget, and the smallest budget."""
        assert cheapest.predicted_error is not None
        assert self.max_error is not None
        steps = np.hypot(*np.diff(cheapest.points, axis=0).T)
        distance = np.concatenate([[0.0], np.cumsum(steps)])
        late = distance > self.model.settle_distance
        late &= cheapest.predicted_error > self.max_error
        where = int(np.argmax(late))
        north, east = cheapest.points[where]
        return (
            f"vehicle {self.name}: no route keeps the predicted navigation error within "
            f"navigation.max_error_m = {self.max_error:g} m; the shortest route exceeds it "
            f"{distance[where]:.0f} m from the start (north {north:.0f} m, east {east:.0f} m), "
            f"and the smallest budget any route meets is {smallest_budget(floor):g} m "
            "(raise max_error_m or settle_s)"
        )


def smallest_budget(floor: float) -> float:
    """A route's smallest peak error [m] rounded up to the decimetre, as users are told."""
    return math.ceil(floor * 10.0) / 10.0


def route_rms(route: Route) -> float:
    """RMS of a route's predicted error [m], weighted by the length flown at each cell."""
    assert route.predicted_error is not None
    if route.predicted_error.size == 1:  # start and goal in one cell: two points, one cell
        return float(route.predicted_error[0])
    steps = np.hypot(*np.diff(route.points, axis=0).T)
    weights = np.concatenate([[0.0], steps]) + np.concatenate([steps, [0.0]])
    if not np.any(weights > 0.0):
        return float(route.predicted_error[0])
    return float(np.sqrt(np.average(route.predicted_error**2, weights=weights)))


def _peak(route: Route) -> float:
    assert route.peak_error is not None
    return route.peak_error


def vehicle_navigation(
    maps: TerrainMaps,
    navigation: NavigationConfig,
    names: tuple[str, ...],
    models: tuple[VehicleModel, ...] | list[VehicleModel],
    straight: FloatArray,
    *,
    horizon: float | None,
    cruise_speed: float | None,
    vehicle_depth: float,
    weight: float,
    altitude: float | None = None,
) -> tuple[VehicleNavigation, ...]:
    """The :class:`VehicleNavigation` of each vehicle.

    Parameters
    ----------
    maps : TerrainMaps
        The mission's maps (the cost grid is the search grid).
    navigation : NavigationConfig
        The mission's ``[navigation]`` table.
    names, models : sequence
        The vehicles and their models.
    straight : ndarray of shape (n_vehicles,)
        Straight start-goal distances [m].
    horizon, cruise_speed : float or None
        ``fleet.horizon_s`` [s] or ``fleet.cruise_speed`` [m/s] (neither: each vehicle's
        energy-optimal cruise speed).
    vehicle_depth : float
        Depth of the plan [m] (the altimeter's range is the seabed below it).
    weight : float
        ``weights.navigation`` [W/m²].
    altitude : float, optional
        ``mission.altitude_m`` [m]: the vehicles follow the seabed at this height instead of
        flying at ``vehicle_depth`` (:func:`~auvplan.navigation.prediction.fisher_map`).
    """
    settings = navigation.settings(vehicle_depth=vehicle_depth)
    fisher = fisher_map(maps.bathymetry, maps.cost_geometry, settings.sensor, altitude=altitude)
    vehicles = []
    for name, model, distance in zip(names, models, straight, strict=True):
        fastest = top_speed(model)
        if horizon is not None:
            speed = min(max(float(distance) / horizon, 0.05), fastest)
        else:
            speed = cruise_speed if cruise_speed is not None else optimal_cruise_speed(model).speed
        per_metre = energy_per_metre(model, speed)
        energy = (
            _horizon_energy(model, horizon, fastest)
            if horizon is not None
            else _cruise_energy(per_metre)
        )
        step = speed * settings.update_period
        process = float(process_noise_sigma(settings.motion, np.array([[step, 0.0]]))[0] ** 2)
        model_nav = BeliefModel(
            fisher,
            updates_per_metre=1.0 / step,
            drift_rate=settings.motion.bias_sigma,
            process_variance=process,
            initial_sigma=settings.filter.initial_sigma,
            settle_distance=navigation.settle * speed,
            error_weight=weight / (speed * per_metre),
        )
        vehicles.append(
            VehicleNavigation(
                name, model_nav, energy, speed * per_metre, float(distance), navigation.max_error,
                navigation.max_energy_increase, navigation.min_error_reduction,
            )
        )  # fmt: skip
    return tuple(vehicles)


def _horizon_energy(
    model: VehicleModel, horizon: float, fastest: float
) -> Callable[[float], float]:
    """Energy [J] of a route of length ``L`` [m] flown in ``horizon`` [s]: ``P(L/T) T``."""

    def energy(length: float) -> float:
        speed = length / horizon
        return trim_surge(model, speed).power * horizon if speed <= fastest else math.inf

    return energy


def _cruise_energy(per_metre: float) -> Callable[[float], float]:
    """Energy [J] of a route of length ``L`` [m] at a cruise speed: ``e L``."""
    return lambda length: per_metre * length


def predict_tracks(
    navigation: NavigationConfig,
    bathymetry: BathymetryGrid,
    time: FloatArray,
    tracks: FloatArray,
    headings: FloatArray,
    *,
    vehicle_depth: float,
    depths: tuple[FloatArray, ...] | None = None,
) -> tuple[ErrorPrediction, ...]:
    """The predicted TAN error along each vehicle's flown track (the evaluator's model).

    ``navigation`` is the mission's ``[navigation]`` table; ``time`` ``(n_t,)`` [s],
    ``tracks`` ``(n_vehicles, n_t, 2)`` north/east [m], ``headings`` ``(n_vehicles, n_t)``
    [rad]; ``vehicle_depth`` [m] the plan's depth, or ``depths`` each vehicle's depth
    profile ``(n_t,)`` [m] (:mod:`auvplan.mission.depth_profile`) when it varies.
    """
    settings = navigation.settings(vehicle_depth=vehicle_depth)
    if time[-1] - time[0] < settings.update_period:  # shorter than one update: the prior
        settings = dataclasses.replace(settings, update_period=float(time[-1] - time[0]))
    profiles = depths if depths is not None else (None,) * len(tracks)
    return tuple(
        predict_error(bathymetry, Track(time, track, heading, depth), settings)
        for track, heading, depth in zip(tracks, headings, profiles, strict=True)
    )


def budget_of(config: MissionConfig) -> float | None:
    """The mission's explicit navigation budget [m], if its routes are navigation-aware."""
    if config.planner.edge_model != "navigation":
        return None
    return config.navigation.max_error
