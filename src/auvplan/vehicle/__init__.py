"""Vehicle models: MEDUSA 3-DOF dynamics, four-quadrant propellers, DC motors, simulation, trim."""

from __future__ import annotations

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
from auvplan.vehicle.params import HullParams, MotorParams, PropellerParams, VehicleParams
from auvplan.vehicle.propulsion import (
    open_water_thrust_torque,
    thrust_coefficient,
    torque_coefficient,
)

__all__ = [
    "INPUT_NAMES",
    "STATE_NAMES",
    "STATE_UNITS",
    "HullParams",
    "MotorParams",
    "PropellerParams",
    "VehicleModel",
    "VehicleParams",
    "build_vehicle_model",
    "electrical_power",
    "energy",
    "open_water_thrust_torque",
    "thrust_coefficient",
    "torque_coefficient",
    "vessel_dynamics",
]
