"""The figure class of every auvplan plot: a matplotlib ``Figure`` a notebook shows as it is.

auvplan draws on bare :class:`matplotlib.figure.Figure` objects (no pyplot state, no GUI
backend, safe in threads and worker processes). Jupyter shows such a figure only when an
inline backend registered its formatter (``%matplotlib inline``); otherwise a cell that ends
with ``plan.plot()`` prints ``<Figure size 900x550 with 1 Axes>``. :class:`NotebookFigure`
carries its own ``_repr_png_``, which IPython calls for rich display, so the figure appears
with no magic and no backend.
"""

from __future__ import annotations

import io
from typing import Final

from matplotlib.figure import Figure

#: Resolution of the notebook rendering [dots per inch].
NOTEBOOK_DPI: Final = 100


class NotebookFigure(Figure):
    """A :class:`~matplotlib.figure.Figure` that IPython displays as a PNG image."""

    def _repr_png_(self) -> bytes:
        buffer = io.BytesIO()
        self.savefig(buffer, format="png", dpi=NOTEBOOK_DPI, bbox_inches="tight")
        return buffer.getvalue()


__all__ = ["NOTEBOOK_DPI", "NotebookFigure"]
