"""The local frame as a pyproj CRS: metric and true-north against geodesics, CF round trip."""

from __future__ import annotations

import numpy as np
import pytest
from pyproj import CRS, Geod

from auvplan.terrain.projection import LocalProjection


def test_local_frame_is_metric_and_true_north_near_the_centre(rng: np.random.Generator) -> None:
    """Distances and azimuths from the centre match WGS 84 geodesics (10 km around it)."""
    projection = LocalProjection(38.7, -9.2)
    lat = 38.7 + rng.uniform(-0.09, 0.09, 200)
    lon = -9.2 + rng.uniform(-0.11, 0.11, 200)
    north, east = projection.to_local(lat, lon)
    azimuth, _, distance = Geod(ellps="WGS84").inv(np.full(200, -9.2), np.full(200, 38.7), lon, lat)
    np.testing.assert_allclose(np.hypot(north, east), distance, rtol=2e-6)
    # Meridian convergence grows as (lon - lon_0) sin(lat): below 0.07 deg here.
    bearing = np.degrees(np.arctan2(east, north))
    assert np.max(np.abs((bearing - azimuth + 180.0) % 360.0 - 180.0)) < 0.07


def test_crs_carries_the_origin_shift_and_round_trips_through_cf() -> None:
    projection = LocalProjection(36.8, -121.815).shifted(-1161.06, -933.63)
    cf = projection.crs.to_cf()
    assert cf["grid_mapping_name"] == "transverse_mercator"
    assert cf["scale_factor_at_central_meridian"] == 1.0
    assert (cf["false_northing"], cf["false_easting"]) == (1161.06, 933.63)
    assert cf["geographic_crs_name"] == "WGS 84"
    assert LocalProjection.from_crs(CRS.from_cf(cf)) == projection
    # The local coordinates are the CRS's own projected coordinates.
    north, east = projection.to_local(np.array([36.8]), np.array([-121.815]))
    assert (float(north[0]), float(east[0])) == pytest.approx((1161.06, 933.63), abs=1e-6)
    lat, lon = projection.to_geographic(north, east)
    assert (float(lat[0]), float(lon[0])) == pytest.approx((36.8, -121.815), abs=1e-12)


def test_shifted_moves_the_origin_only(rng: np.random.Generator) -> None:
    base = LocalProjection(-33.9, 18.4)
    shifted = base.shifted(250.0, -75.0)
    lat, lon = -33.9 + rng.uniform(-0.02, 0.02, 50), 18.4 + rng.uniform(-0.02, 0.02, 50)
    north, east = base.to_local(lat, lon)
    north_s, east_s = shifted.to_local(lat, lon)
    np.testing.assert_allclose(north_s, north - 250.0, atol=1e-8)
    np.testing.assert_allclose(east_s, east + 75.0, atol=1e-8)


@pytest.mark.parametrize(
    "crs",
    [
        "EPSG:32629",  # UTM: scale factor 0.9996
        "EPSG:31467",  # Gauss-Krüger zone 3 on DHDN: scale 1 but not WGS 84
        "EPSG:4326",  # geographic
        "+proj=tmerc +lat_0=1 +lon_0=10 +k=1 +ellps=GRS80 +towgs84=0,0,0 +units=m",
    ],
)
def test_other_crs_are_not_local_frames(crs: str) -> None:
    assert LocalProjection.from_crs(CRS(crs)) is None


def test_fields_are_the_values_the_crs_holds() -> None:
    """PROJ keeps 15 significant digits: the fields take them, so from_crs(p.crs) == p."""
    projection = LocalProjection(36.80000006172839123, -121.815000000000012, -1234.56789012345678)
    assert projection.lat_0 == 36.8000000617284
    assert LocalProjection.from_crs(projection.crs) == projection
