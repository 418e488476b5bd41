"""Pareto fronts by the epsilon-constraint method: criterion samples, the inactive end, monotonicity."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from test_study_small import small_study, write_study
from test_sweep import TINY

from hiab_sim.cli import main
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.solvers.slsqp import SolveResult, solve
from hiab_sim.study.spec.study_file import study_from_dict
from hiab_sim.sweep.pareto import EpsilonProblem, criterion, pareto_front, samples_of_points


@pytest.fixture(scope="module")
def plain() -> tuple[TaskProblem, SolveResult]:
    """The tiny study (analytic ID) and its plain optimum."""
    study = study_from_dict(small_study(**TINY), "tiny.yaml")
    problem = TaskProblem(study)
    return problem, solve(problem, study.initial_lengths, progress=None)


def test_stacked_samples_equal_the_problems_own_forces(plain: tuple[TaskProblem, SolveResult]) -> None:
    """The criterion's forces (designs stacked on the analytic path) equal the NLP's ID forces at start and optimum."""
    problem, result = plain
    for z in (result.z0, result.z):
        stacked = samples_of_points(problem, np.vstack([z, z]), "peak_force")
        own = problem.evaluate(z).actuators.force.ravel()
        np.testing.assert_allclose(stacked[0], own, rtol=1e-12, atol=1e-8)
        np.testing.assert_array_equal(stacked[0], stacked[1])


def test_inactive_epsilon_reproduces_the_plain_optimum(plain: tuple[TaskProblem, SolveResult]) -> None:
    """With epsilon far above the optimum's criterion, the epsilon problem from the start finds the plain optimum."""
    problem, result = plain
    c0 = criterion(problem, result.z, "rms_torque")
    z, accepted, message, _ = EpsilonProblem(problem, "rms_torque", 10.0 * c0, c0).solve(result.z0, 100)
    assert accepted, message
    assert problem.evaluate(z).cost == pytest.approx(problem.evaluate(result.z).cost, rel=1e-9)
    np.testing.assert_allclose(z[: problem.n_xi], result.z[: problem.n_xi], atol=1e-8)


@pytest.mark.e2e
def test_front_is_monotone_from_the_plain_optimum(plain: tuple[TaskProblem, SolveResult]) -> None:
    """A lower peak force never comes with a lower objective; each point holds its epsilon; it starts at the optimum."""
    problem, result = plain
    front = pareto_front(problem, result.z, "peak_force", 3)
    assert all(p.accepted for p in front), [p.message for p in front]
    assert front[0].objective_value == problem.evaluate(result.z).cost
    for previous, point in itertools.pairwise(front):
        assert point.epsilon < previous.epsilon
        assert point.criterion <= point.epsilon * (1.0 + 1e-6)
        assert point.objective >= previous.objective - 1e-9
    assert front[-1].objective > front[0].objective  # the trade-off is real, not a flat line


def test_pareto_cli_rejects_too_few_points(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--points 1 is one line naming --points and exit status 2."""
    study = write_study(tmp_path, small_study(**TINY))
    assert main(["pareto", str(study), "--against", "peak_force", "--points", "1", "--out", str(tmp_path / "p")]) == 2
    assert "--points" in capsys.readouterr().err
