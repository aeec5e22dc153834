"""The output folder of a mission run: data files, exports, figures and ``report.html``.

:func:`write_output_folder` is what ``auvplan plan``/``demo`` and
:meth:`auvplan.MissionPlan.save` write, all-or-nothing
(:func:`~auvplan.io.output.staged_output_dir`): the data files of the run's record
(:func:`~auvplan.record.write_record`), the exports asked for (made from the record, as
``auvplan export`` makes them from the record it reads), the figures of
:func:`~auvplan.viz.report.mission_figures` and the self-contained ``report.html``
(:func:`~auvplan.viz.html.render_report`), built from the record's summary.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from auvplan._figures import DEFAULT_DPI, RenderedFigure
from auvplan.export import DEFAULT_TOLERANCE_M, MoosFrame, write_exports
from auvplan.io.output import staged_output_dir
from auvplan.io.writing import writing
from auvplan.mission.pipeline import MissionResult
from auvplan.record import PlanRecord, export_plan, write_record
from auvplan.record.files import EXPORT_FOLDER, REPORT_FILE
from auvplan.viz.html import render_report

if TYPE_CHECKING:
    from auvplan.api.companion import Companion


def write_output_folder(
    result: MissionResult,
    record: PlanRecord,
    target: Path,
    *,
    figures: bool = True,
    figure_format: str = "png",
    dpi: int = DEFAULT_DPI,
    exports: Sequence[str] = (),
    tolerance: float = DEFAULT_TOLERANCE_M,
    moos_frame: MoosFrame = "utm",
    companion: Companion | None = None,
) -> list[Path]:
    """Write the output folder of ``result`` into ``target`` (module notes).

    Parameters
    ----------
    result : MissionResult
        The run (the figures are drawn from it).
    record : PlanRecord
        Its record (:func:`auvplan.mission.outputs.plan_record`): the data files, exports
        and report.
    target : Path
        The folder; files of the same name are replaced, other files kept.
    figures : bool
        Write the figures (the report embeds them).
    figure_format : str
        ``"png"``, ``"svg"`` or ``"pdf"``.
    dpi : int
        Resolution of raster figures [dots per inch].
    exports : sequence of str
        Export formats (:data:`auvplan.export.FORMATS`), written into ``target/export``;
        ignored without an optimised plan.
    tolerance : float
        Waypoint tolerance of the exports [m].
    moos_frame : {"utm", "local"}
        Frame of the MOOS-IvP points (:mod:`auvplan.export.moos`).
    companion : Companion, optional
        Draws half the figures in a second process (:mod:`auvplan.api.companion`).

    Returns
    -------
    list of Path
        The files written, under ``target``.
    """
    rendered: dict[str, RenderedFigure] = {}
    if figures:  # rendered before anything is written: a bad format or dpi writes nothing
        from auvplan.viz.report import render_mission_figures  # matplotlib: only now

        draw = render_mission_figures if companion is None else companion.render_figures
        rendered = draw(result, figure_format=figure_format, dpi=dpi)
    with staged_output_dir(target) as staging:
        written = write_record(record, staging)
        if exports and record.has_plan:
            written += write_exports(
                export_plan(record),
                staging / EXPORT_FOLDER,
                exports,
                tolerance=tolerance,
                moos_frame=moos_frame,
            )
        for stem, figure in rendered.items():
            path = staging / f"{stem}.{figure.figure_format}"
            with writing(path):
                path.write_bytes(figure.data)
            written.append(path)
        report = staging / REPORT_FILE
        names = [path.relative_to(staging).as_posix() for path in [*written, report]]
        page = render_report(record.summary.document(), rendered, files=names)
        with writing(report):
            report.write_text(page, encoding="utf-8")
        written.append(report)
        return [target / path.relative_to(staging) for path in written]


__all__ = ["write_output_folder"]
