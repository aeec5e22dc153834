"""Generalized forces ``τ = (X, Y, N)`` of the hull, thrusters and control surfaces (CasADi).

The equations are those of :mod:`auvplan.vehicle.dynamics`; each function builds one term.
"""

from __future__ import annotations

import casadi as ca

from auvplan.vehicle.actuators import ActuatedVehicleParams, ControlSurfaceParams, ThrusterParams
from auvplan.vehicle.params import HullParams


def smooth_abs(value: ca.SX, eps: float) -> ca.SX:
    """``|s|_ε = sqrt(s² + ε²)``."""
    return ca.sqrt(value**2 + eps**2)


def hull_damping(hull: HullParams, vehicle: ActuatedVehicleParams, nu: ca.SX) -> ca.SX:
    """Diagonal of ``D(ν) + D_n(ν)`` [kg/s, kg/s, kg m²/s]."""
    u, v, r = nu[0], nu[1], nu[2]
    fade: ca.SX | float = 1.0
    if hull.linear_damping_fade > 0.0:
        speed = ca.sqrt(u**2 + v**2 + vehicle.eps_abs_speed**2)
        fade = ca.exp(-hull.linear_damping_fade * speed)
    return ca.vertcat(
        -hull.X_u * fade - hull.X_uu * smooth_abs(u, vehicle.eps_abs_speed),
        -hull.Y_v * fade - hull.Y_vv * smooth_abs(v, vehicle.eps_abs_speed),
        -hull.N_r - hull.N_rr * smooth_abs(r, vehicle.eps_abs_rate),
    )


def crossflow_force(hull: HullParams, eps_speed: float, nu: ca.SX) -> ca.SX:
    """Strip-theory cross-flow ``(0, Y, N)`` (:class:`auvplan.vehicle.params.CrossFlowParams`)."""
    strips = hull.crossflow
    if strips is None:
        return ca.SX.zeros(3)
    scale = -0.5 * hull.rho * strips.height * strips.drag_coefficient
    scale *= strips.length / strips.strips
    sway, moment = ca.SX(0.0), ca.SX(0.0)
    for station in strips.stations:
        local = nu[1] + float(station) * nu[2]
        drag = smooth_abs(local, eps_speed) * local
        sway += drag
        moment += float(station) * drag
    return ca.vertcat(0.0, scale * sway, scale * moment)


def thruster_force(
    thruster: ThrusterParams, thrust: ca.SX
) -> tuple[ca.SX | float, ca.SX | float, ca.SX | float]:
    """``(X, Y, N)`` of one thruster's thrust on the hull [N, N, N m]."""
    force = (1.0 - thruster.thrust_deduction) * thrust
    return (
        thruster.surge_share * force,
        thruster.sway_share * force,
        thruster.yaw_arm * force,
    )


def advance_speed(thruster: ThrusterParams, nu: ca.SX) -> ca.SX:
    """``v_a = (1 - w)(cα (u - y r) + sα (v + x r))`` [m/s]."""
    u, v, r = nu[0], nu[1], nu[2]
    axial = thruster.surge_share * (u - thruster.y * r) + thruster.sway_share * (v + thruster.x * r)
    return (1.0 - thruster.wake_fraction) * axial


def surface_force(surface: ControlSurfaceParams, rho: float, nu: ca.SX, delta: ca.SX) -> ca.SX:
    """``(X, Y, N)`` of a control surface: lift ``-q C_Lδ δ``, drag ``-q C_Dδ δ²`` [N, N, N m]."""
    pressure = 0.5 * rho * (nu[0] ** 2 + nu[1] ** 2) * surface.area
    lift = -pressure * surface.lift_slope * delta
    drag = -pressure * surface.drag_slope * delta**2
    return ca.vertcat(drag, lift, surface.x * lift - surface.y * drag)


__all__ = [
    "advance_speed",
    "crossflow_force",
    "hull_damping",
    "smooth_abs",
    "surface_force",
    "thruster_force",
]
