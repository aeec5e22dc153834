"""Vehicle models: planar 3-DOF dynamics, actuators, propellers, motors, simulation, trim.

A vehicle is a hull and a list of actuators: thrusters (four-quadrant or linear propellers
driven by DC motors) and control surfaces.

Typical use::

    from auvplan.io.vehicles import load_vehicle
    from auvplan.vehicle import build_vehicle_model, rk4_simulate, trim_surge

    model = build_vehicle_model(load_vehicle("medusa"))   # or "remus100", or a vehicle file
    model.dynamics(x, c)      # casadi.Function f(x[n_x], c[n_u]) -> xdot[n_x]
    model.power(x, c)         # electrical power incl. hotel load [W]
    n, power = trim_surge(model, 1.0)
"""

from __future__ import annotations

from auvplan.vehicle.actuators import (
    ActuatedVehicleParams,
    ControlSurfaceParams,
    ThrusterParams,
    actuated_vehicle,
)
from auvplan.vehicle.approximation import (
    ApproximationError,
    SmoothingEffect,
    approximation_error_table,
    smoothing_effect,
)
from auvplan.vehicle.dynamics import (
    INPUT_NAMES,
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
    turning_radius,
)
from auvplan.vehicle.operating import ActuatorRoles, actuator_roles, operating_state
from auvplan.vehicle.params import (
    CrossFlowParams,
    HullParams,
    LinearPropellerParams,
    MotorParams,
    PropellerParams,
    VehicleParams,
)
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
    SteadyTurn,
    SurgeTrim,
    TurnTrim,
    VehicleCharacteristics,
    bollard,
    energy_per_metre,
    max_yaw_rate,
    optimal_cruise_speed,
    steady_motion,
    steady_turn,
    tightest_turn,
    top_speed,
    trim_surge,
    trim_turn,
    vehicle_characteristics,
)
from auvplan.vehicle.vertical import DepthLimits

__all__ = [
    "INPUT_NAMES",
    "STATE_NAMES",
    "STATE_UNITS",
    "ActuatedVehicleParams",
    "ActuatorRoles",
    "AdaptiveSimulation",
    "ApproximationError",
    "BollardPull",
    "ControlSurfaceParams",
    "CrossFlowParams",
    "CruiseOptimum",
    "DepthLimits",
    "HullParams",
    "LinearPropellerParams",
    "MotorParams",
    "PropellerParams",
    "SimulationStatus",
    "SmoothingEffect",
    "SteadyMotion",
    "SteadyTurn",
    "SurgeTrim",
    "ThrusterParams",
    "TurnTrim",
    "VehicleCharacteristics",
    "VehicleModel",
    "VehicleParams",
    "actuated_vehicle",
    "actuator_roles",
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
    "operating_state",
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
    "steady_turn",
    "surge_trim_table",
    "thrust_coefficient",
    "tightest_turn",
    "top_speed",
    "torque_coefficient",
    "trim_surge",
    "trim_turn",
    "turning_radius",
    "vehicle_characteristics",
    "vessel_dynamics",
]
