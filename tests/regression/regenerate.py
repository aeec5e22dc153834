"""Regenerate the golden files of ``tests/regression`` (run only when numbers must change).

Usage: ``python tests/regression/regenerate.py``. A commit that changes a golden file says why
the numbers changed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from auvplan.mission import load_mission, run_mission

HERE = Path(__file__).parent


def golden_arrays(mission: Path) -> dict[str, np.ndarray]:
    """The arrays the golden test compares: desired and optimised trajectories, energy, cost."""
    result = run_mission(load_mission(mission))
    assert result.plan is not None
    assert result.deconfliction is not None
    plan = result.plan
    return {
        "desired": np.stack(result.deconfliction.desired_states),
        "states": plan.states,
        "inputs": plan.inputs,
        "energy": plan.energy,
        "cost": np.array(plan.result.cost),
        "n_iter": np.array(plan.result.n_iter),
    }


if __name__ == "__main__":
    np.savez(HERE / "golden_mission.npz", **golden_arrays(HERE / "golden_mission.toml"))
