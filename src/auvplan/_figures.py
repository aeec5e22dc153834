"""File formats and default resolution of figures (light: read by the command line's parser)."""

from __future__ import annotations

from typing import Final

#: File formats of the figures, by suffix: the MIME type.
FIGURE_FORMATS: Final = {"png": "image/png", "svg": "image/svg+xml", "pdf": "application/pdf"}
#: Resolution [dots per inch] of raster figures unless asked otherwise.
DEFAULT_DPI: Final = 150
