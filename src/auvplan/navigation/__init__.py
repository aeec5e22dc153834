"""Terrain-aided navigation (TAN) simulator: how well a vehicle knows where it is along a plan.

A particle filter matches simulated seabed soundings (altimeter or multibeam) against the map
while dead reckoning drifts; Monte-Carlo runs along a planned track give the position error,
the filter's own uncertainty, convergence and divergence, and the posterior Cramér-Rao bound
of what the terrain allows. Defaults and their sources are in each model's docstring.
"""

from __future__ import annotations

from auvplan import _numba_cache  # noqa: F401 (damaged numba cache files heal: first)
from auvplan.navigation.depth import depth_at, depth_gradient_at
from auvplan.navigation.evaluation import (
    PlanNavigation,
    VehiclePlan,
    evaluate_plans,
    navigation_summary,
    settings_document,
)
from auvplan.navigation.filter import FilterTrace, ParticleFilterOptions, run_particle_filter
from auvplan.navigation.metrics import convergence_time, has_diverged, nees, rmse
from auvplan.navigation.montecarlo import (
    MonteCarloResult,
    NavigationSettings,
    Track,
    run_monte_carlo,
)
from auvplan.navigation.motion import (
    DeadReckoningModel,
    dead_reckon,
    process_noise_sigma,
    simulate_odometry,
)
from auvplan.navigation.pcrb import posterior_crb
from auvplan.navigation.sensors import (
    SensorModel,
    beam_geometry,
    simulate_soundings,
)

__all__ = [
    "DeadReckoningModel",
    "FilterTrace",
    "MonteCarloResult",
    "NavigationSettings",
    "ParticleFilterOptions",
    "PlanNavigation",
    "SensorModel",
    "Track",
    "VehiclePlan",
    "beam_geometry",
    "convergence_time",
    "dead_reckon",
    "depth_at",
    "depth_gradient_at",
    "evaluate_plans",
    "has_diverged",
    "navigation_summary",
    "nees",
    "posterior_crb",
    "process_noise_sigma",
    "rmse",
    "run_monte_carlo",
    "run_particle_filter",
    "settings_document",
    "simulate_odometry",
    "simulate_soundings",
]
