"""Ocean-model current files (NetCDF) as a :class:`~auvplan.ocean.GriddedCurrent`, as published.

========================  ==========================  ===================================
provider                  velocity variables           grid
========================  ==========================  ===================================
CF (any)                  ``eastward_/northward_sea_   1-D lat/lon, projected (CF
                          water_velocity``             ``grid_mapping``) or local axes
Copernicus Marine         ``uo``, ``vo``               time, depth, latitude, longitude
HYCOM                     ``water_u``, ``water_v``     time, depth, lat, lon (0..360);
                                                       int16 scale/offset/fill
NOAA RTOFS                ``u_velocity``/``v_velocity``  MT, Layer/Depth, Y, X with 2-D
                          (2-D), ``u``/``v`` (3-D)     ``Latitude``/``Longitude``
ROMS / CROCO              ``u``, ``v`` (C-grid)        ocean_time, s_rho, eta_u/xi_u,
                                                       eta_v/xi_v; ``lat_rho``, ``angle``
========================  ==========================  ===================================

The current is taken at the mission depth (linear between the bracketing levels), over the
mission's time slices (cftime, the file's calendar) and over the map: on the file's own
lattice when its axes are evenly spaced, else resampled onto a regular local grid
(:mod:`auvplan.io.currents.reader` lists the steps).
"""

from auvplan.io.currents.reader import read_current
from auvplan.io.currents.variables import CURRENT_NAMES

__all__ = ["CURRENT_NAMES", "read_current"]
