"""Energy map: the stacked-design analytic path against the per-design one, and the map against the optimiser."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lengths_helper import CRANE, feasible_lengths
from test_study_small import small_study, write_study
from test_sweep import TINY

from hiab_sim.cli import main
from hiab_sim.crane.description import LinkLengths
from hiab_sim.dynamics.analytic_batch import batched_inverse_dynamics
from hiab_sim.dynamics.analytic_id import analytic_inverse_dynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.errors import HiabSimError
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.run import run_study
from hiab_sim.study.spec.study_file import load_study
from hiab_sim.sweep.energy_map import (
    VARIABLES,
    energy_map,
    evaluate_designs,
    optimum_design,
    start_design,
)

UNIT = st.lists(st.floats(0.0, 1.0), min_size=6, max_size=6)


@settings(max_examples=15, deadline=None)
@given(designs=st.lists(UNIT, min_size=1, max_size=4), seed=st.integers(0, 1000))
def test_stacked_designs_match_the_per_design_path(designs: list[list[float]], seed: int) -> None:
    """Forces, rates and strokes of D stacked designs equal D calls of the per-design analytic path."""
    rng = np.random.default_rng(seed)
    T = 12
    q = np.column_stack([rng.uniform(0.4, 0.8, T), rng.uniform(-1.5, -1.1, T), rng.uniform(0.2, 0.6, T)])
    dq, ddq = rng.normal(0.0, 0.2, (T, 3)), rng.normal(0.0, 0.5, (T, 3))
    tcp = np.array([30.0, -1500.0, 0.0])
    lengths = [feasible_lengths(np.array(u)) for u in designs]
    stacked = batched_inverse_dynamics(CRANE, np.array([x.as_array() for x in lengths]), q, dq, ddq, tcp)
    for d, x in enumerate(lengths):
        one = analytic_inverse_dynamics(CRANE, x, JointSamples(q, dq, ddq), tcp_force=tcp)
        for got, want in zip(stacked, (one.force, one.velocity, one.acceleration, one.stroke), strict=True):
            np.testing.assert_allclose(got[d], want, rtol=1e-12, atol=1e-9)


@pytest.fixture(scope="module")
def optimum(tmp_path_factory: pytest.TempPathFactory) -> tuple[TaskProblem, Path, dict]:  # type: ignore[type-arg]
    """The tiny study optimised on the analytic path: its problem, result folder and result."""
    folder = tmp_path_factory.mktemp("map")
    study = load_study(write_study(folder, small_study(**TINY)))
    output = run_study(study, folder / "run", progress=None, figures=False)
    return TaskProblem(study, id_path="analytic"), output.folder, output.result


def test_map_at_the_optimum_equals_the_optimisers_objective(optimum: tuple) -> None:  # type: ignore[type-arg]
    """At the optimum's lengths on its trajectory the map's cost and net energy are the run's own values."""
    problem, folder, result = optimum
    base = optimum_design(folder)
    at = evaluate_designs(problem, base, base.xi[None])
    assert at.cost[0] == pytest.approx(result.optimal.collocation_cost_W2s, rel=1e-10)
    assert at.net_energy[0] == pytest.approx(result.optimal.net_electrical_energy_J, rel=1e-10)
    assert at.objective[0] == pytest.approx(result.history[-1].scaled_cost, rel=1e-10)
    assert at.battery_energy[0] == pytest.approx(result.energy.optimal.battery_energy_J, rel=1e-10)
    assert at.feasible[0]


def test_map_of_a_battery_energy_study_is_its_objective(tmp_path: Path) -> None:
    """With ``objective: battery_energy`` the map's objective at the optimum is the optimiser's final scaled cost."""
    study = load_study(write_study(tmp_path, {**small_study(**TINY), "objective": "battery_energy"}))
    output = run_study(study, tmp_path / "run", progress=None, figures=False)
    problem = TaskProblem(study, id_path="analytic")
    base = optimum_design(output.folder)
    at = evaluate_designs(problem, base, base.xi[None])
    assert problem.objective.name == "battery_energy"
    assert at.objective[0] == pytest.approx(output.result.history[-1].scaled_cost, rel=1e-9)
    assert at.battery_energy[0] == pytest.approx(output.result.energy.optimal.battery_energy_J, rel=1e-10)


@pytest.mark.parametrize("variables", [(0, 1), (1, 2), (0, 2)])
def test_no_feasible_cell_beats_the_optimum(optimum: tuple, variables: tuple[int, int]) -> None:  # type: ignore[type-arg]
    """The map's best feasible cell is no better than the optimum, and the cell nearest it is within one grid step.

    The optimum's trajectory is fixed and two lengths vary: the optimum is a KKT point of this slice too,
    so a feasible cell may undercut it only by the optimiser's tolerances (ftol 1e-9 on the scaled cost).
    """
    problem, folder, _ = optimum
    base = optimum_design(folder)
    m = energy_map(problem, base, variables, 25)
    f_opt = m.at_base.objective[0]
    feasible = m.values.feasible
    assert feasible.any()
    assert m.values.objective[feasible].min() >= f_opt - 1e-6
    i, j = variables
    near = np.argmin(np.abs(m.axes[0] - base.xi[i])), np.argmin(np.abs(m.axes[1] - base.xi[j]))
    grid = m.grid(m.values.objective)
    step = max(np.abs(np.diff(grid, axis=0)).max(), np.abs(np.diff(grid, axis=1)).max())
    assert abs(grid[near] - f_opt) <= step


def test_map_margins_equal_the_problems_constraint_rows() -> None:
    """The map's Xi-dependent margins equal the NLP's rows (min over time) at designs around the start."""
    study = load_study(None)
    problem = TaskProblem(study, id_path="analytic")
    base = start_design(problem)
    rng = np.random.default_rng(4)
    xi = base.xi[None] * (1.0 + rng.uniform(-0.002, 0.002, (3, 6)))
    xi = np.vstack([base.xi[None], xi])
    values = evaluate_designs(problem, base, xi)
    strip = re.compile(r" at t=.*$")
    for d in range(len(xi)):
        z = problem.initial_point(LinkLengths.from_array(xi[d]))
        try:
            rows = problem.margins(z)
        except HiabSimError:  # the per-design ID refuses designs outside the working range; the map marks them
            assert not values.feasible[d]
            continue
        by_name: dict[str, float] = {}
        for name, value in zip(problem.constraint_names, rows, strict=True):
            key = strip.sub("", name)
            by_name[key] = min(by_name.get(key, np.inf), float(value))
        want = np.array([by_name[n] for n in values.names])
        np.testing.assert_allclose(values.margins[d], want, rtol=1e-9, atol=1e-9)
        assert values.cost[d] == pytest.approx(problem.evaluate(z).cost, rel=1e-10)


def test_energy_map_cli_writes_the_map_and_names_the_base(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The CLI writes JSON, NPZ and PNG, says which base design and that the trajectory is fixed."""
    study = write_study(tmp_path, small_study(**TINY))
    assert main(["energy-map", str(study), "--grid", "12", "--out", str(tmp_path / "map")]) == 0
    out = capsys.readouterr().out
    assert "start of the study" in out and "trajectory fixed" in out
    summary = json.loads((tmp_path / "map" / "energy_map.json").read_text())
    assert summary["variables"] == ["lift.L", "lift.Lc0"] and summary["cells"] == 144
    assert (tmp_path / "map" / "energy_map.png").stat().st_size > 10_000
    assert np.load(tmp_path / "map" / "energy_map.npz")["objective"].shape == (12, 12)


@pytest.mark.parametrize("bad", ["lift.L", "lift.L,lift.L", "lift.L,boom.X"])
def test_bad_vars_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str], bad: str) -> None:
    """--vars must name two distinct link lengths; otherwise one line naming --vars and exit 2."""
    assert main(["energy-map", "--vars", bad, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "--vars" in err and all(v in err for v in VARIABLES[:1])
