"""Terrain-aided navigation along the plans of an output folder, written into that folder.

:func:`evaluate_output_folder` is what ``auvplan evaluate`` does: read the folder
(:func:`auvplan.record.read_record`; stale or malformed files are refused), fly every
vehicle's track through the Monte-Carlo TAN simulator (:func:`auvplan.sweep.evaluate_folder`)
and write ``navigation.json`` and the figure of :func:`auvplan.viz.navigation.plot_navigation`
into the same folder, all-or-nothing (:func:`~auvplan.io.output.staged_output_dir`: the
folder's other files are kept).
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from auvplan._figures import DEFAULT_DPI
from auvplan.io.output import staged_output_dir
from auvplan.io.results import write_json
from auvplan.navigation.evaluation import EvaluationProgress
from auvplan.record import read_record
from auvplan.record.files import NAVIGATION_FILE
from auvplan.sweep.navigation import NavigationRequest, evaluate_folder

#: Opens the progress display of ``n`` Monte-Carlo runs in all and gives its callback.
ProgressDisplay = Callable[[int], AbstractContextManager[EvaluationProgress]]


@dataclass(frozen=True)
class EvaluatedFolder:
    """What :func:`evaluate_output_folder` wrote: ``navigation.json``'s document, the files."""

    document: dict[str, Any]
    """The ``navigation.json`` document (:func:`auvplan.navigation.navigation_summary`)."""
    written: tuple[Path, ...]
    """``navigation.json`` and the figure, if any, under the folder."""


def evaluate_output_folder(
    folder: Path,
    request: NavigationRequest,
    *,
    seed: int = 0,
    figure_format: str | None = "png",
    dpi: int = DEFAULT_DPI,
    progress: ProgressDisplay | None = None,
) -> EvaluatedFolder:
    """Fly the plans of ``folder`` through the TAN simulator and write the results there.

    Parameters
    ----------
    folder : Path
        Output folder of ``auvplan plan``/``demo`` (or a sweep's run).
    request : NavigationRequest
        The navigation to fly, over the plan mission's ``[navigation]`` table.
    seed : int
        Base seed of the Monte-Carlo runs.
    figure_format : str or None
        ``"png"``, ``"svg"`` or ``"pdf"``: the figure is ``navigation.<figure_format>``;
        None writes ``navigation.json`` only.
    dpi : int
        Resolution of the raster figure [dots per inch].
    progress : callable, optional
        Called with the number of runs to fly (tracks x runs); the context manager it
        returns gives the progress callback
        (:data:`~auvplan.navigation.evaluation.EvaluationProgress`).

    Returns
    -------
    EvaluatedFolder

    Raises
    ------
    InputError, DataFormatError
        For a folder without an optimised plan, a stale or malformed file, a navigation
        value out of range or a track that cannot be flown; nothing is written.
    """
    record = read_record(folder)
    options = request.options(record, seed=seed)
    n_tracks = sum(len(vehicles) for vehicles in record.plans.values())
    if progress is None:
        navigation = evaluate_folder(record, options)
    else:
        with progress(n_tracks * request.n_runs) as callback:
            navigation = evaluate_folder(record, options, progress=callback)
    figure = None
    if figure_format is not None:
        from auvplan.viz.navigation import plot_navigation  # matplotlib: only when drawn
        from auvplan.viz.report import render_figure

        figure = render_figure(
            plot_navigation(record.maps.bathymetry, navigation.evaluations),
            figure_format=figure_format,
            dpi=dpi,
        )
    written = [folder / NAVIGATION_FILE]
    with staged_output_dir(folder) as staging:
        write_json(navigation.document, staging / NAVIGATION_FILE)
        if figure is not None:
            figure_name = f"navigation.{figure_format}"
            (staging / figure_name).write_bytes(figure.data)
            written.append(folder / figure_name)
    return EvaluatedFolder(navigation.document, tuple(written))
