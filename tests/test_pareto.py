"""Pareto fronts by the epsilon-constraint method: criterion samples, their Jacobian, the inactive end, mixes."""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import numpy as np
import pytest
from test_energy_map import two_task_mix
from test_study_small import small_study, write_study
from test_sweep import TINY

from hiab_sim.cli import main
from hiab_sim.dynamics.analytic_batch import batched_inverse_dynamics
from hiab_sim.emla.drive import drive_state
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.solvers.slsqp import SolveResult, solve
from hiab_sim.study.spec.study_file import study_from_dict
from hiab_sim.sweep import pareto
from hiab_sim.sweep.epsilon_rows import epsilon_problem
from hiab_sim.sweep.pareto import (
    FAR_END_SLACK,
    FEASIBLE,
    criterion,
    criterion_samples,
    minimise_criterion,
    pareto_front,
    samples_jacobian,
    solve_point,
)


@pytest.fixture(scope="module")
def plain() -> tuple[StudyProblem, SolveResult]:
    """The tiny study (analytic ID) and its plain optimum."""
    study = study_from_dict(small_study(**TINY), "tiny.yaml")
    problem = StudyProblem(study)
    return problem, solve(problem, study.initial_lengths, progress=None)


@pytest.fixture(scope="module")
def mix() -> StudyProblem:
    """The tiny study as a two-task mix (weights 1 and 3, a payload in the second)."""
    return StudyProblem(study_from_dict(two_task_mix(), "mix.yaml"))


def test_criterion_samples_equal_the_cranes_stacked_analytic_id(plain: tuple[StudyProblem, SolveResult]) -> None:
    """The criterion's forces and rms torque equal the crane's stacked analytic ID at start and optimum."""
    problem, result = plain
    p = problem.problems[0]
    for z in (result.z0, result.z):
        design, c = p.unpack(z)
        q = p.joints(c)
        f, v, a, _ = batched_inverse_dynamics(
            problem.study.crane, design.as_array()[None], q.position, q.velocity, q.acceleration, p.tcp_force
        )
        np.testing.assert_allclose(criterion_samples(problem, z, "peak_force"), f[0].ravel(), rtol=1e-12, atol=1e-8)
        tau = np.column_stack(
            [drive_state(e, f[0, :, i], v[0, :, i], a[0, :, i]).motor_torque for i, e in enumerate(p.emlas)]
        )
        rms = np.sqrt(np.mean(np.sum(tau**2, axis=1)))
        assert criterion_samples(problem, z, "rms_torque")[0] == pytest.approx(rms, rel=1e-12)


@pytest.mark.parametrize("name", ["peak_force", "rms_torque"])
def test_criterion_jacobian_matches_central_differences_on_a_mix(mix: StudyProblem, name: str) -> None:
    """D samples / dz of a two-task mix equals central differences, in the Xi columns and each task's own columns."""
    rng = np.random.default_rng(5)
    z = mix.initial_point(mix.study.initial_lengths)
    z[mix.n_xi :] += rng.normal(0.0, 2e-3, mix.n - mix.n_xi)
    jac = samples_jacobian(mix, z, name)
    columns = [*range(mix.n_xi), *(off + j for off in mix.offsets for j in (0, 7, 20))]
    h = 1e-6
    for i in columns:
        up, down = z.copy(), z.copy()
        up[i] += h
        down[i] -= h
        fd = (criterion_samples(mix, up, name) - criterion_samples(mix, down, name)) / (2 * h)
        scale = max(1.0, float(np.abs(fd).max()))
        np.testing.assert_allclose(jac[:, i], fd, atol=1e-5 * scale)
    # a task's samples do not depend on another task's coefficients
    rows0 = len(mix.problems[0].times) * 3 if name == "peak_force" else 1
    assert not jac[:rows0, mix.offsets[1] :].any() and not jac[rows0:, mix.offsets[0] : mix.offsets[1]].any()


@pytest.mark.parametrize("name", ["peak_force", "rms_torque"])
def test_epsilon_rows_hold_each_tasks_criterion_with_central_difference_jacobian(mix: StudyProblem, name: str) -> None:
    """The epsilon problem's added rows are epsilon -+ each task's samples, scaled; their Jacobian central differences.

    The rows read each task's own evaluation; the criterion samples compute the inverse dynamics on
    their own. The study's own rows, its variables and its cost scale stay as they were.
    """
    rng = np.random.default_rng(8)
    z = mix.initial_point(mix.study.initial_lengths)
    z[mix.n_xi :] += rng.normal(0.0, 2e-3, mix.n - mix.n_xi)
    c = criterion(mix, z, name)
    bounded = epsilon_problem(mix, name, 0.9 * c, c)
    assert (bounded.n, bounded.cost_scale) == (mix.n, mix.cost_scale)
    added = np.array(["epsilon." in row for row in bounded.constraint_names])
    np.testing.assert_array_equal(bounded.constraints(z)[~added], mix.constraints(z))
    rows = bounded.constraints(z)[added]
    s = criterion_samples(mix, z, name)
    expected = np.concatenate([0.9 * c - s, 0.9 * c + s]) if name == "peak_force" else 0.9 * c - s
    np.testing.assert_allclose(np.sort(rows), np.sort(expected / c), rtol=0.0, atol=1e-12)
    jac = bounded.constraints_jacobian(z)[added]
    h = 1e-6
    for i in [*range(mix.n_xi), *(off + j for off in mix.offsets for j in (0, 7, 20))]:
        up, down = z.copy(), z.copy()
        up[i] += h
        down[i] -= h
        fd = (bounded.constraints(up)[added] - bounded.constraints(down)[added]) / (2 * h)
        np.testing.assert_allclose(jac[:, i], fd, atol=1e-5 * max(1.0, float(np.abs(fd).max())))


@pytest.mark.e2e
def test_front_of_an_ipopt_study_is_solved_by_ipopt_to_its_far_end() -> None:
    """An IPOPT study's front points are IPOPT's; the far end converges just above c_min, below z_min's objective.

    z_min (the least peak force) is feasible at the far end, so the far end's objective is at most
    its own: the least-criterion design is not the far end's answer (it minimises the criterion alone).
    """
    data = small_study(**TINY)
    data["solver"] = {**data["solver"], "method": "ipopt"}
    problem = StudyProblem(study_from_dict(data, "tiny_ipopt.yaml"))
    optimum = solve(problem, problem.study.initial_lengths, progress=None)
    z_min, c_min, converged = minimise_criterion(problem, optimum.z, "peak_force")
    assert converged
    traced = pareto_front(problem, optimum.z, "peak_force", 3)
    front = traced.points
    assert all(p.accepted for p in front), [p.message for p in front]
    accepted_try = [p.message.rsplit("; from ", 1)[-1].split(": ")[-1] for p in front[1:]]  # after any retry
    assert all(m in ("Solve_Succeeded", "Solved_To_Acceptable_Level") for m in accepted_try), accepted_try
    far = front[-1]
    assert far.epsilon == pytest.approx(c_min + FAR_END_SLACK * (front[0].criterion - c_min), rel=1e-12)
    assert far.criterion <= far.epsilon * (1.0 + FEASIBLE)
    assert far.objective < problem.evaluate(z_min).cost / problem.cost_scale
    assert (traced.least.epsilon, traced.least.criterion) == (c_min, c_min)
    assert traced.least.objective == problem.evaluate(z_min).cost / problem.cost_scale


def test_inactive_epsilon_reproduces_the_plain_optimum(plain: tuple[StudyProblem, SolveResult]) -> None:
    """With epsilon far above the optimum's criterion, the epsilon problem from the start finds the plain optimum."""
    problem, result = plain
    c0 = criterion(problem, result.z, "rms_torque")
    z, accepted, message, _ = solve_point(epsilon_problem(problem, "rms_torque", 10.0 * c0, c0), result.z0)
    assert accepted, message
    assert problem.evaluate(z).cost == pytest.approx(problem.evaluate(result.z).cost, rel=1e-9)
    np.testing.assert_allclose(z[: problem.n_xi], result.z[: problem.n_xi], atol=1e-8)


def test_a_point_tried_from_several_starts_keeps_every_tries_message(
    plain: tuple[StudyProblem, SolveResult], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each try's message is kept, named by its start: all three failed, or one failed and the next accepted.

    The solver is replaced by one that answers a scripted (accepted, message) per call; a point
    accepted at its first try keeps that try's message alone.
    """
    problem, result = plain
    c0 = criterion(problem, result.z, "peak_force")
    monkeypatch.setattr(pareto, "minimise_criterion", lambda p, z, name: (result.z, 0.99 * c0, True))
    answers = iter([(False, "a"), (False, "b"), (False, "c"), (False, "d"), (True, "e"), (True, "f")])
    monkeypatch.setattr(pareto, "solve_point", lambda bounded, z0: (z0, *next(answers), 1))
    front = pareto_front(problem, result.z, "peak_force", 4).points
    assert [p.message for p in front[1:]] == [
        "from the previous point: a; from the study's start: b; from the least-criterion design: c",
        "from the previous point: d; from the study's start: e",
        "f",
    ]
    assert [p.accepted for p in front[1:]] == [False, True, True]


@pytest.mark.e2e
def test_front_is_monotone_from_the_plain_optimum(plain: tuple[StudyProblem, SolveResult]) -> None:
    """A lower peak force never comes with a lower objective; each point holds its epsilon; it starts at the optimum."""
    problem, result = plain
    front = pareto_front(problem, result.z, "peak_force", 3).points
    assert all(p.accepted for p in front), [p.message for p in front]
    assert front[0].objective_value == problem.evaluate(result.z).cost
    assert front[0].design_names == problem.model.design_names
    for previous, point in itertools.pairwise(front):
        assert point.epsilon < previous.epsilon
        assert point.criterion <= point.epsilon * (1.0 + 1e-6)
        assert point.objective >= previous.objective - 1e-9
    assert front[-1].objective > front[0].objective  # the trade-off is real, not a flat line


@pytest.mark.e2e
def test_front_point_of_a_mix_is_feasible_for_every_task(mix: StudyProblem) -> None:
    """Each accepted point of a two-task mix's front holds every task's rows and its epsilon on every task.

    Checked on each task's own one-task problem (built alone, its own rows and violation) and on the
    forces of each task's ID, not on the stacked problem the front was solved on. About 27 s on 2 cores.
    """
    optimum = solve(mix, mix.study.initial_lengths, progress=None)
    front = pareto_front(mix, optimum.z, "peak_force", 3).points
    assert sum(p.accepted for p in front) >= 2, [p.message for p in front]
    for point in front:
        if not point.accepted:
            continue
        z = np.asarray(point.z)
        for k, task in enumerate(mix.study.tasks):
            alone = TaskProblem(mix.study, task=task)
            zk = mix.task_z(z, k)
            assert alone.max_violation(zk) <= FEASIBLE
            assert np.abs(alone.evaluate(zk).actuators.force).max() <= point.epsilon * (1.0 + 1e-6)


@pytest.mark.e2e
def test_far_end_of_the_default_study_converges_just_above_the_least_peak_force(tmp_path: Path) -> None:
    """The default study's far end is a converged point beside the least-criterion design (pareto.json, summary.md).

    At epsilon = c_min itself SLSQP stalled from all three starts (79 iterations, a positive directional
    derivative); the far end stands FAR_END_SLACK of the span above it. Its objective is at most the
    least-criterion design's (that design is feasible there), and both are written. About 15 s on 2 cores.
    """
    out = tmp_path / "front"
    assert main(["pareto", "--against", "peak_force", "--points", "2", "--out", str(out)]) == 0
    data = json.loads((out / "pareto.json").read_text())
    plain, far = data["points"]
    least = data["least_criterion"]
    assert far["accepted"], far["message"]
    assert far["epsilon"] == pytest.approx(
        least["criterion"] + FAR_END_SLACK * (plain["criterion"] - least["criterion"])
    )
    assert least["criterion"] <= far["criterion"] <= far["epsilon"] * (1.0 + 1e-9) < plain["criterion"]
    assert plain["objective"] < far["objective"] <= least["objective"]
    assert "least peak actuator force the study's limits allow" in (out / "summary.md").read_text()


def test_pareto_cli_rejects_too_few_points(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--points 1 is one line naming --points and exit status 2."""
    study = write_study(tmp_path, small_study(**TINY))
    assert main(["pareto", str(study), "--against", "peak_force", "--points", "1", "--out", str(tmp_path / "p")]) == 2
    assert "--points" in capsys.readouterr().err
