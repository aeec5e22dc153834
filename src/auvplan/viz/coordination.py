"""Figures of temporal deconfliction: the coordination space of a pair, timed trajectories."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from auvplan.deconfliction import (
    CoordinationProblem,
    CoordinationResult,
    positions_along,
    timed_positions,
)
from auvplan.errors import InputError
from auvplan.viz.figure import NotebookFigure
from auvplan.viz.style import pair_colors, plain_tick_labels, vehicle_colors

#: Raster resolution of the shaded collision region (samples per axis).
REGION_SAMPLES = 400


def plot_coordination_space(
    problem: CoordinationProblem,
    result: CoordinationResult,
    pair: tuple[int, int] = (0, 1),
    *,
    width_inches: float = 6.0,
) -> Figure:
    r"""The 2-D coordination space ``(s_i, s_j)`` of one pair with its collision region.

    The shaded region is ``{(s_i, s_j): ‖p_i(s_i) - p_j(s_j)‖ < 2 r_c}`` (the "cylinder" of
    paper Sec. III-B, sampled on a raster); the line is the pair's projection of the chosen
    schedule ``(s_i(t), s_j(t))``, the dashed line the nominal schedule at cruise speed.

    Parameters
    ----------
    problem : CoordinationProblem
        The paths.
    result : CoordinationResult
        A schedule for ``problem``.
    pair : tuple of int
        Vehicles ``(i, j)``, ``i != j``; ``s_i`` on the horizontal axis.
    width_inches : float
        Figure width [in].

    Returns
    -------
    matplotlib.figure.Figure
        Created without pyplot; save it with ``fig.savefig(path)``.
    """
    i, j = pair
    n = problem.n_vehicles
    if not (0 <= i < n and 0 <= j < n and i != j):
        raise InputError(f"pair must name two different vehicles of {n}, got {pair}")
    length_i, length_j = problem.path_lengths[i], problem.path_lengths[j]
    s_i = np.linspace(0.0, length_i, REGION_SAMPLES)
    s_j = np.linspace(0.0, length_j, REGION_SAMPLES)
    p_i = positions_along(problem.paths[i], problem.arc_lengths[i], s_i)
    p_j = positions_along(problem.paths[j], problem.arc_lengths[j], s_j)
    distance = np.hypot(
        p_i[:, None, 0] - p_j[None, :, 0], p_i[:, None, 1] - p_j[None, :, 1]
    )  # (s_i, s_j)
    figure = NotebookFigure(figsize=(width_inches, width_inches * length_j / length_i * 0.9 + 0.6))
    ax = figure.add_subplot()
    ax.contourf(
        s_i, s_j, distance.T, levels=[0.0, problem.separation], colors=["tab:red"], alpha=0.35
    )
    ax.contour(s_i, s_j, distance.T, levels=[problem.separation], colors="tab:red")
    horizon = max(result.time[-1], float(problem.nominal_arrival_times[[i, j]].max()))
    t = np.linspace(0.0, horizon, 200)
    ax.plot(
        np.minimum(problem.cruise_speeds[i] * t, length_i),
        np.minimum(problem.cruise_speeds[j] * t, length_j),
        "k--",
        lw=1,
        label="nominal (cruise speed, no wait)",
    )
    ax.plot(result.progress[i], result.progress[j], color="tab:blue", lw=2, label="deconflicted")
    ax.plot([0.0, length_i], [0.0, length_j], "o", color="k", ms=4)
    ax.set(
        xlabel=f"progress $s_{i}$ of vehicle {problem.label(i)} [m]",
        ylabel=f"progress $s_{j}$ of vehicle {problem.label(j)} [m]",
        xlim=(0.0, length_i),
        ylim=(0.0, length_j),
        aspect="equal",
        title=f"coordination space of vehicles {problem.label(i)} and {problem.label(j)} "
        f"(red: closer than 2 $r_c$ = {problem.separation:g} m)",
    )
    ax.title.set_fontsize("small")
    ax.legend(loc="upper left", fontsize="small")
    return plain_tick_labels(figure)


def plot_timed_paths(
    problem: CoordinationProblem,
    result: CoordinationResult,
    *,
    n_snapshots: int = 6,
    width_inches: float = 11.0,
) -> Figure:
    """Timed trajectories over the map and pairwise separation against time.

    Parameters
    ----------
    problem : CoordinationProblem
        The paths.
    result : CoordinationResult
        A schedule for ``problem``.
    n_snapshots : int
        Number of equally spaced times at which every vehicle's position is marked.
    width_inches : float
        Figure width [in].

    Returns
    -------
    matplotlib.figure.Figure
        Left: paths (east right, north up) with the positions at the snapshot times (one
        marker shade per time) and circles of radius ``r_c`` at the time of minimum
        separation. Right: every pair's distance against time, ``2 r_c`` and the certified
        bound. Created without pyplot.
    """
    figure = NotebookFigure(figsize=(width_inches, 0.45 * width_inches), layout="constrained")
    ax_map, ax_sep = figure.subplots(1, 2)
    colors = vehicle_colors(problem.n_vehicles)
    snapshots = np.linspace(0.0, result.time[-1], n_snapshots)
    marks = timed_positions(result, problem, snapshots)
    critical = timed_positions(result, problem, np.array([result.min_separation_time]))[:, 0]
    for i, path in enumerate(problem.paths):
        ax_map.plot(
            path[:, 1], path[:, 0], color=colors[i], lw=1.5, label=f"vehicle {problem.label(i)}"
        )
        ax_map.scatter(
            marks[i, :, 1],
            marks[i, :, 0],
            c=snapshots,
            cmap="Greys",
            vmin=-0.3 * snapshots[-1],
            edgecolors=colors[i],
            zorder=3,
            s=25,
        )
        ax_map.plot(path[0, 1], path[0, 0], "^", color=colors[i])
        ax_map.plot(path[-1, 1], path[-1, 0], "s", color=colors[i])
    for i in result.min_separation_pair:
        if i >= 0:
            circle = _circle(critical[i], problem.safety_radius)
            ax_map.plot(circle[:, 1], circle[:, 0], color=colors[i], lw=1, ls=":")
    ax_map.set_aspect("equal", adjustable="datalim")
    ax_map.set(
        xlabel="east [m]",
        ylabel="north [m]",
        title="paths, positions every "
        f"{snapshots[1] - snapshots[0] if n_snapshots > 1 else 0:.3g} s (darker = later)",
    )
    ax_map.title.set_fontsize("small")
    ax_map.legend(fontsize="small")
    fine = result.time if result.time.size <= 20_000 else np.linspace(0, result.time[-1], 20_000)
    positions = timed_positions(result, problem, fine)
    n = problem.n_vehicles
    pairs = [(i, j) for i in range(n) for j in range(i + 1, n)]
    for (i, j), color in zip(pairs, pair_colors(len(pairs)), strict=True):
        ax_sep.plot(
            fine,
            np.hypot(*(positions[i] - positions[j]).T),
            lw=1,
            color=color,
            label=f"{problem.label(i)}–{problem.label(j)}" if n <= 6 else None,
        )
    ax_sep.axhline(problem.separation, color="tab:red", lw=1.5, label="2 $r_c$")
    ax_sep.plot(
        [result.min_separation_time],
        [result.min_separation],
        "kx",
        label=f"certified minimum {result.min_separation:.3g} m",
    )
    ax_sep.set(
        xlabel="time [s]",
        ylabel="pairwise distance [m]",
        ylim=(0.0, None),
        title=f"{result.method}: makespan {result.makespan:.4g} s, "
        f"total delay {result.delays.sum():.4g} s",
    )
    ax_sep.title.set_fontsize("small")
    ax_sep.legend(fontsize="small", ncols=2)
    return plain_tick_labels(figure)


def _circle(center: np.ndarray, radius: float) -> np.ndarray:
    angle = np.linspace(0.0, 2.0 * np.pi, 73)
    return np.column_stack([center[0] + radius * np.cos(angle), center[1] + radius * np.sin(angle)])
