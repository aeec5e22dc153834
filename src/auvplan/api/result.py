"""The notebook-first API: plan a mission, look at the plan, save it, open it again.

>>> import auvplan                                        # doctest: +SKIP
>>> plan = auvplan.plan("mission.toml")                   # doctest: +SKIP
>>> plan.status, plan.summary["optimization"]["total_energy_J"]   # doctest: +SKIP
>>> plan.to_dataframe().groupby("vehicle")["power"].mean()          # doctest: +SKIP
>>> plan.plot().savefig("paths.png")                      # doctest: +SKIP
>>> plan.save("out/run1"); auvplan.load("out/run1").to_xarray()     # doctest: +SKIP

A :class:`MissionPlan` holds what an output folder holds, its :class:`~auvplan.record.PlanRecord`
(``summary.json``, the maps of ``maps.nc``, each vehicle's trajectories), so a plan made in
memory (:func:`plan`) and the same plan read back from its folder (:func:`load`) answer alike.
"""

from __future__ import annotations

import logging
import os
import shutil
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from auvplan._figures import DEFAULT_DPI
from auvplan._typing import FloatArray
from auvplan.errors import InputError
from auvplan.export import DEFAULT_TOLERANCE_M, MoosFrame
from auvplan.io.output import staged_output_dir
from auvplan.mission.config import MissionConfig, load_mission, parse_mission
from auvplan.mission.outputs import plan_record
from auvplan.mission.pipeline import MissionResult, Stage, run_mission
from auvplan.mission.progress import ProgressReporter, no_progress
from auvplan.record import PlanRecord, read_record, trajectories_dataset_of
from auvplan.record.files import MAIN_PLAN
from auvplan.terrain import BathymetryGrid

if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr
    from matplotlib.figure import Figure

    from auvplan.api.companion import Companion
    from auvplan.api.progress import ConsoleProgress
    from auvplan.api.replanning import StatesSource

#: What :func:`plan` accepts as a mission: a TOML file, a validated mission, or its document.
MissionSource = str | os.PathLike[str] | MissionConfig | Mapping[str, Any]


class MissionPlan:
    """A planned mission: its summary, trajectories and figures (module notes).

    Made by :func:`plan` (in memory; :attr:`result` holds the full
    :class:`~auvplan.mission.MissionResult`) or :func:`load` (from an output folder).

    Parameters
    ----------
    record : PlanRecord
        What the output folder holds (:mod:`auvplan.record`).
    result : MissionResult, optional
        The run, when planned in this session.
    folder : Path, optional
        The output folder it was loaded from.
    """

    def __init__(
        self,
        record: PlanRecord,
        *,
        result: MissionResult | None = None,
        folder: Path | None = None,
    ) -> None:
        self._record = record
        self._summary = record.summary.document()
        self._trajectories = trajectories_dataset_of(record, MAIN_PLAN) if record.has_plan else None
        self._result = result
        self._folder = folder

    @classmethod
    def from_result(cls, result: MissionResult, *, warnings: Sequence[str] = ()) -> MissionPlan:
        """The plan of a run of :func:`~auvplan.mission.run_mission` (``warnings``: logged)."""
        return cls(plan_record(result, warnings=warnings), result=result)

    @property
    def record(self) -> PlanRecord:
        """What the output folder holds: summary, mission, maps, each vehicle's trajectories."""
        return self._record

    @property
    def summary(self) -> dict[str, Any]:
        """The ``summary.json`` document (every number needed to verify the plan)."""
        return self._summary

    @property
    def bathymetry(self) -> BathymetryGrid:
        """The terrain the mission was planned on."""
        return self._record.maps.bathymetry

    @property
    def result(self) -> MissionResult | None:
        """The full run (stage results, solver history), if planned in this session."""
        return self._result

    @property
    def folder(self) -> Path | None:
        """The output folder the plan was loaded from, if any."""
        return self._folder

    @property
    def names(self) -> tuple[str, ...]:
        """The vehicles' names, in mission order."""
        return tuple(vehicle["name"] for vehicle in self._summary["vehicles"])

    @property
    def status(self) -> str | None:
        """The plan's status, ``None`` when the run stopped before the optimiser.

        ``"CONVERGED"`` when every constraint holds between samples, another
        :class:`~auvplan.mission.checks.PlanStatus` name, or ``"FAILED"``.
        """
        optimization = self._summary.get("optimization")
        return None if optimization is None else str(optimization["plan_status"])

    @property
    def warnings(self) -> tuple[str, ...]:
        """The warnings logged during the run."""
        return tuple(self._summary.get("warnings", ()))

    def to_xarray(self) -> xr.Dataset:
        """The optimised trajectories: the dataset of ``trajectories.nc`` (a copy).

        Dimensions ``trajectory`` (vehicles) and ``obs`` (time samples); coordinates ``time``
        (UTC), ``depth`` and, on georeferenced terrain, ``lat``/``lon``; variables ``north``,
        ``east`` [m], ``heading`` [deg], ``u``, ``v`` [m/s], ``r`` [rad/s], ``n_ps``,
        ``n_sb`` [rev/s] and ``power`` [W] (:mod:`auvplan.io.trajectories_file`); a mixed fleet
        adds its other actuator states (``n_prop`` [rev/s], ``delta_rudder`` [rad], NaN for
        vehicles without them) and ``vehicle_type``.

        Raises
        ------
        InputError
            If there is no optimised plan (the run stopped early or the optimiser failed).
        """
        if self._trajectories is None:
            reason = self._summary.get("optimization", {}).get("verdict")
            raise InputError(
                "no optimised plan: "
                + (reason or f"the run stopped after stage {self._summary.get('stage')}")
            )
        return self._trajectories.copy(deep=True)

    def to_dataframe(self) -> pd.DataFrame:
        """The optimised trajectories in long format: one row per vehicle and time sample.

        Columns ``vehicle``, ``time`` (UTC), ``t`` [s since the start], then the coordinates
        and variables of :meth:`to_xarray`: ``lat``, ``lon`` (georeferenced terrain only),
        ``depth``, ``north``, ``east``, ``u``, ``v``, ``r``, ``n_ps``, ``n_sb``, ``power``,
        ``heading`` (a mixed fleet: its other actuator states before ``heading``,
        ``vehicle_type`` after it).
        """
        dataset = self.to_xarray()
        frame = dataset.to_dataframe().reset_index().drop(columns="obs")
        frame = frame.rename(columns={"trajectory": "vehicle"}).astype({"vehicle": str})
        frame["t"] = (frame["time"] - dataset["time"].values.min()).dt.total_seconds()
        frame["time"] = frame["time"].dt.tz_localize("UTC")  # the file's times are UTC
        places = [name for name in ("lat", "lon", "depth") if name in dataset.coords]
        return frame[["vehicle", "time", "t", *places, *map(str, dataset.data_vars)]]

    def plot(self) -> Figure:
        """The mission figure: pre-planned paths and optimised trajectories over the terrain.

        The figure ``paths`` of the output folder (paper Fig. 6), with latitude/longitude
        axes and a scale bar on georeferenced terrain.
        """
        from auvplan.viz.mission import plot_mission_paths

        vehicles = self._summary["vehicles"]
        planned = [np.asarray(v["preplan"]["points_north_east_m"], dtype=float) for v in vehicles]
        tables = self._record.plans.get(MAIN_PLAN)
        tracks = None if tables is None else [table.positions for table in tables]
        obstacles = self._summary.get("obstacles", [])
        circles = np.array(
            [(o["center"]["north"], o["center"]["east"], o["radius_m"])
             for o in obstacles if o["shape"] == "circle"]
        ).reshape(-1, 3)  # fmt: skip

        def rings(obstacle: dict[str, Any]) -> tuple[FloatArray, ...]:
            return tuple(
                np.array([(p["north"], p["east"]) for p in ring], dtype=float)
                for ring in (obstacle["vertices"], *obstacle.get("holes", ()))
            )

        polygons = [rings(o) for o in obstacles if o["shape"] == "polygon"]
        area = next((rings(o) for o in obstacles if o["shape"] == "area"), ())
        return plot_mission_paths(
            self.bathymetry, self.names, planned, tracks,
            safety_radius=self._summary["fleet"]["safety_radius_m"],
            circles=circles, polygons=polygons, area=area,
        )  # fmt: skip

    def replan(
        self,
        at: float,
        states: StatesSource = None,
        *,
        progress: bool = True,
        jobs: int | None = None,
    ) -> MissionPlan:
        """Plan the rest of this plan from time ``at`` [s] and the vehicles' states then.

        ``states``: a ``STATES.csv`` file (columns ``vehicle,north,east,heading_deg,speed``,
        or ``lat,lon`` for ``north,east``) or vehicle -> ``{north, east, heading_deg,
        speed}``; vehicles not given start where this plan has them at ``at``. The new plan
        keeps the goals, the horizon's end (its horizon is ``T - at``) and the constraints;
        ``summary["replan"]`` names this plan (:func:`auvplan.api.replanning.replan`, which
        also says what ``jobs`` does).

        Raises
        ------
        InputError, DataFormatError
            For a bad ``at`` or state, before anything is planned.
        """
        from auvplan.api.replanning import replan

        return replan(self, at, states, progress=progress, jobs=jobs)

    def save(
        self,
        directory: str | os.PathLike[str],
        *,
        figures: bool = True,
        figure_format: str = "png",
        dpi: int = DEFAULT_DPI,
        exports: Sequence[str] = (),
        tolerance_m: float = DEFAULT_TOLERANCE_M,
        moos_frame: MoosFrame = "utm",
        companion: Companion | None = None,
    ) -> list[Path]:
        """Write the output folder of ``auvplan plan`` into ``directory``; returns the files.

        ``summary.json``, ``mission.toml``, ``maps.nc``, the trajectories (CSV and NetCDF),
        the figures in ``figure_format`` (``png``, ``svg`` or ``pdf``) at ``dpi``, the
        exports (``moos``, ``qgc``, ``imc``, ``gpx``, ``kml``, ``geojson``) into
        ``directory/export`` (MOOS-IvP points in ``moos_frame``) and ``report.html``; all-or-nothing
        (:func:`auvplan.api.folder.write_output_folder`). A plan loaded from a folder is
        copied as it is (the options apply to a plan made in this session). A ``companion``
        (:mod:`auvplan.api.companion`) draws half the figures.
        """
        target = Path(directory)
        if self._result is None:
            assert self._folder is not None  # a plan is made in memory or loaded
            with staged_output_dir(target) as staging:
                shutil.copytree(self._folder, staging, dirs_exist_ok=True)
                copied = sorted(path for path in staging.rglob("*") if path.is_file())
                return [target / path.relative_to(staging) for path in copied]
        from auvplan.api.folder import write_output_folder
        from auvplan.export import parse_formats

        return write_output_folder(
            self._result, self._record, target, figures=figures,
            figure_format=figure_format, dpi=dpi,
            exports=parse_formats(",".join(exports)) if exports else (), tolerance=tolerance_m,
            moos_frame=moos_frame, companion=companion,
        )  # fmt: skip

    def _repr_html_(self) -> str:
        """The status and the vehicles table (Jupyter shows a plan with it)."""
        from auvplan.viz.html import render_overview

        return render_overview(self._summary)

    def __repr__(self) -> str:
        where = "" if self._folder is None else f", folder={str(self._folder)!r}"
        status = self.status or f"stage {self._summary.get('stage')}"
        return f"MissionPlan(vehicles={list(self.names)}, status={status!r}{where})"


def plan(
    mission: MissionSource,
    *,
    stage: Stage | str = Stage.FULL,
    compare_energy_only: bool = False,
    compare_no_current: bool = False,
    compare_paper: bool = False,
    progress: bool = True,
    companion: Companion | None = None,
) -> MissionPlan:
    """Plan a mission: maps and A* paths, deconfliction, PRONTO (SPEC §1-§5).

    Parameters
    ----------
    mission : str, path, MissionConfig or mapping
        A mission TOML file, a validated mission (:func:`auvplan.load_mission`,
        :func:`auvplan.demo_mission`), or the mission document as a dict (file paths in it
        are relative to the current folder).
    stage : Stage or str
        Last stage to run: ``"preplan"``, ``"deconflict"`` or ``"full"``.
    compare_energy_only : bool
        Also optimise with the terrain weight set to 0 (the paper's energy-only reference).
    compare_no_current : bool
        With a ``[current]``: also plan as if in still water, fly both plans in the current
        and report the saving (``summary["current_comparison"]``).
    compare_paper : bool
        With navigation-aware routes: also plan on the paper's information-map routes
        (``summary["paper"]``, ``trajectories_paper.csv``).
    progress : bool
        Show progress (:class:`auvplan.api.progress.ConsoleProgress`).
    companion : Companion, optional
        A second process (:mod:`auvplan.api.companion`) that compiles the optimiser's kernels
        of a first run while this one searches the paths.

    Returns
    -------
    MissionPlan
        Also when the optimiser fails or a constraint is violated: see
        :attr:`MissionPlan.status` and ``summary["optimization"]``.

    Raises
    ------
    InputError, DataFormatError, InfeasibleError
        For a mission that cannot be planned (the message names the key, file or vehicle).
    """
    config = _mission_config(mission)
    try:
        last_stage = Stage(stage)
    except ValueError:
        choices = ", ".join(repr(s.value) for s in Stage)
        raise InputError(f"stage must be one of {choices}, got {stage!r}") from None
    with logged_warnings() as warnings, progress_reporter(config, progress) as reporter:
        stages: ProgressReporter = no_progress if reporter is None else reporter
        if companion is not None and last_stage is Stage.FULL:
            companion.warm_up(config)
        result = run_mission(
            config,
            stage=last_stage,
            compare_energy_only=compare_energy_only,
            compare_no_current=compare_no_current,
            compare_paper=compare_paper,
            callback=None if reporter is None else reporter.iteration,
            progress=stages,
            before_optimization=None if companion is None else companion.wait_for_warm_up,
            jobs=1 if companion is None else 2,
        )
    return MissionPlan.from_result(result, warnings=warnings)


def load(folder: str | os.PathLike[str]) -> MissionPlan:
    """Open the output folder of ``auvplan plan``/``demo`` or :meth:`MissionPlan.save`.

    Raises
    ------
    InputError
        If ``folder`` is not an output folder (no ``summary.json``).
    DataFormatError
        If one of its files is unreadable, malformed or stale
        (:func:`auvplan.record.read_record`).
    """
    path = Path(folder)
    return MissionPlan(read_record(path), folder=path)


def _mission_config(mission: MissionSource) -> MissionConfig:
    if isinstance(mission, MissionConfig):
        return mission
    if isinstance(mission, Mapping):
        return parse_mission(mission, base_dir=Path.cwd())
    return load_mission(Path(mission))


@contextmanager
def logged_warnings() -> Iterator[list[str]]:
    """Collect the warnings that auvplan logs while the block runs (one line each)."""
    collected: list[str] = []

    class Collector(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            collected.append(record.getMessage())

    handler = Collector(logging.WARNING)
    source = logging.getLogger("auvplan")
    source.addHandler(handler)
    try:
        yield collected
    finally:
        source.removeHandler(handler)


@contextmanager
def progress_reporter(config: MissionConfig, progress: bool) -> Iterator[ConsoleProgress | None]:
    """The console progress of a run of ``config`` while the block runs (None: ``progress`` off)."""
    if not progress:
        yield None
        return
    from auvplan.api.progress import ConsoleProgress

    levels = config.solver.pronto_options().epsilon_levels()
    with ConsoleProgress(epsilon_levels=levels) as reporter:
        yield reporter


__all__ = ["MissionPlan", "MissionSource", "load", "plan"]
