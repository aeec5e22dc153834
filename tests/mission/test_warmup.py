"""The first-run warm-up calls the optimiser's kernels with the argument types of a mission."""

from __future__ import annotations

import types

import numba

import auvplan
from auvplan.mission.config import parse_mission
from auvplan.mission.pipeline import run_mission
from auvplan.mission.warmup import ITERATIONS, warm_up, warm_up_missions
from auvplan.optimization import _kernel_cache, _kernels, constraints

MIXED = {
    "terrain": {"synthetic": True},
    "fleet": {"horizon_s": 900.0, "safety_radius_m": 5.0},
    "vehicle": [
        {"name": "a", "type": "medusa", "start": {"north": 20.0, "east": 100.0, "speed": 0.3},
         "goal": {"north": 300.0, "east": 100.0}},
        {"name": "b", "type": "remus100", "start": {"north": 20.0, "east": 300.0, "speed": 1.2},
         "goal": {"north": 300.0, "east": 300.0}},
        {"name": "c", "type": "medusa", "start": {"north": 20.0, "east": 500.0, "speed": 0.3},
         "goal": {"north": 300.0, "east": 500.0}},
    ],
    "current": {"north": 0.1, "east": 0.0},
    "solver": {"dt_s": 1.0, "compile": True},
}  # fmt: skip


def test_one_small_mission_per_vehicle_type_with_the_mission_settings() -> None:
    config = parse_mission(MIXED)
    small = warm_up_missions(config)
    assert [m.vehicles[0].type for m in small] == ["medusa", "remus100"]
    for mission in small:
        assert len(mission.vehicles) == 1
        restored = {"max_iter": config.solver.max_iter, "compile": True}
        assert mission.solver.model_copy(update=restored) == config.solver
        assert mission.solver.max_iter == ITERATIONS
        assert not mission.solver.compile
        assert mission.maps == config.maps
        assert mission.weights == config.weights
        assert mission.current is not None
    still = parse_mission({**MIXED, "current": None})
    assert all(mission.current is None for mission in warm_up_missions(still))


def _signatures() -> dict[str, int]:
    """Compiled signatures of every optimiser kernel loaded in this process."""
    modules = [_kernels, constraints, *_kernel_cache._LOADED.values()]
    return {
        f"{module.__name__}.{name}": len(value.signatures)
        for module in modules
        for name, value in vars(module).items()
        if isinstance(value, numba.core.registry.CPUDispatcher)
        and isinstance(module, types.ModuleType)
    }


def test_after_the_warm_up_the_mission_compiles_no_optimiser_kernel() -> None:
    config = auvplan.demo_mission()
    warm_up(config)
    warmed = _signatures()
    assert warmed
    assert sum(warmed.values()) > 10
    run_mission(  # on two threads, as `auvplan plan` on two cores
        config.model_copy(update={"solver": config.solver.model_copy(update={"max_iter": 3})}),
        jobs=2,
    )
    after = _signatures()
    grown = {name: count for name, count in after.items() if count > warmed.get(name, 0)}
    assert not grown, f"kernels the warm-up did not compile: {grown}"
