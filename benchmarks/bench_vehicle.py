"""Benchmarks and accuracy tables of the MEDUSA vehicle model.

Run once and print the tables::

    .venv/bin/python benchmarks/bench_vehicle.py

Also usable with asv (classes with ``setup``, ``time_*`` and ``track_*``).

1. The optimiser's inner loop (issue 3): one RK4 step of two stacked vehicles (16 states,
   4 inputs), its Jacobians ``F_x, F_u`` and the costate-weighted Hessians
   ``Σ_i λ_i ∇²F^i`` over 10,000 steps, through ``auvplan.optimization.discretization``
   when it exists (else a CasADi construction of the same quantities in this file).
2. RK4 on the optimiser's grid vs the adaptive reference (``solve_ivp`` DOP853, 1e-10) on a
   50 s manoeuvre through all four propeller quadrants.
3. Low-order propeller series: error table and effect on thrust, torque and steady power.
4. Effect of the smoothing constants at bollard and at cruise.
"""

from __future__ import annotations

import importlib.util
import sys
import time
from collections.abc import Callable

import casadi as ca
import numpy as np

from auvplan._typing import FloatArray
from auvplan.io.vehicles import load_vehicle
from auvplan.vehicle import VehicleModel, build_vehicle_model, vessel_dynamics
from auvplan.vehicle.approximation import approximation_error_table, smoothing_effect
from auvplan.vehicle.simulate import rk4_simulate, simulate_adaptive

N_STEPS = 10_000
DT = 0.5  # s, the optimiser's default grid
N_VEHICLES = 2

# 50 s manoeuvre on a 0.5 s zero-order-hold grid (same as tests/vehicle/test_vehicle_simulate.py)
MANOEUVRE = (
    (1, (0.8, 0.8)),
    (20, (0.0, 0.0)),
    (1, (0.3, -0.3)),
    (20, (0.0, 0.0)),
    (1, (-0.3, 0.3)),
    (15, (0.0, 0.0)),
    (2, (-0.8, -0.8)),
    (20, (0.0, 0.0)),
    (1, (0.8, 0.8)),
    (19, (0.0, 0.0)),
)


def fleet_functions(model: VehicleModel, n_vehicles: int) -> tuple[ca.Function, ca.Function]:
    """Block-diagonal fleet dynamics ``f(x, u, p)`` and summed power ``l(x, u, p)``."""
    x = ca.SX.sym("x", model.n_x * n_vehicles)
    u = ca.SX.sym("u", model.n_u * n_vehicles)
    p = ca.SX.sym("p", 0)
    rates, powers = [], []
    for i in range(n_vehicles):
        xi = x[i * model.n_x : (i + 1) * model.n_x]
        ui = u[i * model.n_u : (i + 1) * model.n_u]
        rates.append(model.dynamics(xi, ui))
        powers.append(model.power(xi, ui))
    return (
        ca.Function("f", [x, u, p], [ca.vertcat(*rates)]),
        ca.Function("l", [x, u, p], [sum(powers[1:], powers[0])]),
    )


def random_grid(
    n_vehicles: int, n_steps: int, rng: np.random.Generator
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Random states around cruise in all quadrants, random inputs and costates."""
    one = np.column_stack(
        [
            rng.uniform(-200, 200, (n_steps, 2)),
            rng.uniform(-np.pi, np.pi, n_steps),
            rng.uniform(-0.5, 1.5, n_steps),
            rng.uniform(-0.2, 0.2, n_steps),
            rng.uniform(-0.5, 0.5, n_steps),
            rng.uniform(-75, 75, (n_steps, 2)),
        ]
    )
    states = np.hstack([np.roll(one, 7 * i, axis=0) for i in range(n_vehicles)])
    inputs = rng.uniform(-1, 1, (n_steps, 2 * n_vehicles))
    costates = rng.normal(size=states.shape)
    return states, inputs, costates


class _OwnDiscretization:
    """Fallback (and JIT variant): the same RK4 step, Jacobians and λ-weighted Hessians."""

    def __init__(self, f: ca.Function, dt: float, n_steps: int, *, jit: bool = False) -> None:
        n_x, n_u = f.size1_in(0), f.size1_in(1)
        x, u, lam = ca.SX.sym("x", n_x), ca.SX.sym("u", n_u), ca.SX.sym("lam", n_x)
        p = ca.SX.sym("p", 0)
        k1 = f(x, u, p)
        k2 = f(x + dt / 2 * k1, u, p)
        k3 = f(x + dt / 2 * k2, u, p)
        k4 = f(x + dt * k3, u, p)
        x_next = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        w = ca.vertcat(x, u)
        hessian, _ = ca.hessian(ca.dot(lam, x_next), w)
        options = (
            {"jit": True, "compiler": "shell", "jit_options": {"flags": ["-O1"]}} if jit else {}
        )
        step = ca.Function("F", [x, u], [x_next], options)
        jac = ca.Function("J", [x, u], [ca.jacobian(x_next, x), ca.jacobian(x_next, u)], options)
        hess = ca.Function("H", [x, u, lam], [hessian], options)
        self.hessian_instructions = ca.Function("H", [x, u, lam], [hessian]).n_instructions()
        self.step_map = step.map(n_steps)
        self.jac_map = jac.map(n_steps)
        self.hess_map = hess.map(n_steps)

    def step(self, states: FloatArray, inputs: FloatArray) -> object:
        return self.step_map(states.T, inputs.T)

    def jacobians(self, states: FloatArray, inputs: FloatArray) -> object:
        return self.jac_map(states.T, inputs.T)

    def weighted_hessians(self, states: FloatArray, inputs: FloatArray, lam: FloatArray) -> object:
        return self.hess_map(states.T, inputs.T, lam.T)


class InnerLoopSuite:
    """RK4 step, Jacobians and λ-weighted Hessians: 2 vehicles x 10,000 steps."""

    params = ((30, 10), ("discretization", "jit"))
    param_names = ("propeller_order", "backend")
    timeout = 900

    def setup(self, propeller_order: int, backend: str) -> None:
        model = build_vehicle_model(load_vehicle("medusa"), propeller_order=propeller_order)
        dynamics, running_cost = fleet_functions(model, N_VEHICLES)
        self.states, self.inputs, self.costates = random_grid(
            N_VEHICLES, N_STEPS, np.random.default_rng(3)
        )
        self.parameters = np.zeros((N_STEPS, 0))
        start = time.perf_counter()
        have_discretization = (
            importlib.util.find_spec("auvplan.optimization.discretization") is not None
        )
        if backend == "discretization" and have_discretization:
            from auvplan.optimization.discretization import discretize_rk4

            discrete = discretize_rk4(dynamics, running_cost, DT)
            self.backend = "auvplan.optimization.discretization (CasADi VM)"
            self._evaluate = {
                "step": lambda: discrete.step(self.states, self.inputs, self.parameters),
                "jacobians": lambda: discrete.jacobians(self.states, self.inputs, self.parameters),
                "weighted_hessians": lambda: discrete.weighted_hessians(
                    self.states, self.inputs, self.parameters, self.costates
                ),
            }
        else:
            jit = backend == "jit"
            own = _OwnDiscretization(dynamics, DT, N_STEPS, jit=jit)
            self.backend = "CasADi JIT, gcc -O1" if jit else "CasADi VM (benchmark's own)"
            self._evaluate = {
                "step": lambda: own.step(self.states, self.inputs),
                "jacobians": lambda: own.jacobians(self.states, self.inputs),
                "weighted_hessians": lambda: own.weighted_hessians(
                    self.states, self.inputs, self.costates
                ),
            }
            if jit:  # compile now, so that the build time includes it
                for function in self._evaluate.values():
                    function()
        self.build_seconds = time.perf_counter() - start

    def time_step(self, propeller_order: int, backend: str) -> None:  # noqa: ARG002 (asv parameters)
        self._evaluate["step"]()

    def time_jacobians(self, propeller_order: int, backend: str) -> None:  # noqa: ARG002 (asv parameters)
        self._evaluate["jacobians"]()

    def time_weighted_hessians(self, propeller_order: int, backend: str) -> None:  # noqa: ARG002 (asv parameters)
        self._evaluate["weighted_hessians"]()

    def track_all_finite(self, propeller_order: int, backend: str) -> int:  # noqa: ARG002 (asv parameters)
        arrays: list[object] = []
        for name in ("step", "jacobians", "weighted_hessians"):
            value = self._evaluate[name]()
            arrays.extend(value if isinstance(value, tuple | list) else [value])
        return int(all(np.all(np.isfinite(np.asarray(array, dtype=float))) for array in arrays))


class SimulationSuite:
    """RK4 rollout vs adaptive reference on the manoeuvre."""

    def setup(self) -> None:
        self.model = build_vehicle_model(load_vehicle("medusa"))
        self.inputs = np.vstack([np.tile(c, (n, 1)) for n, c in MANOEUVRE])
        self.t_end = self.inputs.shape[0] * DT

    def time_rk4_rollout_dt_0_1(self) -> None:
        rk4_simulate(self.model, np.zeros(8), np.repeat(self.inputs, 5, axis=0), DT / 5)

    def time_adaptive_reference(self) -> None:
        simulate_adaptive(self.model, np.zeros(8), self.inputs, (0.0, self.t_end))

    def time_vessel_dynamics_10000(self) -> None:
        states, inputs, _ = random_grid(1, N_STEPS, np.random.default_rng(1))
        vessel_dynamics(states, inputs, self.model)

    def track_position_error_dt_0_5(self) -> float:
        return rk4_position_errors(self.model, self.inputs)[DT]


def rk4_position_errors(model: VehicleModel, inputs: FloatArray) -> dict[float, float]:
    """Max horizontal position error [m] of RK4 at dt = 0.5, 0.1 s vs the adaptive reference."""
    t_end = inputs.shape[0] * DT
    reference = simulate_adaptive(model, np.zeros(8), inputs, (0.0, t_end))
    errors = {}
    for substeps in (1, 5):
        states = rk4_simulate(
            model, np.zeros(8), np.repeat(inputs, substeps, axis=0), DT / substeps
        )
        grid = states[::substeps]
        errors[DT / substeps] = float(np.max(np.hypot(*(grid[:, :2] - reference.states[:, :2]).T)))
    return errors


def _best_of(function: Callable[[], object], repeats: int = 3) -> float:
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - start)
    return float(best)


def main() -> None:
    with_jit = "--jit" in sys.argv[1:]
    print(
        f"Inner loop: {N_VEHICLES} MEDUSA vehicles stacked (16 states, 4 inputs), "
        f"{N_STEPS} RK4 steps of {DT} s; times for all {N_STEPS} steps (best of 3)"
    )
    print(
        f"  {'order':>5}  {'backend':<48}{'build [s]':>10}{'F [s]':>8}{'F_x,F_u [s]':>12}"
        f"{'Σλ∇²F [s]':>11}{'finite':>7}"
    )
    cases = [(30, "discretization"), (10, "discretization")]
    if with_jit:
        cases += [(30, "jit"), (10, "jit")]
    for order, backend in cases:
        suite = InnerLoopSuite()
        suite.setup(order, backend)
        times = []
        for method in (suite.time_step, suite.time_jacobians, suite.time_weighted_hessians):
            method(order, backend)  # first call builds the mapped function
            times.append(_best_of(lambda m=method, o=order, b=backend: m(o, b)))
        finite = bool(suite.track_all_finite(order, backend))
        print(
            f"  {order:>5}  {suite.backend:<48}{suite.build_seconds:>10.1f}{times[0]:>8.2f}"
            f"{times[1]:>12.2f}{times[2]:>11.2f}{finite!s:>7}"
        )
    if not with_jit:
        print("  (run with --jit to add CasADi's JIT-compiled variant; compiling takes minutes)")

    sim = SimulationSuite()
    sim.setup()
    errors = rk4_position_errors(sim.model, sim.inputs)
    print("\nRK4 vs solve_ivp (DOP853, rtol = atol = 1e-10), 50 s manoeuvre, all quadrants")
    for dt, error in errors.items():
        print(f"  dt = {dt:.1f} s: max position error {error:.2e} m")
    print(f"  adaptive reference: {_best_of(sim.time_adaptive_reference, 1):.2f} s")
    print(f"  RK4 rollout, 500 steps: {_best_of(sim.time_rk4_rollout_dt_0_1):.4f} s")
    print(f"  vessel_dynamics on 10,000 states: {_best_of(sim.time_vessel_dynamics_10000):.4f} s")

    params = sim.model.params
    print("\nLow-order propeller series vs full order-30 series (B4-70 P/D 1.4)")
    print(
        f"  {'K':>3} {'rms dCT*':>9} {'max dCT*':>9} {'rms dCQ*':>9} {'max dCQ*':>9}"
        f" {'T_bollard':>10} {'Q_bollard':>10} {'P(0.5)':>8} {'P(1.0)':>8}"
    )
    for row in approximation_error_table(params):
        p05, p10 = row.propulsion_power
        print(
            f"  {row.order:>3} {row.rms_thrust_coefficient:>9.4f}"
            f" {row.max_thrust_coefficient:>9.4f} {row.rms_torque_coefficient:>9.4f}"
            f" {row.max_torque_coefficient:>9.4f}"
            f" {row.bollard_thrust:>+10.2%} {row.bollard_torque:>+10.2%}"
            f" {p05:>+8.2%} {p10:>+8.2%}"
        )
    print("  (P = steady electrical propulsion power without hotel load; relative changes)")

    print(
        f"\nSmoothing (eps_V = {params.eps_inflow} m/s, eps_|u| = {params.eps_abs_speed} m/s, "
        f"eps_|r| = {params.eps_abs_rate} rad/s, eps_sgn(n) = {params.eps_sign_n} rev/s) "
        "vs eps = 1e-9"
    )
    print(f"  {'condition':<16}{'thrust':>12}{'torque':>12}{'power':>12}")
    for effect in smoothing_effect(params):
        print(
            f"  {effect.condition:<16}{effect.thrust:>12.2e}{effect.torque:>12.2e}"
            f"{effect.power:>12.2e}"
        )


if __name__ == "__main__":
    main()
