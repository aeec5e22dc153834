"""The vehicle models of a mission's vehicle types, built once per type and propeller order."""

from __future__ import annotations

from functools import cache

from auvplan.io.vehicles import load_vehicle
from auvplan.vehicle import VehicleModel, build_vehicle_model


@cache
def vehicle_model(vehicle_type: str, propeller_order: int | None) -> VehicleModel:
    """The model of a vehicle type (cached per type and order; the order is capped)."""
    params = load_vehicle(vehicle_type)
    if propeller_order is not None:
        propeller_order = min(propeller_order, params.propeller.max_order)
    return build_vehicle_model(params, propeller_order=propeller_order)
