"""The record of each run and the sweep's table (``sweep.csv``, ``sweep.json``).

Every finished run's folder holds, next to the normal ``plan`` output, ``sweep_run.json``:
the run's id, varied values, seed, digest (:class:`~auvplan.sweep.spec.SweepRun`), wall time,
peak memory, the worker process (host, pid) and ``plan_of``: the run whose plan the folder
shares (runs of one mission that differ only in their seed are planned once,
:mod:`auvplan.sweep.runner`), ``null`` for a run that planned itself. A run is *finished*
when its folder holds ``summary.json`` and a ``sweep_run.json`` with the digest the sweep
expects; :func:`read_run_folder` then rebuilds its :class:`RunRecord` from the two files,
exactly as for a run that just ended, so a resumed sweep's table equals a fresh one's.

Columns of ``sweep.csv``, one row per run in grid order: ``run_id``, one column per varied key
(its dotted name), ``seed``, ``status`` (the plan verdict ``CONVERGED`` /
``CONSTRAINT_VIOLATED`` / ``NOT_CONVERGED`` / ``FAILED`` from ``summary.json``, ``PREPLANNED``
or ``DECONFLICTED`` for ``--stage``, or for a run that raised, its error class such as
``InfeasibleError`` or ``worker died``), ``reason`` (one line, empty for a converged plan),
``energy_J`` (fleet total), ``terrain_information`` (mean over vehicles of each one's mean
terrain information), ``n_iter``, ``wall_s``, ``peak_rss_mb`` (empty where the platform cannot
tell), ``tan_rmse_m``, ``energy_J.<vehicle>`` per vehicle, and ``folder`` (relative to the
sweep's folder in the files written: they hold no absolute path).

**Adding columns per run** (the hook for later evaluations): :func:`add_run_columns` calls a
function ``columns(folder) -> {column: value}`` on every run folder and fills (or adds) those
columns. :func:`navigation_columns` is the one the sweep always applies: it reads
``navigation.json`` (written by ``auvplan sweep --evaluate`` or ``auvplan evaluate
RUN_FOLDER``) and fills ``tan_rmse_m`` (``plans.terrain_aware.rmse_m``) and its companions
``tan_rmse_std_m``, ``tan_pcrb_m``, ``dead_reckoning_rmse_m`` (appended after ``folder``).
"""

from __future__ import annotations

import json
import math
import os
import socket
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final

import pandas as pd

from auvplan._version import __version__
from auvplan.errors import AuvplanError, DataFormatError
from auvplan.io.output import staged_output_file
from auvplan.io.results import write_json
from auvplan.io.text import read_json
from auvplan.record import PlanSummary, read_summary
from auvplan.record.files import NAVIGATION_FILE, RUN_RECORD_FILE
from auvplan.sweep.spec import SweepRun

TAN_COLUMN: Final = "tan_rmse_m"
#: Further columns from ``navigation.json``: column -> key of ``plans.terrain_aware``.
NAVIGATION_EXTRAS: Final = {
    "tan_rmse_std_m": "rmse_std_m",
    "tan_pcrb_m": "pcrb_rms_m",
    "dead_reckoning_rmse_m": "dead_reckoning_rmse_m",
}
#: Status of runs stopped by ``--stage`` before the optimiser.
STAGE_STATUS: Final = {"preplan": "PREPLANNED", "deconflict": "DECONFLICTED"}
#: Status of a plan whose optimiser produced nothing (summary.json) — a failed run.
PLAN_FAILED: Final = "FAILED"
#: Numeric result columns, in table order (after the varied keys, seed, status and reason).
RESULT_COLUMNS: Final = (
    "energy_J", "terrain_information", "n_iter", "wall_s", "peak_rss_mb", TAN_COLUMN,
)  # fmt: skip


@dataclass(frozen=True)
class RunRecord:
    """The outcome of one run: what :data:`sweep.csv <auvplan.sweep.table>` shows of it.

    ``energy`` [J] is the fleet total, ``terrain_information`` [-] the mean over vehicles,
    ``wall_s`` [s] the run's wall time, ``peak_rss_mb`` [MiB] its process's peak resident
    memory; each is ``None`` when the run has none (failed, or stopped by ``--stage``).
    ``folder`` is the run's output folder (``None`` when it failed before writing one);
    ``skipped`` tells a run finished by an earlier invocation; ``messages`` are the warnings
    the run logged; ``navigation_error`` says why its navigation evaluation (``--evaluate``)
    failed, if it did; ``plan_of`` is the run whose plan (or planning failure) this run
    shares, ``None`` when it planned itself.
    """

    run_id: str
    values: Mapping[str, Any]
    seed: int | None
    status: str
    reason: str = ""
    energy: float | None = None
    terrain_information: float | None = None
    n_iter: int | None = None
    wall_s: float | None = None
    peak_rss_mb: float | None = None
    vehicle_energy: Mapping[str, float] = field(default_factory=dict)
    folder: Path | None = None
    skipped: bool = False
    messages: tuple[str, ...] = ()
    navigation_error: str | None = None
    plan_of: str | None = None

    @property
    def failed(self) -> bool:
        """True when the run produced no plan output (it raised, or the optimiser failed)."""
        return self.folder is None or self.status == PLAN_FAILED

    @property
    def description(self) -> str:
        """One line for progress displays: ``run-id: status[ wall s][: reason]``."""
        wall = "" if self.wall_s is None else f" {self.wall_s:.1f} s"
        reason = f": {self.reason}" if self.reason else ""
        return f"{self.run_id}: {self.status}{wall}{reason}"


def run_record_document(
    run: SweepRun,
    *,
    wall_s: float,
    peak_rss_mb: float | None,
    messages: Sequence[str],
    plan_of: str | None = None,
) -> dict[str, Any]:
    """The content of a finished run's ``sweep_run.json`` (written by the worker that ran it).

    ``wall_s`` [s] and ``peak_rss_mb`` [MiB] are those of the planning, also in a run that
    shares the plan of run ``plan_of``.
    """
    return {
        "auvplan_version": __version__,
        "run_id": run.run_id,
        "values": dict(run.values),
        "seed": run.seed,
        "digest": run.digest,
        "wall_s": wall_s,
        "peak_rss_mb": peak_rss_mb,
        "worker": {"host": socket.gethostname(), "pid": os.getpid()},
        "messages": list(messages),
        "plan_of": plan_of,
    }


def read_run_folder(folder: Path, run: SweepRun) -> RunRecord | None:
    """The record of ``run`` if ``folder`` holds it finished, else ``None`` (to be run).

    Finished means ``summary.json`` (:func:`auvplan.record.read_summary`) and
    ``sweep_run.json`` are readable and the digest matches ``run`` (same mission, values and
    stage).
    """
    try:
        record = read_json(folder / RUN_RECORD_FILE, what="sweep run record")
        summary = read_summary(folder)
    except AuvplanError:
        return None
    if not isinstance(record, dict) or record.get("digest") != run.digest:
        return None
    try:
        return _record_from(run, folder, record, summary)
    except (KeyError, TypeError, ValueError):  # a run record of another layout: run again
        return None


def _record_from(
    run: SweepRun, folder: Path, record: dict[str, Any], summary: PlanSummary
) -> RunRecord:
    optimization = summary.optimization
    common = {
        "folder": folder,
        "wall_s": float(record["wall_s"]),
        "peak_rss_mb": record["peak_rss_mb"],
        "messages": tuple(record["messages"]),
        "plan_of": record.get("plan_of"),  # absent from the records of earlier versions
    }
    if optimization is None:
        return RunRecord(run.run_id, run.values, run.seed, STAGE_STATUS[summary.stage], **common)
    status = optimization.plan_status
    reason = "" if status == "CONVERGED" else " ".join(optimization.verdict.split())
    vehicles = optimization.vehicles or {}
    energy = {name: vehicle.energy_J for name, vehicle in vehicles.items()}
    information = [
        vehicle.mean_terrain_information
        for vehicle in vehicles.values()
        if vehicle.mean_terrain_information is not None
    ]
    return RunRecord(
        run.run_id,
        run.values,
        run.seed,
        status,
        reason,
        energy=optimization.total_energy_J if energy else None,
        terrain_information=sum(information) / len(information) if information else None,
        n_iter=optimization.n_iter,
        vehicle_energy=energy,
        **common,
    )


def sweep_frame(records: Sequence[RunRecord], keys: Sequence[str]) -> pd.DataFrame:
    """The table of ``records`` (module notes: columns), one row per run in the given order."""
    rows = []
    for record in records:
        row: dict[str, Any] = {"run_id": record.run_id}
        row.update({key: _cell(record.values[key]) for key in keys})
        row.update(seed=record.seed, status=record.status, reason=record.reason)
        row.update(
            energy_J=record.energy,
            terrain_information=record.terrain_information,
            n_iter=record.n_iter,
            wall_s=record.wall_s,
            peak_rss_mb=record.peak_rss_mb,
        )
        row[TAN_COLUMN] = math.nan
        row.update({f"energy_J.{name}": value for name, value in record.vehicle_energy.items()})
        row["folder"] = "" if record.folder is None else str(record.folder)
        rows.append(row)
    columns = ["run_id", *keys, "seed", "status", "reason", *RESULT_COLUMNS]
    frame = pd.DataFrame(rows, columns=None if rows else columns)
    vehicle_columns = [column for column in frame.columns if column not in {*columns, "folder"}]
    frame = frame.reindex(columns=[*columns, *vehicle_columns, "folder"])
    frame["seed"] = frame["seed"].astype("Int64")
    frame["n_iter"] = frame["n_iter"].astype("Int64")
    return frame


def add_run_columns(
    frame: pd.DataFrame, columns: Callable[[Path], Mapping[str, float | str | None]]
) -> pd.DataFrame:
    """Fill columns per run folder: ``columns(folder)`` gives ``{column: value}`` for a run.

    The hook later evaluations use to put their figures into the sweep's table. Rows without
    a folder (failed runs) are left as they are; a column the function names for the first
    time is added (empty elsewhere). Returns a new frame.

    Examples
    --------
    >>> frame = pd.DataFrame({"run_id": ["a", "b"], "folder": ["/runs/a", ""]})
    >>> add_run_columns(frame, lambda folder: {"name": folder.name})["name"].tolist()
    ['a', nan]
    """
    frame = frame.copy()
    for index, folder in frame["folder"].items():
        if not folder:
            continue
        for column, value in columns(Path(folder)).items():
            if column not in frame.columns:
                frame[column] = pd.Series(dtype=object if isinstance(value, str) else float)
            frame.loc[index, column] = value
    return frame


def navigation_columns(folder: Path) -> dict[str, float | None]:
    """TAN columns from the run folder's ``navigation.json`` (none while it is absent).

    ``tan_rmse_m`` is ``plans.terrain_aware.rmse_m``; when the file has them, also
    ``tan_rmse_std_m`` (spread of the runs' RMSE), ``tan_pcrb_m`` (RMS posterior Cramér-Rao
    bound) and ``dead_reckoning_rmse_m`` [m].

    Raises
    ------
    DataFormatError
        If ``navigation.json`` exists but is unreadable or lacks
        ``plans.terrain_aware.rmse_m``.
    """
    path = folder / NAVIGATION_FILE
    if not path.is_file():
        return {}
    document = read_json(path, what="navigation file")
    try:
        plan = document["plans"]["terrain_aware"]
        rmse = plan["rmse_m"]
    except (KeyError, TypeError):
        raise DataFormatError(f"{path}: no plans.terrain_aware.rmse_m") from None
    columns: dict[str, float | None] = {TAN_COLUMN: None if rmse is None else float(rmse)}
    for column, key in NAVIGATION_EXTRAS.items():
        if plan.get(key) is not None:
            columns[column] = float(plan[key])
    return columns


def write_sweep_files(
    frame: pd.DataFrame, directory: Path, *, spec: Mapping[str, Any], **sections: Any
) -> list[Path]:
    """Write ``sweep.csv`` (the frame) and ``sweep.json`` (spec, sections and rows) atomically.

    ``directory`` is created if needed. Returns the two paths.
    """
    directory.mkdir(parents=True, exist_ok=True)
    table, document = directory / "sweep.csv", directory / "sweep.json"
    if "folder" in frame.columns:  # the run folders relative to the sweep's: the files travel
        frame = frame.assign(folder=[f and relative_to(f, directory) for f in frame["folder"]])
    with staged_output_file(table) as staging:
        frame.to_csv(staging, index=False)
    content = {"auvplan_version": __version__, "spec": spec, **sections, "runs": json_rows(frame)}
    with staged_output_file(document) as staging:  # dates, paths, pandas NA as text
        write_json(json.loads(json.dumps(content, default=str)), staging)
    return [table, document]


def relative_to(path: str | Path, directory: Path) -> str:
    """``path`` relative to ``directory`` (POSIX; ``..`` where it lies outside).

    How the sweep's files name other files: they hold no absolute path.

    Examples
    --------
    >>> sweep = Path("/data/sweep")
    >>> relative_to("/data/sweep/runs/a", sweep), relative_to("/data/m.toml", sweep)
    ('runs/a', '../m.toml')
    """
    return Path(os.path.relpath(Path(path).resolve(), directory.resolve())).as_posix()


def json_rows(frame: pd.DataFrame) -> list[dict[str, Any]]:
    """The rows of ``frame`` as JSON objects (missing cells ``None``, numpy scalars unwrapped)."""
    return [
        {str(key): _json_cell(value) for key, value in row.items()}
        for row in frame.to_dict(orient="records")
    ]


def write_pareto_table(
    points: pd.DataFrame, directory: Path, *, label_key: str | None, objective: str
) -> list[Path]:
    """Write the trade-off points as ``pareto.csv`` and ``pareto.md``; returns the two paths.

    ``points`` is :attr:`auvplan.sweep.ParetoView.points`. The markdown table shows per point
    its group, label, energy [kJ] and its change against the energy-only plan [%], the
    objective and its improvement [%], the runs averaged, and the front it lies on.
    """
    csv_file, markdown = directory / "pareto.csv", directory / "pareto.md"
    with staged_output_file(csv_file) as staging:
        points.to_csv(staging, index=False)
    header = [
        "group", label_key or "label", "energy [kJ]", "energy vs energy-only",
        objective, "improvement", "runs", "converged", "front",
    ]  # fmt: skip
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for _, point in points.iterrows():
        front = "overall" if point["on_overall_front"] else ("group" if point["on_front"] else "")
        cells = [
            str(point["group"]) or "-",
            "energy-only" if point["is_reference"] else str(point["label"]),
            f"{point['energy_J'] / 1e3:.1f}",
            _percent(point["energy_increase"]),
            f"{point[objective]:.3f}",
            _percent(point["improvement"]),
            str(point["n_runs"]),
            "yes" if point["converged"] else "no",
            front,
        ]
        lines.append("| " + " | ".join(cells) + " |")
    with staged_output_file(markdown) as staging:
        staging.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return [csv_file, markdown]


def _percent(fraction: float) -> str:
    return "" if math.isnan(fraction) else f"{100.0 * fraction:+.1f} %"


def _cell(value: Any) -> Any:
    """A varied value as a table cell (arrays and tables as JSON text)."""
    return json.dumps(value, default=str) if isinstance(value, list | tuple | dict) else value


def _json_cell(value: Any) -> Any:
    """A table cell as a JSON value: missing as ``None``, other non-JSON types as text."""
    if value is None or value is pd.NA or (isinstance(value, float) and math.isnan(value)):
        return None
    if isinstance(value, bool | int | float | str):
        return value
    return value.item() if hasattr(value, "item") else str(value)


__all__ = [
    "RUN_RECORD_FILE",
    "TAN_COLUMN",
    "RunRecord",
    "add_run_columns",
    "json_rows",
    "navigation_columns",
    "read_run_folder",
    "relative_to",
    "run_record_document",
    "sweep_frame",
    "write_pareto_table",
    "write_sweep_files",
]
