"""All file input and output of auvplan: bathymetry readers, vehicle files, result writers."""

from __future__ import annotations

from auvplan.io.output import staged_output_dir

__all__ = ["staged_output_dir"]
