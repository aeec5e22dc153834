"""
The MEDUSA vehicle model
========================

The vehicle model that the optimiser uses (SPEC §3-4): planar 3-DOF dynamics with DSOR's
published MEDUSA hydrodynamics, two four-quadrant Wageningen B4-70 P/D 1.4 propellers
(Roddy et al. 2006), thruster input dynamics ``ṅ = w_c tanh(c)`` and DC motors whose
electrical power, plus a hotel load, is the energy cost.

This example loads the packaged vehicle type, prints its headline numbers (the same as
``auvplan vehicle``), compares the low-order propeller approximations with the full series,
simulates a short manoeuvre with RK4, and draws the validation figure.
"""

from __future__ import annotations

import numpy as np

from auvplan.io.vehicles import load_vehicle
from auvplan.vehicle import build_vehicle_model, energy
from auvplan.vehicle.approximation import approximation_error_table
from auvplan.vehicle.simulate import rk4_simulate
from auvplan.vehicle.trim import vehicle_characteristics
from auvplan.viz.vehicle import plot_vehicle_validation

params = load_vehicle("medusa")
model = build_vehicle_model(params)

# %%
# Headline numbers: bollard pull, top speed, energy-optimal cruise, steady power.
for name, value in vehicle_characteristics(model).to_dict().items():
    print(f"{name:<26} {value}")

# %%
# Low-order propeller series (truncated Fourier series are least-squares optimal).
for row in approximation_error_table(params, (1, 3, 10, 20)):
    print(
        f"order {row.order:>2}: rms dC_T* = {row.rms_thrust_coefficient:.4f}, "
        f"bollard thrust {row.bollard_thrust:+.1%}, power at 1 m/s {row.propulsion_power[1]:+.1%}"
    )

# %%
# A manoeuvre: accelerate, turn to starboard (port propeller faster), straighten.
dt = 0.5
inputs = np.zeros((80, 2))
inputs[0] = (0.35, 0.35)  # both propellers to ~25 rev/s (0.5 m/s cruise) in 0.5 s
inputs[20] = (0.03, -0.03)  # port 4.5 rev/s faster: r > 0, the bow turns to starboard
inputs[40] = (-0.03, 0.03)
states = rk4_simulate(model, np.zeros(8), inputs, dt)
time = dt * np.arange(states.shape[0])
padded = np.vstack([inputs, inputs[-1:]])
north, east, psi = states[-1, :3]
print(f"final position north {north:.1f} m, east {east:.1f} m, heading {np.degrees(psi):.0f} deg")
print(f"electrical energy {energy(time, states, padded, model) / 1e3:.2f} kJ over {time[-1]:.0f} s")

# %%
# The validation figure: C_T*, C_Q* over the four quadrants (full vs low order), the
# steady speed-power curve, and a turning circle.
figure = plot_vehicle_validation(model)
