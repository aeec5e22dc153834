"""A vehicle type's headline characteristics, and its validation figure.

:func:`describe_vehicle` is what ``auvplan vehicle`` does: load a vehicle type
(:func:`auvplan.io.vehicles.load_vehicle`), build its model, compute its characteristics
(:func:`auvplan.vehicle.trim.vehicle_characteristics`) and, if asked, write the figure of
:func:`auvplan.viz.vehicle.plot_vehicle_validation` all-or-nothing
(:func:`~auvplan.io.output.staged_output_file`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Final

from auvplan.io.output import staged_output_file
from auvplan.io.vehicles import load_vehicle
from auvplan.io.writing import writing
from auvplan.vehicle.dynamics import build_vehicle_model
from auvplan.vehicle.params import Propeller
from auvplan.vehicle.trim import VehicleCharacteristics, vehicle_characteristics

#: Resolution of the validation figure's raster formats [dots per inch].
FIGURE_DPI: Final = 120


@dataclass(frozen=True)
class VehicleDescription:
    """What :func:`describe_vehicle` found: the numbers, the propeller, the figure written."""

    characteristics: VehicleCharacteristics
    """Headline numbers (SI units, propeller speeds in rev/s)."""
    propeller: Propeller
    """The vehicle's propeller model (a Fourier series or linear in the advance ratio)."""
    figure: Path | None
    """The validation figure written, or None."""


def describe_vehicle(
    vehicle: str | Path, *, propeller_order: int | None = None, figure: Path | None = None
) -> VehicleDescription:
    """The characteristics of a vehicle type, and its validation figure if ``figure`` is given.

    Parameters
    ----------
    vehicle : str or Path
        A packaged vehicle type (``"medusa"``, ``"remus100"``) or a vehicle TOML file.
    propeller_order : int, optional
        Harmonics of the propeller series (default: the file's order, else all).
    figure : Path, optional
        Where to write the validation figure; its extension gives the format.

    Returns
    -------
    VehicleDescription

    Raises
    ------
    InputError, DataFormatError
        For an unknown vehicle type, a malformed vehicle file or an order out of range.
    """
    model = build_vehicle_model(load_vehicle(vehicle), propeller_order=propeller_order)
    characteristics = vehicle_characteristics(model)
    if figure is not None:
        from auvplan.viz.vehicle import plot_vehicle_validation  # matplotlib: only when asked

        drawn = plot_vehicle_validation(model)
        with staged_output_file(figure) as staging, writing(staging):
            drawn.savefig(staging, dpi=FIGURE_DPI)
    return VehicleDescription(characteristics, model.vehicle.propeller, figure)
