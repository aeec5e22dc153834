"""Evaluation of an optimised plan: energy, information, arrival, replay, separation.

Separation is measured on the plan flown with its tracking regulator on a grid
``CHECK_REFINEMENT`` times finer than the solver's (:func:`auvplan.mission.verify.
replay_closed_loop`), so that it holds between the solver's samples as well.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np
from scipy.integrate import cumulative_trapezoid
from scipy.interpolate import RegularGridInterpolator

from auvplan._typing import FloatArray
from auvplan.mission.checks import BatteryUse, PlanVerdict, judge_plan
from auvplan.mission.config import MissionConfig
from auvplan.mission.costs import CostBreakdown, constraint_slack, cost_breakdown
from auvplan.mission.depth_profile import DepthProfile, fleet_depth_profiles
from auvplan.mission.fleet import FleetProblemFunctions
from auvplan.mission.navigation import predict_tracks
from auvplan.mission.preplan import PreplanStage
from auvplan.mission.verify import replay_closed_loop
from auvplan.navigation.prediction import ErrorPrediction
from auvplan.optimization import ProntoResult, TrajectoryProblem
from auvplan.planning import distance_to_obstacle
from auvplan.record.labels import Pair
from auvplan.terrain import TerrainMaps
from auvplan.vehicle import headings, positions

#: Refinement of the solver grid for the certified-separation resimulation.
CHECK_REFINEMENT: Final = 10


@dataclass(frozen=True)
class OptimizedPlan:
    """Stage 3 for one weighting: the PRONTO result and the fleet's trajectories.

    ``states[i]`` ``(n_t, n_x_i)`` and ``inputs[i]`` ``(n_t - 1, n_u_i)`` are vehicle ``i``'s
    own states and inputs (vehicles may differ in size), ``power`` ``(n_vehicles, n_t)`` [W],
    ``energy`` ``(n_vehicles,)`` [J] = trapezoidal ∫ power dt,
    ``arrival_error`` ``(n_vehicles,)`` [m], ``terrain_information`` ``(n_vehicles,)`` mean
    information-map value along the trajectory; ``separations[name][other]`` the minimum
    distance [m] to each other vehicle (centre to centre) and obstacle (to its edge; polygons
    are enforced by the pre-planner and only checked here) when the plan is flown with its
    tracking regulator on a grid ``CHECK_REFINEMENT`` times finer than the solver's, whose
    time series are ``fine_distances`` (by :class:`~auvplan.record.labels.Pair`) on
    ``fine_time``;
    ``tracking_error`` ``(n_vehicles,)`` is that replay's largest distance [m] from the plan at
    the solver nodes. ``predicted_navigation`` is the predicted TAN error along each replayed
    track (:func:`auvplan.mission.navigation.predict_tracks`), flown at each vehicle's depth
    profile ``depth_profiles`` for ``[mission] altitude_m`` (``None``: the constant
    ``depth_m``; :mod:`auvplan.mission.depth_profile`). ``verdict`` says whether every
    constraint holds between samples (:func:`auvplan.mission.checks.judge_plan`). ``costs`` is
    the objective by named term and ``constraint_slack[block][pair]`` the smallest value of
    each constraint row at the solver nodes (:mod:`auvplan.mission.costs`). ``fleet_solve``
    says how stage 3 solved the fleet: ``"coupled"`` or ``"decomposed"``
    (:mod:`auvplan.mission.decomposition`).
    """

    result: ProntoResult
    terrain_weight: float
    states: tuple[FloatArray, ...]
    inputs: tuple[FloatArray, ...]
    power: FloatArray
    energy: FloatArray
    arrival_error: FloatArray
    terrain_information: FloatArray
    separations: dict[str, dict[str, float]]
    fine_time: FloatArray
    fine_distances: dict[Pair, FloatArray]
    tracking_error: FloatArray
    predicted_navigation: tuple[ErrorPrediction, ...]
    depth_profiles: tuple[DepthProfile, ...] | None
    verdict: PlanVerdict
    costs: CostBreakdown
    constraint_slack: dict[str, dict[str, float]]
    fleet_solve: str = "coupled"


def evaluate_plan(
    config: MissionConfig,
    preplan: PreplanStage,
    time: FloatArray,
    dt: float,
    problem: TrajectoryProblem,
    functions: FleetProblemFunctions,
    result: ProntoResult,
    terrain_weight: float,
    fleet_solve: str = "coupled",
) -> OptimizedPlan:
    """Energy, information, arrival error and sampled-and-between separations of a result.

    ``time`` is the solver grid of control interval ``dt`` [s]; ``problem`` and ``functions``
    the solved fleet problem (for the cost terms and constraint slacks); ``fleet_solve`` how
    it was solved (:attr:`OptimizedPlan.fleet_solve`).
    """
    layout = functions.layout
    models = layout.models
    flat_states, flat_inputs = result.trajectory.states, result.trajectory.inputs
    states = tuple(np.ascontiguousarray(x) for x in layout.unstack_states(flat_states))
    inputs = tuple(np.ascontiguousarray(c) for c in layout.unstack_inputs(flat_inputs))
    held = np.vstack([flat_inputs, flat_inputs[-1:]])
    power_map = functions.power.map(time.size, "serial")
    power = np.asarray(power_map(flat_states.T, held.T)).reshape(layout.n_vehicles, time.size)
    used = np.asarray(cumulative_trapezoid(power, time, axis=1, initial=0.0), dtype=np.float64)
    energy = np.ascontiguousarray(used[:, -1])
    planned = np.stack([positions(model, states[i]) for i, model in enumerate(models)])
    arrival = np.hypot(*(planned[:, -1] - preplan.goals[:, :2]).T)
    information = information_along(preplan.maps, planned)

    flown = [
        replay_closed_loop(
            model,
            states[i],
            inputs[i],
            layout.gains_of(result.regulator_gains, i),
            dt,
            refinement=CHECK_REFINEMENT,
            current=preplan.current,
        )
        for i, model in enumerate(models)
    ]
    fine = np.stack([positions(model, flown[i]) for i, model in enumerate(models)])
    fine_time = dt / CHECK_REFINEMENT * np.arange(fine.shape[1], dtype=np.float64)
    tracking_error = np.max(np.linalg.norm(fine[:, ::CHECK_REFINEMENT] - planned, axis=-1), axis=1)
    fine_distances, separations = pairwise_distances(preplan, fine)
    profiles = fleet_depth_profiles(
        config.mission.altitude, preplan.bathymetry, time, planned,
        tuple(model.vehicle.depth_limits for model in models),
    )  # fmt: skip
    predicted = predict_tracks(
        config.navigation, preplan.bathymetry, fine_time, fine,
        np.stack([headings(model, flown[i]) for i, model in enumerate(models)]),
        vehicle_depth=config.mission.depth,
        depths=None if profiles is None else tuple(
            np.interp(fine_time, time, profile.depth) for profile in profiles
        ),
    )  # fmt: skip
    return OptimizedPlan(
        result=result,
        terrain_weight=terrain_weight,
        states=states,
        inputs=inputs,
        power=power,
        energy=energy,
        arrival_error=arrival,
        terrain_information=information,
        separations=separations,
        fine_time=fine_time,
        fine_distances=fine_distances,
        tracking_error=tracking_error,
        predicted_navigation=predicted,
        depth_profiles=profiles,
        costs=cost_breakdown(problem, functions, result.trajectory),
        constraint_slack=constraint_slack(problem, functions, result.trajectory),
        verdict=judge_plan(
            config,
            preplan.names,
            result,
            fine_time,
            fine_distances,
            arrival,
            predicted,
            preplan.navigation,
            BatteryUse(time, used, tuple(model.vehicle.battery_capacity for model in models)),
            profiles,
        ),
        fleet_solve=fleet_solve,
    )


def pairwise_distances(
    preplan: PreplanStage, tracks: FloatArray
) -> tuple[dict[Pair, FloatArray], dict[str, dict[str, float]]]:
    """Distance series between every pair and to every obstacle, and their minima.

    ``tracks`` ``(n_vehicles, n_t, 2)`` north/east [m]. Returns the series by
    :class:`~auvplan.record.labels.Pair` and ``minima[a][b]`` (symmetric between vehicles) [m].
    """
    names = preplan.names
    series: dict[Pair, FloatArray] = {}
    minima: dict[str, dict[str, float]] = {name: {} for name in names}
    for i, name in enumerate(names):
        for j in range(i + 1, len(names)):
            distance = np.hypot(*(tracks[i] - tracks[j]).T)
            series[Pair(name, names[j])] = distance
            minima[name][names[j]] = minima[names[j]][name] = float(np.min(distance))
        for obstacle, label in zip(preplan.obstacles, preplan.obstacle_names, strict=True):
            distance = distance_to_obstacle(obstacle, *tracks[i].T)
            series[Pair(name, label)] = distance
            minima[name][label] = float(np.min(distance))
    return series, minima


def information_along(maps: TerrainMaps, tracks: FloatArray) -> FloatArray:
    """Mean information-map value (eq. 13, fine grid) along each track ``(n_t, 2)``."""
    geometry = maps.bathymetry.geometry
    field = np.nan_to_num(maps.information, nan=0.0)
    interpolator = RegularGridInterpolator(
        (geometry.north, geometry.east), field, bounds_error=False, fill_value=0.0
    )
    return np.array([float(np.mean(interpolator(track))) for track in tracks])
