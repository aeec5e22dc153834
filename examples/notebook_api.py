# %% [markdown]
# # auvplan from a notebook
#
# Plan the paper's scenario (two MEDUSAs crossing the eastern rim of the synthetic volcanic
# bank), look at the plan as an xarray Dataset and a pandas DataFrame, draw it, save the
# output folder and open it again, with nothing but `import auvplan`.
#
# Run it as a script (`python examples/notebook_api.py`) or cell by cell (`# %%`) in
# VS Code, Spyder or Jupytext. The mission is the demo's, on a 1 s solver grid instead of
# 0.5 s so that it runs in seconds.

# %%
from pathlib import Path

import auvplan

mission = {
    "terrain": {"synthetic": True, "seed": 7},
    "fleet": {"horizon_s": 600.0, "safety_radius_m": 5.0},
    "vehicle": [
        {
            "name": "blue",
            "start": {"north": 10.0, "east": 400.0, "heading_deg": 0.0, "speed": 0.5},
            "goal": {"north": 380.0, "east": 420.0, "heading_deg": 0.0},
        },
        {
            "name": "green",
            "start": {"north": 10.0, "east": 440.0, "heading_deg": 0.0, "speed": 0.5},
            "goal": {"north": 380.0, "east": 450.0, "heading_deg": 0.0},
        },
    ],
    "solver": {"dt_s": 1.0},
}
plan = auvplan.plan(mission)  # also: auvplan.plan("mission.toml"), auvplan.demo_mission()
print(plan)

# %% [markdown]
# The summary holds every number needed to verify the plan (it is `summary.json`).

# %%
optimization = plan.summary["optimization"]
print(f"plan {plan.status}: {optimization['verdict']}")
for name, vehicle in optimization["vehicles"].items():
    closest = min(vehicle["min_separation_m"].values())
    print(
        f"{name:>6s}: {vehicle['energy_J'] / 1e3:6.1f} kJ, "
        f"terrain information {vehicle['mean_terrain_information']:.3f}, "
        f"closest approach {closest:.1f} m"
    )

# %% [markdown]
# The trajectories as the CF trajectory dataset of `trajectories.nc` ...

# %%
dataset = plan.to_xarray()
print(dataset[["north", "east", "u", "power"]])

# %% [markdown]
# ... and in long format, one row per vehicle and time step.

# %%
frame = plan.to_dataframe()
print(frame.groupby("vehicle")[["u", "power"]].mean())

# %% [markdown]
# The mission figure (paper Fig. 6): pre-planned paths dashed, optimised trajectories solid,
# one colour per vehicle.

# %%
figure = plan.plot()
Path("out").mkdir(exist_ok=True)
figure.savefig("out/notebook_api_paths.png", dpi=100)
figure  # noqa: B018  (the cell's value: a notebook shows the figure, no %matplotlib needed)

# %% [markdown]
# The output folder of `auvplan plan` (data, figures as SVG, `report.html`), opened again.

# %%
output = Path("out/notebook_api")
files = plan.save(output, figure_format="svg")
print("wrote", ", ".join(path.name for path in files))
reopened = auvplan.load(output)
assert reopened.to_xarray().equals(dataset)
print(reopened)
