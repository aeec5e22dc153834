"""``report.html``: one self-contained page per output folder (standard library only).

The page is built from the folder's ``summary.json`` document and its rendered figures, which
are embedded as base64 ``data:`` URIs (PNG or SVG; a PDF figure is shown by its PNG preview),
so the file can be mailed or archived alone. Every text from the summary is escaped with
:func:`html.escape`. Sections: status and warnings, vehicles (energy, battery capacity and
what the plan leaves in it, terrain information, arrival error, closest approach, timing),
constraint violations, optimiser (status, iterations, per-iteration history), energy-only
comparison, deconfliction, wall times, settings, figures and the folder's files.
"""

from __future__ import annotations

import base64
import html
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any, Final

from auvplan._figures import FIGURE_CAPTIONS, RenderedFigure

_STYLE: Final = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 72em; color: #222; }
h1 { font-size: 1.6em; } h2 { font-size: 1.25em; margin-top: 1.6em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.92em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: right; }
th { background: #f2f2f2; } td:first-child, th:first-child { text-align: left; }
.status { display: inline-block; padding: 0.3em 0.8em; border-radius: 0.3em; font-weight: bold; }
.ok { background: #d8f0d8; } .bad { background: #f8d8d8; } .info { background: #e4e8f4; }
figure { margin: 1.2em 0; } figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #555; } ul.warnings li { color: #8a4b00; }
"""


def render_report(
    summary: Mapping[str, Any],
    figures: Mapping[str, RenderedFigure],
    *,
    files: Sequence[str] = (),
) -> str:
    """The HTML text of ``report.html``.

    Parameters
    ----------
    summary : mapping
        The ``summary.json`` document (plain JSON values).
    figures : mapping of str to RenderedFigure
        The figures by file stem, in display order.
    files : sequence of str
        The folder's files, relative to it, listed at the end.

    Returns
    -------
    str
        A complete HTML5 document.
    """
    mission = summary.get("mission") or "built-in demo mission"
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en">',
        '<head><meta charset="utf-8">',
        f"<title>auvplan report: {_text(mission)}</title>",
        f"<style>{_STYLE}</style></head>",
        "<body>",
        "<h1>auvplan plan report</h1>",
        _key_values(
            {
                "mission": mission,
                "auvplan": summary.get("auvplan_version"),
                "start time (UTC)": summary.get("start_time"),
                "stage run": summary.get("stage"),
                "terrain": summary.get("terrain", {}).get("name"),
            }
        ),
        *_warnings(summary),
        "<h2>Status and vehicles</h2>",
        render_overview(summary),
        *_optimizer(summary.get("optimization"), "Optimiser"),
        *_navigation(summary),
        *_comparison(summary),
        *_deconfliction(summary),
        "<h2>Wall time</h2>",
        _table(
            ("stage", "seconds"),
            [
                *summary.get("wall_time_s", {}).items(),
                ("total", sum(summary.get("wall_time_s", {}).values())),
            ],
            (str, _fixed(2)),
        ),
        "<h2>Settings</h2>",
        _key_values({**summary.get("fleet", {}), **summary.get("solver", {})}),
        *_figures(figures),
        *_files(files),
        "</body>",
        "</html>",
    ]
    return "\n".join(parts) + "\n"


def render_overview(summary: Mapping[str, Any]) -> str:
    """An HTML fragment: the plan's status and the vehicles table (a notebook's view of a plan).

    Examples
    --------
    >>> render_overview({"stage": "preplan", "vehicles": []})[:40]
    '<p><span class="status info">stopped aft'
    """
    status, status_class = _status(summary)
    return "\n".join(
        [f'<p><span class="status {status_class}">{_text(status)}</span></p>', _vehicles(summary)]
    )


def _status(summary: Mapping[str, Any]) -> tuple[str, str]:
    """The headline and its CSS class: the plan status, or the stage the run stopped after."""
    optimization = summary.get("optimization")
    if optimization is None:
        return f"stopped after stage {summary.get('stage')}: no optimised plan", "info"
    status = str(optimization.get("plan_status"))
    text = f"plan {status}: {optimization.get('verdict', '')}"
    return text, "ok" if status == "CONVERGED" else "bad"


def _warnings(summary: Mapping[str, Any]) -> list[str]:
    warnings = list(summary.get("warnings", []))
    if not warnings:
        return ["<h2>Warnings</h2>", "<p>None.</p>"]
    items = "".join(f"<li>{_text(warning)}</li>" for warning in warnings)
    return ["<h2>Warnings</h2>", f'<ul class="warnings">{items}</ul>']


def _vehicles(summary: Mapping[str, Any]) -> str:
    optimized = (summary.get("optimization") or {}).get("vehicles", {})
    rows = []
    for vehicle in summary.get("vehicles", []):
        name = vehicle["name"]
        plan = optimized.get(name, {})
        closest = _closest(plan.get("min_separation_m", {}))
        timing = vehicle.get("timing", {})
        rows.append(
            (
                name,
                vehicle.get("type"),
                _kilo(plan.get("energy_J")),
                _kilo(vehicle.get("battery_capacity_J")),
                _kilo(plan.get("energy_remaining_J")),
                _percent(plan.get("energy_remaining_fraction")),
                plan.get("mean_terrain_information"),
                plan.get("arrival_error_m"),
                plan.get("tracking_error_m"),
                closest,
                timing.get("arrival_time_s"),
                timing.get("delay_s"),
                vehicle["preplan"].get("graph_cost"),
                vehicle["preplan"].get("smoothed_length_m"),
            )
        )
    headers = (
        "vehicle", "type", "energy [kJ]", "battery [kJ]", "remaining [kJ]", "remaining [%]",
        "mean information [-]", "arrival error [m]", "tracking error [m]",
        "closest approach [m]", "arrival [s]", "delay [s]", "A* cost [-]", "path length [m]",
    )  # fmt: skip
    formats = (str, str, _fixed(2), _fixed(2), _fixed(2), _fixed(1), _fixed(3), _fixed(2),
               _fixed(2), str, _fixed(1), _fixed(1), _fixed(1), _fixed(1))  # fmt: skip
    return _table(headers, rows, formats)


def _kilo(value: float | None) -> float | None:
    """An energy [J] in kJ (None stays None: shown as n/a)."""
    return None if value is None else value / 1e3


def _percent(value: float | None) -> float | None:
    """A fraction [-] in % (None stays None)."""
    return None if value is None else 100.0 * value


def _closest(separations: Mapping[str, float | None]) -> str | None:
    """``"12.30 (green)"``: the smallest separation and to whom, or None."""
    known = {other: value for other, value in separations.items() if value is not None}
    if not known:
        return None
    other = min(known, key=lambda key: known[key])
    return f"{known[other]:.2f} ({other})"


def _optimizer(record: Mapping[str, Any] | None, title: str) -> list[str]:
    if record is None:
        return []
    parts = [
        f"<h2>{_text(title)}</h2>",
        _key_values(
            {
                "plan status": record.get("plan_status"),
                "verdict": record.get("verdict"),
                "solver status": record.get("status"),
                "message": record.get("message"),
                "iterations": record.get("n_iter"),
                "final cost h": record.get("cost"),
                "terrain weight": record.get("terrain_weight"),
                "total energy [kJ]": _kilo(record.get("total_energy_J")),
            }
        ),
    ]
    violations = record.get("violations", [])
    if violations:
        parts += [
            "<h3>Constraint violations</h3>",
            _table(
                ("kind", "who", "value", "limit", "unit", "time [s]", "advice"),
                [(v.get("kind"), v.get("who"), v.get("value"), v.get("limit"),
                  v.get("unit", "m"), v.get("time"), v.get("advice")) for v in violations],
                (str, str, _fixed(2), _fixed(2), str, _fixed(1), str),
            ),
        ]  # fmt: skip
    history = record.get("history", [])
    if history:
        keys = ("iteration", "cost", "decrement", "step", "direction", "epsilon", "delta",
                "min_slack", "wall_time")  # fmt: skip
        parts += [
            "<h3>Iterations</h3>",
            _table(
                ("iteration", "cost h", "−Dh·ζ", "step γ", "direction", "ε", "δ", "min slack",
                 "wall time [s]"),
                [tuple(row.get(key) for key in keys) for row in history],
                (str, _general(10), _scientific, _general(3), str, _scientific, _scientific,
                 _general(3), _fixed(2)),
            ),
        ]  # fmt: skip
    return parts


def _navigation(summary: Mapping[str, Any]) -> list[str]:
    """Per vehicle: how its route was chosen and the predicted TAN error of each plan [m]."""
    plans = {
        label: (summary.get(key) or {}).get("vehicles", {})
        for label, key in (("plan", "optimization"), ("energy-only", "energy_only"),
                           ("paper", "paper"))
    }  # fmt: skip
    rows = []
    for vehicle in summary.get("vehicles", []):
        route = vehicle.get("preplan", {}).get("navigation")
        predicted = {
            label: records.get(vehicle["name"], {}).get("predicted_navigation_error", {})
            for label, records in plans.items()
        }
        if route is None and not any(predicted.values()):
            continue
        route = route or {}
        rows.append(
            (
                vehicle["name"],
                route.get("mode"),
                route.get("budget_m"),
                route.get("route_predicted_rms_m"),
                route.get("energy_only_route_predicted_rms_m"),
                route.get("route_energy_increase"),
                *(predicted[label].get("rms_m") for label in plans),
                predicted["plan"].get("peak_after_settle_m"),
            )
        )
    if not rows:
        return []
    headers = (
        "vehicle", "route", "budget [m]", "route RMS [m]", "shortest route RMS [m]",
        "route energy [+]", "plan RMS [m]", "energy-only plan RMS [m]", "paper plan RMS [m]",
        "plan peak after settling [m]",
    )  # fmt: skip
    formats: tuple[Callable[[Any], str], ...] = (str, str, *([_fixed(2)] * 8))
    return [
        "<h2>Navigation (predicted TAN error, 1-σ radial)</h2>",
        _table(headers, rows, formats),
    ]


def _comparison(summary: Mapping[str, Any]) -> list[str]:
    energy_only = summary.get("energy_only")
    if energy_only is None:
        return []
    parts = _optimizer(energy_only, "Energy-only comparison (terrain weight 0)")
    rows = [
        (name, record["energy_J"] / 1e3, record["mean_terrain_information"],
         record["arrival_error_m"], _closest(record["min_separation_m"]))
        for name, record in energy_only.get("vehicles", {}).items()
    ]  # fmt: skip
    headers = ("vehicle", "energy [kJ]", "mean information [-]", "arrival error [m]",
               "closest approach [m]")  # fmt: skip
    return [*parts, _table(headers, rows, (str, _fixed(2), _fixed(3), _fixed(2), str))]


def _deconfliction(summary: Mapping[str, Any]) -> list[str]:
    record = summary.get("deconfliction")
    if record is None:
        return []
    return [
        "<h2>Deconfliction</h2>",
        _key_values(
            {
                "method": record.get("method"),
                "status": record.get("status"),
                "message": record.get("message"),
                "fallback": record.get("fallback") or "none",
                "horizon [s]": record.get("horizon_s"),
                "nodes expanded": record.get("n_expanded"),
                "certified minimum separation [m]": record.get("certified_min_separation_m"),
            }
        ),
    ]


def _figures(figures: Mapping[str, RenderedFigure]) -> list[str]:
    if not figures:
        return ["<h2>Figures</h2>", "<p>None (written without figures).</p>"]
    parts = ["<h2>Figures</h2>"]
    for stem, rendered in figures.items():
        encoded = base64.b64encode(rendered.preview).decode("ascii")
        caption = FIGURE_CAPTIONS.get(stem, "")
        parts.append(
            f'<figure id="{_text(stem)}"><img alt="{_text(stem)}" '
            f'src="data:{rendered.preview_type};base64,{encoded}">'
            f"<figcaption><b>{_text(stem)}.{rendered.figure_format}</b> {_text(caption)}"
            "</figcaption></figure>"
        )
    return parts


def _files(files: Sequence[str]) -> list[str]:
    if not files:
        return []
    items = "".join(f"<li>{_text(name)}</li>" for name in files)
    return ["<h2>Files</h2>", f"<ul>{items}</ul>"]


def _key_values(values: Mapping[str, Any]) -> str:
    rows = "".join(
        f"<tr><th>{_text(key)}</th><td>{_text(_value(value))}</td></tr>"
        for key, value in values.items()
    )
    return f"<table>{rows}</table>"


def _table(
    headers: Sequence[str],
    rows: Iterable[Sequence[Any]],
    formats: Sequence[Callable[[Any], str]],
) -> str:
    head = "".join(f"<th>{_text(header)}</th>" for header in headers)
    body = "".join(
        "<tr>"
        + "".join(
            f"<td>{_text('n/a' if value is None else fmt(value))}</td>"
            for value, fmt in zip(row, formats, strict=True)
        )
        + "</tr>"
        for row in rows
    )
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _value(value: Any) -> str:
    if value is None:
        return "n/a"
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, list | tuple):
        return ", ".join(_value(item) for item in value)
    return str(value)


def _fixed(digits: int) -> Callable[[Any], str]:
    return lambda value: f"{value:.{digits}f}"


def _general(digits: int) -> Callable[[Any], str]:
    return lambda value: f"{value:.{digits}g}"


def _scientific(value: Any) -> str:
    return f"{value:.2e}"


def _text(value: Any) -> str:
    return html.escape(str(value), quote=True)


__all__ = ["render_overview", "render_report"]
