"""Validation figure of a vehicle model: propeller curves, speed-power curve, turning circle."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from auvplan.vehicle.dynamics import VehicleModel
from auvplan.vehicle.operating import FIRST_ACTUATOR, operating_state
from auvplan.vehicle.params import LinearPropellerParams, Propeller
from auvplan.vehicle.propulsion import thrust_coefficient, torque_coefficient
from auvplan.vehicle.reference import positions
from auvplan.vehicle.simulate import rk4_simulate
from auvplan.vehicle.trim import (
    SteadyTurn,
    optimal_cruise_speed,
    steady_turn,
    tightest_turn,
    top_speed,
    trim_surge,
)
from auvplan.viz.figure import NotebookFigure
from auvplan.viz.style import plain_tick_labels


def plot_vehicle_validation(
    model: VehicleModel,
    *,
    orders: Sequence[int] = (1, 3, 10),
    turn_speed: float | None = None,
    turn_rate: float | None = None,
) -> Figure:
    """Three panels that show what the vehicle model does.

    1. The first propeller's open-water curves: ``C_T*(β)`` and ``C_Q*(β)`` over the four
       quadrants for a four-quadrant series (the full series and the truncated low-order
       series of ``orders``), or ``K_T(J)``, ``K_Q(J)`` and the efficiency for a linear one.
    2. Steady straight motion vs speed: propeller speed, thrust per propeller and
       electrical power (with and without the hotel load), up to the top speed.
    3. A steady turning circle simulated with RK4 from its trim, drawn east to the right and
       north up: by default the tightest turn at the cruise speed (full steering, the
       turning radius ``auvplan vehicle`` reports), else the turn at ``turn_speed`` [m/s]
       and ``turn_rate`` [rad/s].

    Parameters
    ----------
    model : VehicleModel
        Model to draw.
    orders : sequence of int
        Low orders of a four-quadrant propeller series to compare with the full one.
    turn_speed : float, optional
        Surge speed of the turning circle [m/s] (with ``turn_rate``).
    turn_rate : float, optional
        Yaw rate of the turning circle [rad/s] (> 0: to starboard).

    Returns
    -------
    matplotlib.figure.Figure
        Created without pyplot (no global state); save with ``figure.savefig(path)``.
    """
    figure = NotebookFigure(figsize=(14.0, 4.6))
    figure.set_layout_engine("constrained")
    propeller_axes, speed_axes, turn_axes = figure.subplots(1, 3)
    _plot_propeller(propeller_axes, model.vehicle.propeller, orders)
    _plot_straight_motion(speed_axes, model)
    if turn_speed is None or turn_rate is None:
        speed = optimal_cruise_speed(model).speed
        turn = tightest_turn(model, speed)
        label = f"u = {speed:.2f} m/s (cruise), full steering"
    else:
        turn = steady_turn(model, turn_speed, turn_rate)
        label = f"u = {turn_speed} m/s, r = {turn_rate} rad/s"
    _plot_turn(turn_axes, model, turn, label)
    return plain_tick_labels(figure)


def _plot_propeller(axes: Axes, propeller: Propeller, orders: Sequence[int]) -> None:
    if isinstance(propeller, LinearPropellerParams):
        advance = np.linspace(0.0, 1.5 * propeller.J_max, 200)
        k_t = propeller.K_T0 + propeller.thrust_slope * advance
        k_q = propeller.K_Q0 + propeller.torque_slope * advance
        efficiency = np.where(k_t > 0.0, advance * k_t / (2.0 * np.pi * k_q), np.nan)
        axes.plot(advance, k_t, color="tab:blue", lw=2.0, label="$K_T$")
        axes.plot(advance, 10.0 * k_q, color="tab:red", lw=2.0, label="$10\\,K_Q$")
        axes.plot(advance, efficiency, color="k", ls="--", label="$\\eta_0 = J K_T/(2\\pi K_Q)$")
        axes.axvline(propeller.J_max, color="0.7", lw=0.8)
        axes.set_xlabel("advance ratio J [-]")
        axes.set_title(f"{propeller.name}: $K_T$, $K_Q$ linear in J", fontsize=10)
        axes.grid(alpha=0.3)
        axes.legend(fontsize=8)
        return
    beta = np.linspace(-np.pi, np.pi, 721)
    degrees = np.degrees(beta)
    full_order = propeller.max_order
    for function, label, color in (
        (thrust_coefficient, "$C_T^*$", "tab:blue"),
        (torque_coefficient, "$10\\,C_Q^*$", "tab:red"),
    ):
        scale = 10.0 if function is torque_coefficient else 1.0
        axes.plot(
            degrees,
            scale * function(beta, propeller, order=full_order),
            color=color,
            lw=2.0,
            label=f"{label} order {full_order}",
        )
        for index, order in enumerate(orders):
            axes.plot(
                degrees,
                scale * function(beta, propeller, order=order),
                color=color,
                lw=1.0,
                ls=(":", "--", "-.")[index % 3],
                label=f"{label} order {order}",
            )
    for edge in (-90, 0, 90):
        axes.axvline(edge, color="0.7", lw=0.8)
    axes.set_xlim(-180, 180)
    axes.set_xticks([-180, -90, 0, 90, 180])
    axes.set_xlabel("advance angle β [deg]")
    axes.set_title(f"{propeller.name}: four-quadrant series")
    axes.legend(fontsize=7, ncol=2, loc="lower left")
    axes.set_ylabel("coefficient [-]")


def _plot_straight_motion(axes: Axes, model: VehicleModel) -> None:
    u_max = top_speed(model)
    speeds = np.linspace(0.05, u_max, 40)
    trims = [trim_surge(model, float(u)) for u in speeds]
    n = np.array([trim.n for trim in trims])
    power = np.array([trim.power for trim in trims])
    thrust = np.array(
        [
            float(model.thrust_torque(operating_state(model, u=float(u), throttle=float(m)))[0])
            for u, m in zip(speeds, n, strict=True)
        ]
    )
    hotel = model.vehicle.hotel_power
    axes.plot(speeds, power, color="k", label="electrical power [W]")
    axes.plot(speeds, power - hotel, color="k", ls="--", label="propulsion power [W]")
    axes.plot(speeds, n, color="tab:green", label="propeller speed [rev/s]")
    axes.plot(speeds, thrust, color="tab:blue", label="thrust per propeller [N]")
    axes.axvline(u_max, color="0.6", lw=0.8)
    axes.set_xlabel("surge speed u [m/s]")
    axes.set_title(f"steady straight motion (top speed {u_max:.2f} m/s)")
    axes.legend(fontsize=8, loc="upper left")
    axes.grid(alpha=0.3)


def _plot_turn(axes: Axes, model: VehicleModel, turn: SteadyTurn, label: str) -> None:
    rate = float(turn.state[model.index("r")])
    period = 2.0 * np.pi / abs(rate)
    n_steps = 400
    states = rk4_simulate(model, turn.state, np.zeros((n_steps, model.n_u)), period / n_steps)
    track = positions(model, states)
    actuators = ", ".join(
        f"{name} = {np.degrees(value):.1f}°"
        if name.startswith("delta_")
        else f"{name} = {value:.1f}"
        for name, value in zip(
            model.state_names[FIRST_ACTUATOR:], turn.state[FIRST_ACTUATOR:], strict=True
        )
    )
    axes.plot(track[:, 1], track[:, 0], color="tab:purple")
    axes.plot([0.0], [0.0], "o", color="k", label="start (heading north)")
    axes.set_aspect("equal")
    axes.set_xlabel("east [m]")
    axes.set_ylabel("north [m]")
    axes.set_title(
        f"turning circle R = {turn.radius:.2f} m, {label}\n{actuators}, P = {turn.power:.0f} W",
        fontsize=9,
    )
    axes.legend(fontsize=8)
    axes.grid(alpha=0.3)


__all__ = ["plot_vehicle_validation"]
