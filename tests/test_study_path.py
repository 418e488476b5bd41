"""One study path: rows of Xi alone held once over the tasks, and the battery objective through every analysis."""

from __future__ import annotations

from pathlib import Path

import pytest
from test_mix import two_tasks
from test_study_small import small_study

from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.run import run_study
from hiab_sim.study.spec.study_file import load_study, study_from_dict

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.e2e
def test_shipped_duty_mix_holds_each_xi_only_row_once() -> None:
    """xs031_duty_mix (three tasks, the crane's working range): 12 buildable-range and 12 working-range rows, not 36."""
    problem = StudyProblem(load_study(ROOT / "optimize" / "xs031_duty_mix.yaml"))
    assert problem.n_tasks == 3
    for block in ("buildable_range", "working_range"):
        assert sum(f": {block}." in name for name in problem.constraint_names) == 12
    for task in range(3):  # every task keeps its own trajectory rows
        assert sum(b.block.name == "tracking.position" for b in problem.blocks if b.task == task) == 1


def test_single_task_study_problem_is_its_task_bit_for_bit() -> None:
    """A one-task study's NLP is its task's: the same cost, rows and gradient at a point (w = 1)."""
    problem = StudyProblem(study_from_dict(small_study(), "s.yaml"))
    task = problem.problems[0]
    z = problem.initial_point(problem.study.initial_lengths) + 1e-3
    assert problem.cost(z) == task.cost(z)
    assert (problem.constraints(z) == task.constraints(z)).all()
    assert (problem.cost_gradient(z) == task.cost_gradient(z)).all()
    assert problem.constraint_names == task.constraint_names


@pytest.mark.e2e
def test_battery_objective_gives_sensitivities_cross_evaluation_and_costf2_in_their_units(tmp_path: Path) -> None:
    """Two tasks, objective battery_energy: sensitivities, cross-evaluation and costs each in their own unit.

    Sensitivities in J and % of the battery energy, the cross-evaluation's objective in J and its costs
    in W^2 s (costf2), the designs' costs costf2.
    """
    study = study_from_dict({**two_tasks(), "objective": "battery_energy"}, "two.yaml")
    r = run_study(study, tmp_path / "run", progress=None, figures=False, cross=True).result
    s = r.sensitivity
    assert s is not None and s.objective == "battery_energy" and s.objective_unit == "J"
    assert r.energy is not None
    # the smooth battery energy the solver saw (weighted over the tasks, on its 12-interval collocation
    # grid) against the energy section's, the same smooth energy on the 120-interval fine grid: they
    # differ by the trapezoid rule's error on the coarse grid (measured 1.07 % on this study)
    assert s.objective_value == pytest.approx(r.energy.optimal.battery_energy_smooth_J, rel=2e-2)
    assert s.objective_value < 1e5  # joules of a 6 s cycle, not W^2 s (~1e6)
    for m in s.multipliers:
        assert m.percent_per_unit == pytest.approx(100.0 * m.objective_decrease_per_unit / s.objective_value)
    assert r.optimal.collocation_cost_W2s is not None and r.optimal.collocation_cost_W2s > 1e5  # costf2
    assert r.buildable is not None
    cross = r.cross_evaluation
    assert cross is not None and cross.objective_unit == "J" and cross.mix_objective_value is not None
    mix_objective = cross.mix_objective_value[-1]
    # the mix design re-optimised at its Xi from its own trajectory and from the inverse-kinematics fit:
    # never above the optimum's own objective, in the same unit (here the fit's start ends 0.93 % lower,
    # a better local optimum of the trajectory than the mix solve's)
    assert mix_objective is not None and mix_objective <= s.objective_value * (1.0 + 1e-9)
    assert mix_objective == pytest.approx(s.objective_value, rel=2e-2)
    mix_cost = cross.mix_cost_W2s[-1]  # costf2 [W^2 s] of that re-optimised trajectory (1.2 % below the optimum's)
    assert mix_cost is not None and mix_cost == pytest.approx(r.optimal.collocation_cost_W2s, rel=2e-2)


@pytest.mark.e2e
def test_codesign_of_two_tasks_scores_each_combination_by_the_weighted_objective() -> None:
    """A two-task study's co-design row: the objective [J] is the tasks' weighted exact battery energy."""
    from hiab_sim.study.analysis.codesign import combinations, solve_combination

    data = {
        **two_tasks(),
        "objective": "battery_energy",
        "transmission": {"lift": [{"gear_ratio": 4.5, "screw_lead": 0.01}]},
    }
    study = study_from_dict(data, "two.yaml")
    combo = combinations(study)[1]
    row = solve_combination(study, combo)
    assert row.status == "converged", row.message
    assert row.objective_unit == "J" and row.objective_value == row.battery_energy_J
    assert row.costf2_W2s is not None and row.costf2_W2s > 1e5  # W^2 s, not joules
    assert row.battery_energy_J is not None and row.initial_battery_energy_J is not None
    assert row.battery_energy_J < row.initial_battery_energy_J
