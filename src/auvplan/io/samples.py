"""The bathymetry samples shipped with auvplan, by name.

Three small real grids (``auvplan/data/bathymetry``; sources, licences and checksums in the
README beside them) let the examples and tests run on a fresh clone: a mission names one with
``[terrain] sample = "monterey"``.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import Final, Literal, get_args

#: A sample's name, as a mission file writes it.
SampleName = Literal["monterey", "balanus", "lisbon"]
#: The file of each sample.
SAMPLE_FILES: Final[dict[str, str]] = {
    "monterey": "monterey_canyon_head_ncei_13arcsec.nc",
    "balanus": "balanus_seamount_gebco2024_15arcsec.nc",
    "lisbon": "south_lisbon_shelf_emodnet_dtm.nc",
}
assert tuple(SAMPLE_FILES) == get_args(SampleName)


def samples_folder() -> Path:
    """The folder of the packaged samples (inside the installed package)."""
    return Path(str(resources.files("auvplan").joinpath("data", "bathymetry")))


def sample_path(name: SampleName) -> Path:
    """The file of sample ``name``.

    Examples
    --------
    >>> sample_path("monterey").name
    'monterey_canyon_head_ncei_13arcsec.nc'
    """
    return samples_folder() / SAMPLE_FILES[name]


__all__ = ["SAMPLE_FILES", "SampleName", "sample_path", "samples_folder"]
