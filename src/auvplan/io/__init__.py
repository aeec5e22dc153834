"""All file input and output of auvplan: bathymetry readers, vehicle files, result writers."""

from __future__ import annotations

from auvplan.io.bathymetry import detect_format, read_bathymetry
from auvplan.io.maps_file import read_maps_netcdf, write_maps_netcdf
from auvplan.io.output import (
    check_output_dir,
    check_output_file,
    staged_output_dir,
    staged_output_file,
)
from auvplan.io.text import read_text, read_toml
from auvplan.io.vehicles import load_propeller_table, load_vehicle, packaged_vehicle_types

__all__ = [
    "check_output_dir",
    "check_output_file",
    "detect_format",
    "load_propeller_table",
    "load_vehicle",
    "packaged_vehicle_types",
    "read_bathymetry",
    "read_maps_netcdf",
    "read_text",
    "read_toml",
    "staged_output_dir",
    "staged_output_file",
    "write_maps_netcdf",
]
