"""Facts about figures that need no matplotlib: formats, resolution, captions, rendered bytes.

Light: read by the command line's parser and by the report page written without figures.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

#: File formats of the figures, by suffix: the MIME type.
FIGURE_FORMATS: Final = {"png": "image/png", "svg": "image/svg+xml", "pdf": "application/pdf"}
#: Resolution [dots per inch] of raster figures unless asked otherwise.
DEFAULT_DPI: Final = 150
#: What each figure of :func:`~auvplan.viz.report.mission_figures` shows, by file stem.
FIGURE_CAPTIONS: Final = {
    "maps": "Terrain maps (paper Fig. 5): bathymetry, information, excitation and cost.",
    "paths": "Pre-planned paths (dashed) and optimised trajectories over the bathymetry "
    "(paper Fig. 6); circles: safety radius at start and goal.",
    "paths_cost": "Pre-planned paths over the shifted cost map that A* searched.",
    "paths_energy_only": "Energy-only optimum (terrain weight 0) against the pre-planned paths.",
    "paths_paper": "The paper's plan beside: its information-map routes (dashed) and their "
    "optimum.",
    "coordination": "Coordination space of the first two vehicles: collision region and the "
    "deconflicted schedule.",
    "time_series": "Surge and sway speed, yaw rate, propeller speeds (and control-surface "
    "deflections) and electrical power.",
    "separation": "Distance between every pair of vehicles and to every obstacle, on the "
    "closed-loop replay.",
    "navigation_predicted": "Predicted TAN position error (1-σ radial) along each flown plan, "
    "with the navigation budget.",
}


@dataclass(frozen=True)
class RenderedFigure:
    """A figure rendered to bytes: the file, and a preview that a web page can show.

    ``data`` is the file in ``figure_format`` (a key of :data:`FIGURE_FORMATS`); ``preview``
    is the same picture as PNG or SVG (``data`` itself unless the format is PDF) of MIME type
    ``preview_type``.
    """

    figure_format: str
    data: bytes
    preview: bytes
    preview_type: str
