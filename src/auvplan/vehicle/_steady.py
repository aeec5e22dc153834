"""Result types of the steady states and the equilibrium solver behind :mod:`.trim`."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from functools import cache
from typing import Final, NamedTuple

import casadi as ca
import numpy as np
from scipy.optimize import root

from auvplan._typing import FloatArray
from auvplan.errors import SolverError
from auvplan.vehicle.dynamics import VehicleModel

NU = slice(3, 6)


class SurgeTrim(NamedTuple):
    """Straight-line trim: every forward-pushing propeller at ``n``."""

    n: float
    """Propeller speed (the throttle) [rev/s]; may exceed ``n_max`` above the top speed."""
    power: float
    """Electrical power including the hotel load [W]."""


class TurnTrim(NamedTuple):
    """Steady turn of a twin-thruster vehicle at a given surge speed and yaw rate."""

    n_ps: float
    """Port propeller speed [rev/s]."""
    n_sb: float
    """Starboard propeller speed [rev/s]."""
    v: float
    """Steady sway speed [m/s]."""
    power: float
    """Electrical power including the hotel load [W]."""


class SteadyMotion(NamedTuple):
    """Steady body velocities for fixed propeller speeds."""

    u: float
    """Surge speed [m/s]."""
    v: float
    """Sway speed [m/s]."""
    r: float
    """Yaw rate [rad/s]."""


class SteadyTurn(NamedTuple):
    """A steady turn: the full state (at the origin, heading north) and its power."""

    state: FloatArray
    """State ``(0, 0, 0, u, v, r, actuators…)``, shape ``(n_x,)``."""
    power: float
    """Electrical power including the hotel load [W]."""

    @property
    def radius(self) -> float:
        """Radius of the circle ``sqrt(u² + v²)/|r|`` [m]."""
        u, v, r = self.state[NU]
        return float(math.hypot(u, v) / abs(r))


class BollardPull(NamedTuple):
    """Thrust and torque of one propeller at ``n_max`` with the vehicle held at rest."""

    thrust: float
    """Thrust per propeller (the first forward-pushing one) [N]."""
    torque: float
    """Shaft torque per propeller [N m]."""
    power: float
    """Electrical power of the vehicle, forward motors at ``n_max`` plus hotel load [W]."""


class CruiseOptimum(NamedTuple):
    """Energy-optimal straight-line cruise."""

    speed: float
    """Surge speed minimising energy per metre [m/s]."""
    energy_per_metre: float
    """``P(u)/u`` at that speed [J/m]."""


def nu_dot(model: VehicleModel, state: FloatArray) -> FloatArray:
    return np.asarray(model.dynamics(state, np.zeros(model.n_u)), dtype=np.float64).ravel()[NU]


def steady_power(model: VehicleModel, state: FloatArray) -> float:
    return float(model.power(state, np.zeros(model.n_u)))


@cache
def state_jacobian(model: VehicleModel) -> ca.Function:
    x = ca.SX.sym("x", model.n_x)
    xdot = model.dynamics(x, ca.SX.zeros(model.n_u))
    return ca.Function("f_x", [x], [ca.jacobian(xdot, x)])


def solve_equilibrium(
    model: VehicleModel,
    state_of: Callable[[FloatArray], FloatArray],
    guesses: Sequence[Sequence[float]],
    what: str,
) -> FloatArray:
    """Unknowns ``z`` (3 of them) with ``ν̇(state_of(z)) = 0``, from the first guess that works.

    ``state_of`` is affine in ``z``, so its Jacobian is read off exactly from unit steps and
    the Newton system uses the exact ``∂f/∂x``.
    """
    origin = state_of(np.zeros(3))
    columns = np.column_stack([state_of(np.eye(3)[k]) - origin for k in range(3)])
    jacobian = state_jacobian(model)

    def residual(z: FloatArray) -> FloatArray:
        return nu_dot(model, state_of(z))

    def residual_jacobian(z: FloatArray) -> FloatArray:
        full = np.asarray(jacobian(state_of(z)), dtype=np.float64)
        return np.asarray(full[NU] @ columns, dtype=np.float64)

    message = ""
    for guess in guesses:
        solution = root(residual, np.asarray(guess, float), jac=residual_jacobian, tol=1e-12)
        if solution.success and np.max(np.abs(residual(solution.x))) <= 1e-8:
            return np.asarray(solution.x, dtype=np.float64)
        message = str(solution.message)
    raise SolverError(f"{what} did not converge: {message}")


#: Units of the fields of :class:`VehicleCharacteristics` (SI; propeller speeds in rev/s).
CHARACTERISTIC_UNITS: Final = {
    "n_max": "rev/s",
    "bollard_thrust": "N",
    "bollard_torque": "N m",
    "bollard_power": "W",
    "top_speed": "m/s",
    "cruise_speed": "m/s",
    "cruise_energy_per_metre": "J/m",
    "hotel_power": "W",
    "power_at_0_5": "W",
    "power_at_1_0": "W",
    "n_at_0_5": "rev/s",
    "n_at_1_0": "rev/s",
    "max_yaw_rate": "rad/s",
    "turning_radius": "m",
    "climb_rate": "m/s",
    "dive_rate": "m/s",
    "min_altitude": "m",
    "battery_capacity": "J",
    "cruise_range": "m",
}


@dataclass(frozen=True)
class VehicleCharacteristics:
    """Headline numbers of a vehicle type (what ``auvplan vehicle`` prints)."""

    name: str
    """Vehicle type."""
    propeller_order: int
    """Harmonics of the propeller series used [-]."""
    n_max: float
    """Maximum speed of the forward-pushing propellers [rev/s]."""
    bollard_thrust: float
    """Thrust per propeller at ``n_max``, vehicle at rest [N]."""
    bollard_torque: float
    """Torque per propeller at ``n_max``, vehicle at rest [N m]."""
    bollard_power: float
    """Electrical power at bollard, all forward motors plus hotel load [W]."""
    top_speed: float
    """Straight-line speed at ``n_max`` [m/s]."""
    cruise_speed: float
    """Energy-optimal cruise speed [m/s]."""
    cruise_energy_per_metre: float
    """Energy per metre at the cruise speed [J/m]."""
    hotel_power: float
    """Hotel load included in every power [W]."""
    power_at_0_5: float
    """Steady electrical power at 0.5 m/s (with hotel load) [W]."""
    power_at_1_0: float
    """Steady electrical power at 1.0 m/s (with hotel load) [W]."""
    n_at_0_5: float
    """Propeller speed at 0.5 m/s [rev/s]."""
    n_at_1_0: float
    """Propeller speed at 1.0 m/s [rev/s]."""
    max_yaw_rate: float
    """Steady yaw rate at full steering (:func:`max_yaw_rate`) [rad/s]."""
    turning_radius: float
    """Radius of the steady turn at full steering at the cruise speed [m]."""
    climb_rate: float
    """Largest rate of ascent of a depth profile (``[vertical]``) [m/s]."""
    dive_rate: float
    """Largest rate of descent of a depth profile [m/s]."""
    min_altitude: float
    """Smallest height above the seabed of a depth profile [m]."""
    battery_capacity: float | None = None
    """Energy of a full battery, None when the vehicle file gives none [J]."""
    cruise_range: float | None = None
    """Distance a full battery carries the vehicle at the energy-optimal cruise in still water,
    ``battery_capacity / cruise_energy_per_metre`` (the longest of any steady speed) [m]."""

    def to_dict(self) -> dict[str, float | int | str | None]:
        """Plain dictionary (JSON-ready), SI units as documented per field.

        Examples
        --------
        >>> from auvplan.io.vehicles import load_vehicle
        >>> from auvplan.vehicle.dynamics import build_vehicle_model
        >>> from auvplan.vehicle.trim import vehicle_characteristics
        >>> table = vehicle_characteristics(build_vehicle_model(load_vehicle("medusa"))).to_dict()
        >>> table["name"], round(float(table["top_speed"]), 2)
        ('medusa', 1.48)
        """
        return dict(asdict(self))

    def to_document(self) -> dict[str, dict[str, float | int | str | None]]:
        """The JSON document of ``auvplan vehicle --json``: the fields and their units.

        ``{"characteristics": self.to_dict(), "units": CHARACTERISTIC_UNITS}``.
        """
        return {"characteristics": self.to_dict(), "units": dict(CHARACTERISTIC_UNITS)}


__all__ = [
    "CHARACTERISTIC_UNITS",
    "NU",
    "BollardPull",
    "CruiseOptimum",
    "SteadyMotion",
    "SteadyTurn",
    "SurgeTrim",
    "TurnTrim",
    "VehicleCharacteristics",
    "nu_dot",
    "solve_equilibrium",
    "state_jacobian",
    "steady_power",
]
