"""``auvplan maps``: outputs on success; one stderr line and nothing written on bad input."""

from __future__ import annotations

from pathlib import Path

import matplotlib.colors
import numpy as np
import pytest

from auvplan.cli.main import main
from auvplan.io.maps_file import read_maps_netcdf

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def test_synthetic_bank_writes_maps_nc_and_png(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    code = main(
        ["maps", "synthetic", "--block", "3", "2", "--omega", "2", "--w", "5", "-o", str(out)]
    )
    assert code == 0
    assert sorted(p.name for p in out.iterdir()) == ["maps.nc", "maps.png"]
    assert (out / "maps.png").read_bytes()[:8] == PNG_MAGIC
    maps = read_maps_netcdf(out / "maps.nc")
    assert maps.parameters.block == (3, 2)
    assert maps.bathymetry.depth.shape == (101, 201)
    assert np.nanmin(maps.shifted_cost) >= 2.0
    assert np.nanmax(maps.shifted_cost) <= 7.0
    printed = capsys.readouterr()
    assert "101 x 201" in printed.out
    assert printed.err == ""


def test_quiet_prints_nothing(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["-q", "maps", "synthetic", "--seed", "3", "-o", str(tmp_path / "q")]) == 0
    assert capsys.readouterr().out == ""
    assert (tmp_path / "q" / "maps.nc").is_file()


def test_real_grid_with_lat_lon_window(
    tmp_path: Path, bathymetry_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "monterey"
    code = main(
        [
            "-q",
            "maps",
            str(bathymetry_dir / "monterey_canyon_head_ncei_13arcsec.nc"),
            "--window-lat", "36.79361", "36.79713",
            "--window-lon", "-121.81472", "-121.80583",
            "-o", str(out),
        ]
    )  # fmt: skip
    assert code == 0
    maps = read_maps_netcdf(out / "maps.nc")
    assert maps.bathymetry.projection is not None
    assert abs(maps.bathymetry.depth.shape[1] - 97) <= 1


def _garbage(tmp_path: Path) -> str:
    path = tmp_path / "garbage.nc"
    path.write_bytes(b"CDF\x01 this is not really netcdf" * 10)
    return str(path)


def _text(tmp_path: Path) -> str:
    path = tmp_path / "notes.txt"
    path.write_text("just some words\n")
    return str(path)


BAD_INPUTS = {
    "missing file": lambda tmp: [str(tmp / "missing.nc")],
    "garbage netcdf": lambda tmp: [_garbage(tmp)],
    "text file": lambda tmp: [_text(tmp)],
    "directory": lambda tmp: [str(tmp)],
    "window outside": lambda tmp: ["synthetic", "--window-north", "5000", "6000"],
    "window east outside": lambda tmp: ["synthetic", "--window-east", "-90", "-10"],
    "lat window on synthetic": lambda tmp: ["synthetic", "--window-lat", "1", "2"],
    "block zero": lambda tmp: ["synthetic", "--block", "0", "2"],
    "block too big": lambda tmp: ["synthetic", "--block", "500", "2"],
    "omega zero": lambda tmp: ["synthetic", "--omega", "0"],
    "omega negative": lambda tmp: ["synthetic", "--omega", "-1"],
    "negative weight": lambda tmp: ["synthetic", "--w", "-1"],
    "exponent zero": lambda tmp: ["synthetic", "--s", "0"],
}


@pytest.mark.parametrize("case", sorted(BAD_INPUTS))
def test_bad_input_one_line_and_nothing_written(
    case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    code = main(["maps", *BAD_INPUTS[case](tmp_path), "-o", str(out)])
    assert code != 0
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0].startswith("auvplan: error:")
    assert captured.out == ""
    assert not out.exists()
    assert not list(tmp_path.glob(".out.*"))  # no staging leftovers


def test_bad_input_on_a_real_grid(
    tmp_path: Path, bathymetry_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    path = bathymetry_dir / "south_lisbon_shelf_emodnet_dtm.nc"
    code = main(["maps", str(path), "--window-lat", "10", "11", "-o", str(out)])
    assert code != 0
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1
    assert path.name in lines[0]
    assert not out.exists()


def test_figure_has_four_map_panels_with_units_and_land_colour() -> None:
    from auvplan.terrain import BathymetryGrid, compute_terrain_maps, synthetic_bank
    from auvplan.viz.maps import LAND_COLOR, plot_terrain_maps

    bank = synthetic_bank()
    depth = bank.depth.copy()
    depth[:10, :20] = np.nan  # land in the south-west corner
    maps = compute_terrain_maps(BathymetryGrid(depth, bank.geometry, name="bank with land"))
    figure = plot_terrain_maps(maps)
    panels = [ax for ax in figure.axes if ax.get_images()]
    assert len(panels) == 4
    labels = {ax.get_ylabel() for ax in figure.axes if ax not in panels}
    assert {"depth [m]", "information [-]", "excitation [-]", "cost [-]"} <= labels
    for ax in panels:
        assert ax.get_aspect() == 1.0
        assert ax.get_xlim() == panels[0].get_xlim()  # shared axes
        image = ax.get_images()[0]
        assert np.ma.is_masked(image.get_array())
        bad = image.get_cmap().get_bad()
        assert np.allclose(bad[:3], matplotlib.colors.to_rgb(LAND_COLOR))
