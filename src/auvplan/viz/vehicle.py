"""Validation figure of a vehicle model: propeller series, speed-power curve, turning circle."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure

from auvplan.vehicle.dynamics import VehicleModel
from auvplan.vehicle.propulsion import thrust_coefficient, torque_coefficient
from auvplan.vehicle.reference import positions
from auvplan.vehicle.simulate import rk4_simulate
from auvplan.vehicle.trim import top_speed, trim_surge, trim_turn
from auvplan.viz.style import plain_tick_labels


def plot_vehicle_validation(
    model: VehicleModel,
    *,
    orders: Sequence[int] = (1, 3, 10),
    turn_speed: float = 0.5,
    turn_rate: float = 0.1,
) -> Figure:
    """Three panels that show what the vehicle model does.

    1. ``C_T*(β)`` and ``C_Q*(β)`` over the four quadrants: the full series and the
       truncated low-order series of ``orders`` (and the model's own order, marked).
    2. Steady straight motion vs speed: propeller speed, thrust per propeller and
       electrical power (with and without the hotel load), up to the top speed.
    3. A steady turning circle at ``turn_speed`` [m/s] and ``turn_rate`` [rad/s], simulated
       with RK4 from the trim, drawn east to the right and north up.

    Parameters
    ----------
    model : VehicleModel
        Model to draw.
    orders : sequence of int
        Low orders of the propeller series to compare with the full one.
    turn_speed : float
        Surge speed of the turning circle [m/s].
    turn_rate : float
        Yaw rate of the turning circle [rad/s] (> 0: to starboard).

    Returns
    -------
    matplotlib.figure.Figure
        Created without pyplot (no global state); save with ``figure.savefig(path)``.
    """
    params = model.params
    figure = Figure(figsize=(14.0, 4.6))
    figure.set_layout_engine("constrained")
    coefficient_axes, speed_axes, turn_axes = figure.subplots(1, 3)

    beta = np.linspace(-np.pi, np.pi, 721)
    degrees = np.degrees(beta)
    full_order = params.propeller.max_order
    for function, label, color in (
        (thrust_coefficient, "$C_T^*$", "tab:blue"),
        (torque_coefficient, "$10\\,C_Q^*$", "tab:red"),
    ):
        scale = 10.0 if function is torque_coefficient else 1.0
        coefficient_axes.plot(
            degrees,
            scale * function(beta, params.propeller, order=full_order),
            color=color,
            lw=2.0,
            label=f"{label} order {full_order}",
        )
        for index, order in enumerate(orders):
            coefficient_axes.plot(
                degrees,
                scale * function(beta, params.propeller, order=order),
                color=color,
                lw=1.0,
                ls=(":", "--", "-.")[index % 3],
                label=f"{label} order {order}",
            )
    for edge in (-90, 0, 90):
        coefficient_axes.axvline(edge, color="0.7", lw=0.8)
    coefficient_axes.set_xlim(-180, 180)
    coefficient_axes.set_xticks([-180, -90, 0, 90, 180])
    coefficient_axes.set_xlabel("advance angle β [deg]")
    coefficient_axes.set_ylabel("coefficient [-]")
    coefficient_axes.set_title(f"{params.propeller.name}: four-quadrant series")
    coefficient_axes.legend(fontsize=7, ncol=2, loc="lower left")

    u_max = top_speed(model)
    speeds = np.linspace(0.05, u_max, 40)
    trims = [trim_surge(model, float(u)) for u in speeds]
    n = np.array([trim.n for trim in trims])
    power = np.array([trim.power for trim in trims])
    thrust = np.array(
        [
            float(model.thrust_torque([0, 0, 0, u, 0, 0, m, m])[0])
            for u, m in zip(speeds, n, strict=True)
        ]
    )
    speed_axes.plot(speeds, power, color="k", label="electrical power [W]")
    speed_axes.plot(
        speeds, power - params.hotel_power, color="k", ls="--", label="propulsion power [W]"
    )
    speed_axes.plot(speeds, n, color="tab:green", label="propeller speed [rev/s]")
    speed_axes.plot(speeds, thrust, color="tab:blue", label="thrust per propeller [N]")
    speed_axes.axvline(u_max, color="0.6", lw=0.8)
    speed_axes.set_xlabel("surge speed u [m/s]")
    speed_axes.set_title(f"steady straight motion (top speed {u_max:.2f} m/s)")
    speed_axes.legend(fontsize=8, loc="upper left")
    speed_axes.grid(alpha=0.3)

    turn = trim_turn(model, turn_speed, turn_rate)
    period = 2.0 * np.pi / abs(turn_rate)
    n_steps = 400
    start = np.zeros(model.n_x)
    for name, value in (
        ("u", turn_speed), ("v", turn.v), ("r", turn_rate), ("n_ps", turn.n_ps),
        ("n_sb", turn.n_sb),
    ):  # fmt: skip
        start[model.index(name)] = value
    states = rk4_simulate(model, start, np.zeros((n_steps, model.n_u)), period / n_steps)
    radius = float(np.hypot(turn_speed, turn.v) / abs(turn_rate))
    track = positions(model, states)
    turn_axes.plot(track[:, 1], track[:, 0], color="tab:purple")
    turn_axes.plot([0.0], [0.0], "o", color="k", label="start (heading north)")
    turn_axes.set_aspect("equal")
    turn_axes.set_xlabel("east [m]")
    turn_axes.set_ylabel("north [m]")
    turn_axes.set_title(
        f"turning circle R = {radius:.2f} m (u = {turn_speed} m/s, r = {turn_rate} rad/s)\n"
        f"n_ps = {turn.n_ps:.1f}, n_sb = {turn.n_sb:.1f} rev/s, P = {turn.power:.0f} W",
        fontsize=10,
    )
    turn_axes.legend(fontsize=8)
    turn_axes.grid(alpha=0.3)
    return plain_tick_labels(figure)


__all__ = ["plot_vehicle_validation"]
