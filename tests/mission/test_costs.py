"""Named cost terms and constraint slacks of a solved fleet problem (the golden mission)."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from auvplan.io.vehicles import load_vehicle
from auvplan.mission.assembly import separation_margin
from auvplan.mission.costs import constraint_slack, cost_breakdown
from auvplan.mission.fleet import COST_TERMS, RUNNING_TERMS, StageWeights, vehicle_stage_functions
from auvplan.optimization.integration import rk4_step
from auvplan.record.labels import Pair
from auvplan.vehicle import build_vehicle_model, positions


def test_the_terms_add_up_to_the_optimisers_running_cost(golden_solved: tuple) -> None:
    """Independently: the RK4 quadrature of the stacked rate l(x, u, p) over every step."""
    _, result, assembled = golden_solved
    problem, trajectory = assembled.problem, result.plan.result.trajectory
    costs = cost_breakdown(problem, assembled.functions, trajectory)
    x = ca.SX.sym("x", problem.initial_state.size)
    u = ca.SX.sym("u", trajectory.inputs.shape[1])
    p = ca.SX.sym("p", problem.stage_parameters.shape[1])
    _, stage_cost = rk4_step(
        problem.dynamics, problem.running_cost, x, u, p, problem.dt, problem.n_substeps
    )
    steps = ca.Function("L", [x, u, p], [stage_cost]).map(trajectory.inputs.shape[0])
    per_step = steps(trajectory.states[:-1].T, trajectory.inputs.T, problem.stage_parameters.T)
    running = float(np.sum(np.asarray(per_step)))
    terms = costs.totals()
    assert list(terms) == list(COST_TERMS)
    assert sum(terms[term] for term in RUNNING_TERMS) == pytest.approx(running, rel=1e-10)
    assert terms["terminal"] == pytest.approx(
        float(assembled.functions.terminal_cost(trajectory.states[-1])), rel=1e-12
    )
    # the energy term is w_E times the energy (trapezoid of the power: a different quadrature)
    energy_weight = golden_solved[0].weights.energy
    np.testing.assert_allclose(
        costs.running["energy"], energy_weight * result.plan.energy, rtol=2e-3
    )
    assert all(value >= 0.0 for value in costs.running["tracking"])
    assert terms["information"] <= 0.0  # a reward


def test_the_summary_reports_the_terms(golden_solved: tuple) -> None:
    _, result, _ = golden_solved
    totals = result.plan.costs.totals()
    per_vehicle = result.plan.costs.running
    assert set(totals) == set(COST_TERMS)
    for term in RUNNING_TERMS:
        assert float(np.sum(per_vehicle[term])) == pytest.approx(totals[term])


def test_collision_slack_is_the_normalised_separation(golden_solved: tuple) -> None:
    """The collision row of "blue / green" is min_k ‖p_b − p_g‖²/(2 r_c + margin)² − 1."""
    config, result, assembled = golden_solved
    slack = constraint_slack(assembled.problem, assembled.functions, result.plan.result.trajectory)
    layout = assembled.functions.layout
    blue, green = (positions(layout.models[i], result.plan.states[i]) for i in range(2))
    (collision,) = [c for c in assembled.functions.constraints if c.name == "collision"]
    assert collision.labels == (Pair("blue", "green"),)
    radius = config.fleet.safety_radius
    margin = separation_margin(
        radius, result.deconfliction.dt, result.deconfliction.desired_states, layout
    )
    distance_sq = np.sum((blue - green) ** 2, axis=1)[:-1]  # the nodes where it is imposed
    expected = float(np.min(distance_sq)) / (2 * radius + margin) ** 2 - 1.0
    assert slack["collision"]["blue / green"] == pytest.approx(expected, rel=1e-9, abs=1e-12)
    assert slack["collision"]["blue / green"] >= 0.0  # a converged plan keeps its constraints
    assert set(slack["state_limits"]) == {
        str(Pair(name, state))
        for name, model in zip(layout.names, layout.models, strict=True)
        for state, _ in model.state_limits
    }


def test_stage_weights_own_the_layout_of_w() -> None:
    """Numbers packed by StageWeights.vector read back by name from the symbol give l."""
    model = build_vehicle_model(load_vehicle("medusa"))
    weights = StageWeights(energy=2.0, tracking=3.0, input=0.5, per_state=(1.0,) * model.n_x)
    _, rate = vehicle_stage_functions(model)
    x = np.linspace(0.1, 0.8, model.n_x)
    c = np.linspace(-0.2, 0.3, model.n_u)
    desired = np.zeros(model.n_x)
    value = float(rate(x, c, desired, weights.vector()))
    power = float(model.power(x, c))
    expected = 2.0 * power + 0.5 * 3.0 * float(np.dot(x, x)) + 0.5 * 0.5 * float(np.dot(c, c))
    assert value == pytest.approx(expected, rel=1e-12)
