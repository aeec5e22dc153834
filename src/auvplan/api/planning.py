"""Plan a mission and write its output folder: what ``auvplan plan`` and ``demo`` do.

:func:`plan_to_folder` checks the export formats asked for (before any planning), runs the
pipeline (:func:`auvplan.api.plan`) with a second process
(:class:`~auvplan.api.companion.Companion`) when two are to be used
(:func:`~auvplan.api.companion.resolve_jobs`), and writes the output folder
(:meth:`auvplan.MissionPlan.save`). A plan that did not converge or breaks a constraint is
written too: :attr:`auvplan.mission.MissionResult.problem` says why.
"""

from __future__ import annotations

from contextlib import nullcontext
from dataclasses import dataclass
from pathlib import Path

from auvplan._figures import DEFAULT_DPI
from auvplan.api.companion import Companion, resolve_jobs
from auvplan.api.result import plan
from auvplan.errors import InputError
from auvplan.export import DEFAULT_TOLERANCE_M, MoosFrame, check_georeference, parse_formats
from auvplan.mission.config import MissionConfig
from auvplan.mission.pipeline import MissionResult


@dataclass(frozen=True)
class SavedPlan:
    """A mission run and the files of its output folder."""

    result: MissionResult
    """The run (:attr:`~auvplan.mission.MissionResult.problem`: why it is not a usable plan)."""
    written: tuple[Path, ...]
    """The files written, under the output folder."""


def plan_to_folder(
    config: MissionConfig,
    target: Path,
    *,
    stage: str = "full",
    compare_energy_only: bool = False,
    compare_no_current: bool = False,
    compare_paper: bool = False,
    progress: bool = True,
    jobs: int | None = None,
    figures: bool = True,
    figure_format: str = "png",
    dpi: int = DEFAULT_DPI,
    exports: str | None = None,
    tolerance_m: float = DEFAULT_TOLERANCE_M,
    moos_frame: MoosFrame = "utm",
) -> SavedPlan:
    """Plan ``config`` and write its output folder into ``target``.

    Parameters
    ----------
    config : MissionConfig
        The mission (:func:`auvplan.load_mission`, :func:`auvplan.demo_mission`).
    target : Path
        The output folder; files of the same name are replaced, other files kept.
    stage : str
        Last stage to run: ``"preplan"``, ``"deconflict"`` or ``"full"``.
    compare_energy_only, compare_no_current, compare_paper : bool
        The comparison plans of :func:`auvplan.api.plan`.
    progress : bool
        Show progress on the console.
    jobs : int, optional
        Processes, 1 or 2 (default: :func:`~auvplan.api.companion.resolve_jobs`).
    exports : str, optional
        Export formats, comma-separated (:data:`auvplan.export.FORMATS`); they need the full
        stage and, but for ``moos`` in the ``local`` frame, a georeferenced terrain.
    figures, figure_format, dpi, tolerance_m, moos_frame
        The output folder's options, as in :meth:`auvplan.MissionPlan.save` (``dpi`` in dots
        per inch, ``tolerance_m`` in m).

    Returns
    -------
    SavedPlan
        Also when the plan did not converge or breaks a constraint.

    Raises
    ------
    InputError, DataFormatError, InfeasibleError
        For a mission that cannot be planned, exports that cannot be made of it, or ``jobs``
        other than 1 or 2; nothing is written.
    """
    formats = _export_formats(config, exports, stage, moos_frame)
    with Companion() if resolve_jobs(jobs) == 2 else nullcontext() as companion:
        if companion is not None and figures:
            companion.start()  # its imports overlap the planning
        mission_plan = plan(
            config,
            stage=stage,
            compare_energy_only=compare_energy_only,
            compare_no_current=compare_no_current,
            compare_paper=compare_paper,
            progress=progress,
            companion=companion,
        )
        written = mission_plan.save(
            target,
            figures=figures,
            figure_format=figure_format,
            dpi=dpi,
            exports=formats,
            tolerance_m=tolerance_m,
            moos_frame=moos_frame,
            companion=companion,
        )
    assert mission_plan.result is not None  # planned in this session
    return SavedPlan(mission_plan.result, tuple(written))


def _export_formats(
    config: MissionConfig, exports: str | None, stage: str, moos_frame: str
) -> tuple[str, ...]:
    """The formats of ``exports``, checked before any planning (fail fast).

    On the synthetic bank only those that need no lat/lon
    (:func:`~auvplan.export.check_georeference`); a bathymetry file without a CRS is known
    only once read, and refused when exporting.
    """
    if exports is None:
        return ()
    formats = parse_formats(exports)
    if stage != "full":
        raise InputError(f"--export needs the optimised plan: drop --stage {stage}")
    if config.terrain.synthetic:
        check_georeference(formats, moos_frame, "the synthetic bank")
    return formats
