"""Navigation along a mission's plans: Monte-Carlo TAN per vehicle and the ``navigation.json`` data.

Plans (``terrain_aware``, ``energy_only``, ...) are compared on common random numbers: vehicle
``v``'s runs use the seed ``[seed, v]`` in every plan, so both plans see the same initial
errors, dead-reckoning biases and noise draws, and their difference is not sampling noise.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from auvplan._typing import FloatArray
from auvplan._version import __version__
from auvplan.navigation.metrics import (
    CONVERGENCE_SIGMA_M,
    DIVERGENCE_SIGMAS,
    DIVERGENCE_UPDATES,
    rmse,
)
from auvplan.navigation.montecarlo import (
    MonteCarloResult,
    NavigationSettings,
    Track,
    check_monte_carlo,
    run_monte_carlo,
)
from auvplan.navigation.prediction import ErrorPrediction, predict_error
from auvplan.terrain import BathymetryGrid

#: Progress callback: ``(plan label, vehicle name, runs finished)``.
EvaluationProgress = Callable[[str, str, int], None]


@dataclass(frozen=True)
class VehiclePlan:
    """One vehicle's planned track and the energy [J] the plan spends on it."""

    track: Track
    energy: float


@dataclass(frozen=True)
class PlanNavigation:
    """Monte-Carlo navigation of every vehicle of one plan, and the plan's energy.

    ``predictions``: the error the planner's model predicts along each track
    (:func:`~auvplan.navigation.prediction.predict_error`).
    """

    results: dict[str, MonteCarloResult]
    energy: dict[str, float]
    predictions: dict[str, ErrorPrediction] = dataclasses.field(default_factory=dict)


def evaluate_plans(
    grid: BathymetryGrid,
    plans: Mapping[str, Mapping[str, VehiclePlan]],
    settings: NavigationSettings,
    *,
    n_runs: int,
    seed: int,
    workers: int | None = None,
    progress: EvaluationProgress | None = None,
) -> dict[str, PlanNavigation]:
    """Run :func:`~auvplan.navigation.run_monte_carlo` for every vehicle of every plan.

    Parameters
    ----------
    grid : BathymetryGrid
        The bathymetry the plans were made on.
    plans : mapping of str to mapping of str to VehiclePlan
        ``plans[label][vehicle]``; a vehicle keeps its index (its seed) across plans by its
        position in the first plan.
    settings : NavigationSettings
        The navigation system.
    n_runs : int
        Runs per vehicle and plan.
    seed : int
        Base seed (module notes).
    workers : int, optional
        Threads per vehicle's runs.
    progress : callable, optional
        Called after each run.

    Returns
    -------
    dict of str to PlanNavigation
        By plan label.

    Raises
    ------
    InputError
        If the runs along a track are refused
        (:func:`~auvplan.navigation.montecarlo.check_monte_carlo`); every track is checked
        before the first run.
    """
    for vehicles in plans.values():
        for vehicle in vehicles.values():
            check_monte_carlo(vehicle.track, settings, n_runs=n_runs, seed=seed)
    index: dict[str, int] = {}
    evaluations = {}
    for label, vehicles in plans.items():
        results = {}
        for name, vehicle in vehicles.items():
            number = index.setdefault(name, len(index))

            def report(done: int, label: str = label, name: str = name) -> None:
                if progress is not None:
                    progress(label, name, done)

            results[name] = run_monte_carlo(
                grid,
                vehicle.track,
                settings,
                n_runs=n_runs,
                seed=[seed, number],
                workers=workers,
                progress=report,
            )
        evaluations[label] = PlanNavigation(
            results,
            {name: vehicle.energy for name, vehicle in vehicles.items()},
            {name: predict_error(grid, v.track, settings) for name, v in vehicles.items()},
        )
    return evaluations


def navigation_summary(
    evaluations: Mapping[str, PlanNavigation],
    settings: NavigationSettings,
    *,
    n_runs: int,
    seed: int,
    plan_records: Mapping[str, Mapping[str, Any]] | None = None,
) -> dict[str, Any]:
    """The ``navigation.json`` document.

    Per plan: ``energy_J``, ``rmse_m`` (mean over vehicles and runs of the run RMSE) and its
    spread ``rmse_std_m``, ``error_p95_m`` and ``error_rms_m`` (95th percentile and root mean
    square of the error over every run and update: the latter is what the predicted 1-σ
    radial error estimates), ``predicted_rmse_m`` (the planner's predicted error, RMS along
    each track, mean over vehicles), ``dead_reckoning_rmse_m``, ``pcrb_rms_m``,
    ``convergence_time_s`` (median over the runs that converged), ``converged_fraction``,
    ``divergence_rate``, and the same per vehicle under ``vehicles`` (with percentiles, the
    final error, mean NEES and ESS).
    With both plans, ``comparison`` holds the RMSE reduction and energy increase of the
    terrain-aware plan (the mission's) over the energy-only one, and ``paper_comparison``
    those of the paper's plan when the folder has it. ``plan_records`` (``summary.json``'s plan
    entries) add each plan's ``terrain_weight`` and ``plan_status``.
    """
    records = plan_records or {}
    document: dict[str, Any] = {
        "auvplan_version": __version__,
        "settings": settings_document(settings, n_runs=n_runs, seed=seed),
        "plans": {},
    }
    for label, evaluation in evaluations.items():
        record = records.get(label, {})
        document["plans"][label] = {
            "terrain_weight": record.get("terrain_weight"),
            "plan_status": record.get("plan_status"),
            **_statistics(list(evaluation.results.values())),
            **_predicted(list(evaluation.predictions.values())),
            "energy_J": float(sum(evaluation.energy.values())),
            "vehicles": {
                name: {
                    "energy_J": evaluation.energy[name],
                    "distance_m": result.distance,
                    **_statistics([result]),
                    **_predicted([evaluation.predictions[name]] if evaluation.predictions else []),
                    **_vehicle_details(result),
                }
                for name, result in evaluation.results.items()
            },
        }
    plans = document["plans"]
    if "energy_only" in plans:
        for label, key in (("terrain_aware", "comparison"), ("paper", "paper_comparison")):
            if label in plans:
                document[key] = _comparison(plans[label], plans["energy_only"])
    return document


def _comparison(plan: Mapping[str, Any], energy_only: Mapping[str, Any]) -> dict[str, Any]:
    """A plan's TAN RMSE reduction and energy increase over the energy-only plan."""
    return {
        "rmse_reduction": 1.0 - plan["rmse_m"] / energy_only["rmse_m"],
        "energy_increase": plan["energy_J"] / energy_only["energy_J"] - 1.0,
        "target": "rmse_reduction >= 0.30 at energy_increase <= 0.10 (issues 13, 23)",
    }


def _predicted(predictions: list[ErrorPrediction]) -> dict[str, Any]:
    """The planner's predicted error along the tracks: mean RMS and mean final error [m]."""
    if not predictions:
        return {}
    return {
        "predicted_rmse_m": float(np.mean([p.rms for p in predictions])),
        "predicted_final_error_m": float(np.mean([p.sigma[-1] for p in predictions])),
    }


def _statistics(results: list[MonteCarloResult]) -> dict[str, Any]:
    """Aggregates over every run of ``results`` (one or several vehicles)."""
    run_rmse = np.concatenate([result.rmse for result in results])
    errors = np.concatenate([result.error.ravel() for result in results])
    convergence = np.concatenate([result.convergence_time for result in results])
    converged = convergence[np.isfinite(convergence)]
    return {
        "rmse_m": float(np.mean(run_rmse)),
        "rmse_std_m": float(np.std(run_rmse)),
        "error_p95_m": float(np.percentile(errors, 95)),
        "error_rms_m": float(np.sqrt(np.mean(errors**2))),
        "dead_reckoning_rmse_m": float(
            np.mean(np.concatenate([result.dead_reckoning_rmse for result in results]))
        ),
        "pcrb_rms_m": float(np.mean([rmse(result.pcrb_sigma) for result in results])),
        "convergence_time_s": float(np.median(converged)) if converged.size else None,
        "converged_fraction": float(converged.size / convergence.size),
        "divergence_rate": float(np.mean(np.concatenate([result.diverged for result in results]))),
    }


def _vehicle_details(result: MonteCarloResult) -> dict[str, Any]:
    """Per-vehicle extras: RMSE percentiles, final errors, consistency and filter health."""
    percentiles = np.percentile(result.rmse, [5, 50, 95])
    return {
        "rmse_percentiles_m": dict(zip(("p5", "p50", "p95"), map(float, percentiles), strict=True)),
        "final_error_m": float(np.mean(result.error[:, -1])),
        "dead_reckoning_final_error_m": float(np.mean(result.dead_reckoning_error[:, -1])),
        "rmse_to_pcrb": float(np.mean(result.rmse) / rmse(result.pcrb_sigma)),
        "mean_nees": float(np.mean(result.nees[np.isfinite(result.nees)])),
        "mean_ess": float(np.mean(result.ess)),
        "mean_resamples": float(np.mean(result.n_resamples)),
    }


def settings_document(settings: NavigationSettings, *, n_runs: int, seed: int) -> dict[str, Any]:
    """``navigation.json``'s ``settings``: every model parameter, the run count and the seed.

    Two evaluations with equal documents give equal results (the seed fixes every draw).
    """
    return {
        "n_runs": n_runs,
        "seed": seed,
        "update_period_s": settings.update_period,
        "sensor": dataclasses.asdict(settings.sensor),
        "dead_reckoning": dataclasses.asdict(settings.motion),
        "particle_filter": dataclasses.asdict(settings.filter),
        "convergence_rule": {
            "sigma_m": CONVERGENCE_SIGMA_M,
            "updates": settings.convergence_updates,
        },
        "divergence_rule": {"sigmas": DIVERGENCE_SIGMAS, "updates": DIVERGENCE_UPDATES},
    }


def time_series(result: MonteCarloResult) -> dict[str, FloatArray]:
    """Per-update curves for figures: RMS TAN and dead-reckoning errors, mean sigma, PCRB [m]."""
    return {
        "tan": rmse(result.error.T),
        "dead_reckoning": rmse(result.dead_reckoning_error.T),
        "sigma": np.mean(result.sigma, axis=0),
        "pcrb": result.pcrb_sigma,
    }
