"""Wall time per pipeline stage for the demo and the 4-vehicle example mission.

Run as a script (``python benchmarks/bench_mission.py [demo] [four_vehicles]``) for a table
from one run; ``MissionSuite`` is the asv form (``time_*`` and ``track_*``).
"""

from __future__ import annotations

import sys
import time
import tomllib
from importlib import resources
from pathlib import Path

import numpy as np

from auvplan.mission.config import MissionConfig, load_mission, parse_mission
from auvplan.mission.pipeline import MissionResult, Stage, run_mission

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "missions"


def mission(name: str) -> MissionConfig:
    """The packaged demo or an example mission by file stem."""
    if name == "demo":
        text = resources.files("auvplan").joinpath("data/missions/demo.toml").read_text("utf-8")
        return parse_mission(tomllib.loads(text))
    return load_mission(EXAMPLES / f"{name}.toml")


class MissionSuite:
    """asv: the whole pipeline on each mission."""

    params = ("demo", "four_vehicles")
    param_names = ("mission",)
    timeout = 1800

    def setup(self, name: str) -> None:
        self.config = mission(name)
        run_mission(self.config)  # warm numba / CasADi caches

    def time_full_pipeline(self, name: str) -> None:  # noqa: ARG002
        run_mission(self.config)

    def track_pronto_iterations(self, name: str) -> int:  # noqa: ARG002
        plan = run_mission(self.config).plan
        assert plan is not None
        return plan.result.n_iter


def report(name: str) -> MissionResult:
    """Run one mission (after a warm-up of the compiled kernels) and print its stage times."""
    config = mission(name)
    run_mission(config, stage=Stage.DECONFLICT)  # warm-up of the compiled kernels
    started = time.perf_counter()
    result = run_mission(config)
    total = time.perf_counter() - started
    plan = result.plan
    assert plan is not None
    stages = "  ".join(f"{stage} {seconds:6.2f} s" for stage, seconds in result.timings.items())
    n_steps = 0 if result.deconfliction is None else result.deconfliction.time.size - 1
    print(
        f"{name:<14s} {len(config.vehicles)} vehicles, N = {n_steps} steps:  {stages}"
        f"  total {total:6.2f} s;  PRONTO {plan.result.status.name} in "
        f"{plan.result.n_iter} iterations, energy {np.sum(plan.energy) / 1e3:.1f} kJ"
    )
    return result


if __name__ == "__main__":
    for name in sys.argv[1:] or MissionSuite.params:
        report(name)
