"""Vehicle models: MEDUSA 3-DOF dynamics, four-quadrant propellers, DC motors, simulation, trim.

Typical use::

    from auvplan.io.vehicles import load_vehicle
    from auvplan.vehicle import build_vehicle_model, rk4_simulate, trim_surge

    model = build_vehicle_model(load_vehicle("medusa"))
    model.dynamics(x, c)      # casadi.Function f(x[8], c[2]) -> xdot[8]
    model.power(x, c)         # electrical power incl. hotel load [W]
    n, power = trim_surge(model, 1.0)
"""

from __future__ import annotations

from auvplan.vehicle.approximation import (
    ApproximationError,
    SmoothingEffect,
    approximation_error_table,
    smoothing_effect,
)
from auvplan.vehicle.dynamics import (
    INPUT_NAMES,
    N_INPUTS,
    N_STATES,
    STATE_NAMES,
    STATE_UNITS,
    VehicleModel,
    build_vehicle_model,
    electrical_power,
    energy,
    vessel_dynamics,
)
from auvplan.vehicle.limits import (
    max_surge_acceleration,
    minimum_useful_speed,
    regulator_floor,
)
from auvplan.vehicle.params import HullParams, MotorParams, PropellerParams, VehicleParams
from auvplan.vehicle.propulsion import (
    open_water_thrust_torque,
    thrust_coefficient,
    torque_coefficient,
)
from auvplan.vehicle.reference import (
    headings,
    positions,
    reference_states,
    surge_trim_table,
)
from auvplan.vehicle.simulate import (
    AdaptiveSimulation,
    SimulationStatus,
    rk4_simulate,
    rk4_step_function,
    simulate_adaptive,
)
from auvplan.vehicle.stiffness import fastest_mode, stable_rk4_step
from auvplan.vehicle.trim import (
    BollardPull,
    CruiseOptimum,
    SteadyMotion,
    SurgeTrim,
    TurnTrim,
    VehicleCharacteristics,
    bollard,
    energy_per_metre,
    max_yaw_rate,
    optimal_cruise_speed,
    steady_motion,
    top_speed,
    trim_surge,
    trim_turn,
    vehicle_characteristics,
)

__all__ = [
    "INPUT_NAMES",
    "N_INPUTS",
    "N_STATES",
    "STATE_NAMES",
    "STATE_UNITS",
    "AdaptiveSimulation",
    "ApproximationError",
    "BollardPull",
    "CruiseOptimum",
    "HullParams",
    "MotorParams",
    "PropellerParams",
    "SimulationStatus",
    "SmoothingEffect",
    "SteadyMotion",
    "SurgeTrim",
    "TurnTrim",
    "VehicleCharacteristics",
    "VehicleModel",
    "VehicleParams",
    "approximation_error_table",
    "bollard",
    "build_vehicle_model",
    "electrical_power",
    "energy",
    "energy_per_metre",
    "fastest_mode",
    "headings",
    "max_surge_acceleration",
    "max_yaw_rate",
    "minimum_useful_speed",
    "open_water_thrust_torque",
    "optimal_cruise_speed",
    "positions",
    "reference_states",
    "regulator_floor",
    "rk4_simulate",
    "rk4_step_function",
    "simulate_adaptive",
    "smoothing_effect",
    "stable_rk4_step",
    "steady_motion",
    "surge_trim_table",
    "thrust_coefficient",
    "top_speed",
    "torque_coefficient",
    "trim_surge",
    "trim_turn",
    "vehicle_characteristics",
    "vessel_dynamics",
]
