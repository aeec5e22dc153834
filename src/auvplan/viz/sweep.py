"""The Pareto figure of a sweep: fleet energy against the navigation objective."""

from __future__ import annotations

from typing import Final

from matplotlib.figure import Figure

from auvplan.sweep.pareto import ParetoView
from auvplan.viz.figure import NotebookFigure

#: Groups drawn with a legend entry (and points with a text label) at most.
MAX_LABELLED_GROUPS: Final = 10
MAX_LABELLED_POINTS: Final = 80
_AXIS_LABELS: Final = {
    "terrain_information": "mean terrain information [-] (higher navigates better)",
    "tan_rmse_m": "TAN position RMSE [m] (lower navigates better)",
}


def plot_pareto(view: ParetoView, *, title: str = "") -> Figure:
    """Energy against navigation per sweep point, each group's non-dominated front drawn.

    Energy is in kJ; when the groups are different missions (the scenario family), each
    group's energy is in percent above that group's least instead, so missions of different
    size share the axis. Converged plans are filled markers, others
    hollow; each point is annotated with its label value (``weights.terrain``). Energy-only
    plans (terrain weight 0) carry a black star; for one mission swept in several groups the
    front over all points is a dashed black line.

    Parameters
    ----------
    view : ParetoView
        From :func:`auvplan.sweep.pareto.pareto_view`.
    title : str
        Figure title (default: what is plotted).
    """
    points = view.points
    groups = list(dict.fromkeys(points["group"]))
    relative = not view.same_mission and len(groups) > 1
    figure = NotebookFigure(figsize=(7.5, 5.0), layout="constrained")
    axes = figure.add_subplot()
    annotate = len(points) <= MAX_LABELLED_POINTS and view.label_key is not None
    for index, group in enumerate(groups):
        members = points[points["group"] == group]
        energy = members["energy_J"].to_numpy(float)
        energy = 100.0 * (energy / energy.min() - 1.0) if relative else energy / 1e3
        objective = members[view.objective].to_numpy(float)
        color = f"C{index % 10}"
        converged = members["converged"].to_numpy(bool)
        legend = group if 1 < len(groups) <= MAX_LABELLED_GROUPS else None
        axes.scatter(energy[converged], objective[converged], color=color, zorder=3, label=legend)
        axes.scatter(
            energy[~converged], objective[~converged], facecolors="none", edgecolors=color,
            zorder=3, label="not converged" if index == 0 and (~converged).any() else None,
        )  # fmt: skip
        front = members["on_front"].to_numpy(bool)
        order = energy[front].argsort()
        axes.plot(energy[front][order], objective[front][order], "-", color=color, lw=1.4)
        reference = members["is_reference"].to_numpy(bool)
        axes.scatter(
            energy[reference], objective[reference], marker="*", s=220, color="black",
            zorder=4, label="energy-only plan (terrain weight 0)" if index == 0 else None,
        )  # fmt: skip
        if annotate:
            for x, y, label in zip(energy, objective, members["label"], strict=True):
                axes.annotate(
                    f"{label:g}" if isinstance(label, float) else str(label), (x, y),
                    textcoords="offset points", xytext=(5, 4), fontsize=8,
                )  # fmt: skip
    overall = points[points["on_overall_front"]].sort_values("energy_J")
    if len(groups) > 1 and not overall.empty:
        axes.plot(
            overall["energy_J"] / 1e3, overall[view.objective], "--", color="black", lw=1.0,
            zorder=2, label="front over all points",
        )  # fmt: skip
    axes.set_xlabel("fleet energy above the group's least [%]" if relative else "fleet energy [kJ]")
    axes.set_ylabel(_AXIS_LABELS.get(view.objective, view.objective))
    axes.grid(alpha=0.3)
    shown = view.label_key or "run"
    axes.set_title(
        title or f"Energy vs navigation over the sweep (points: {shown}; line: Pareto front)",
        fontsize=10,
    )
    if axes.get_legend_handles_labels()[0]:
        axes.legend(fontsize=8)
    return figure


__all__ = ["plot_pareto"]
