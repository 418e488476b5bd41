"""One design for several tasks: the mix NLP's assembly, derivatives, sparsity, payload schedule and optimum."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from test_study_small import small_study

from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.run import run_study
from hiab_sim.study.solvers.sparse_rows import SparseJacobian, task_rows
from hiab_sim.study.spec.payload import Payload
from hiab_sim.study.spec.study_file import Study, study_from_dict

#: Relative cost spread of the NLP's local optima on the two-task study (measured 1.3e-5).
LOCAL_SPREAD = 1e-4
#: Held from 1.5 s to 4.5 s of the second task (weight and inertia).
SCHEDULE = {"mass": 120.0, "pick": 1.5, "release": 4.5}


def two_tasks(**solver: Any) -> dict[str, Any]:
    """The small study as two tasks: its spiral (weight 1) and a smaller one with a payload schedule (weight 2)."""
    data = small_study()
    spiral = {"kind": "spiral", **data.pop("reference")}
    data["tasks"] = [
        {"name": "spiral", "weight": 1.0, "reference": spiral},
        {
            "name": "second",
            "weight": 2.0,
            "reference": {
                **spiral,
                "centre_joints": [0.75, -1.45],
                "end_radius": 0.2,
                "telescope_amplitude": 0.1,
            },
            "payload": SCHEDULE,
        },
    ]
    data["solver"] = {**data["solver"], **solver}
    return data


@pytest.fixture(scope="module")
def study() -> Study:
    return study_from_dict(two_tasks(), "two.yaml")


@pytest.fixture(scope="module")
def mix(study: Study) -> StudyProblem:
    return StudyProblem(study)


def _point(mix: StudyProblem, seed: int = 1) -> np.ndarray:
    """A point near the start: the built crane's Xi, every task's coefficients perturbed."""
    rng = np.random.default_rng(seed)
    z = mix.initial_point(mix.study.initial_lengths)
    z[6:] += rng.normal(0.0, 2e-3, len(z) - 6)
    return z


def test_mix_is_the_weighted_sum_and_the_stack_of_independently_built_tasks(study: Study, mix: StudyProblem) -> None:
    """Cost = sum w_k f_k and rows = each task's rows, against one TaskProblem built per task."""
    z = _point(mix)
    cost, rows = 0.0, []
    for k, task in enumerate(study.tasks):
        alone = TaskProblem(study, task=task)
        zk = np.concatenate([z[:6], z[mix.offsets[k] : mix.offsets[k] + alone.n_c]])
        cost += task.weight * alone.evaluate(zk).cost
        rows.append(alone.constraints(zk)[mix.rows[k]])
    assert mix.evaluate(z).cost == pytest.approx(cost, rel=1e-12)
    np.testing.assert_array_equal(mix.constraints(z), np.concatenate(rows))
    # the working range (Xi only, the same for both tasks) is kept once
    assert sum("working_range" in name for name in mix.constraint_names) == 12
    assert len(mix.constraint_names) == len(mix.constraints(z)) == len(mix.clearance)


def test_mix_gradient_and_jacobians_match_central_differences(mix: StudyProblem) -> None:
    """d(cost)/dz, D g/dz and D e/dz of the assembled mix equal central differences column by column."""
    z = _point(mix, 2)
    grad, jac, jeq = mix.cost_gradient(z), mix.constraints_jacobian(z), mix.equalities_jacobian(z)
    h = 1e-6
    for i in range(mix.n):
        up, down = z.copy(), z.copy()
        up[i] += h
        down[i] -= h
        assert (mix.cost(up) - mix.cost(down)) / (2 * h) == pytest.approx(grad[i], abs=2e-5)
        np.testing.assert_allclose((mix.constraints(up) - mix.constraints(down)) / (2 * h), jac[:, i], atol=2e-4)
        np.testing.assert_allclose((mix.equalities(up) - mix.equalities(down)) / (2 * h), jeq[:, i], atol=1e-6)


def test_sparsity_pattern_holds_every_nonzero_and_tasks_do_not_couple(mix: StudyProblem) -> None:
    """IPOPT's pattern covers every nonzero of D g/dz; a task's rows have no entries in another task's columns."""
    z = _point(mix, 3)
    sparse_jac = SparseJacobian(mix, z)
    pattern = np.zeros(sparse_jac.shape, dtype=bool)
    pattern[sparse_jac.indices, np.repeat(np.arange(mix.n), np.diff(sparse_jac.indptr))] = True
    pattern = pattern[sparse_jac.m_eq :]  # the inequality rows IPOPT holds
    held = np.concatenate([np.searchsorted(kept, t.rows) + sum(len(r) for r in mix.rows[:k])
                           for k, (t, kept) in enumerate(zip(task_rows(mix), mix.rows, strict=True))])  # fmt: skip
    jac = mix.constraints_jacobian(z)[held]
    assert not np.any((jac != 0.0) & ~pattern)
    first = len(task_rows(mix)[0].rows)
    assert not pattern[:first, mix.offsets[1] :].any() and not pattern[first:, mix.offsets[0] : mix.offsets[1]].any()
    assert pattern.mean() < 0.3  # the structure IPOPT exploits


def test_study_level_payload_schedule_enters_the_id_as_weight_and_inertia(study: Study, mix: StudyProblem) -> None:
    """The scheduled task's actuators do extra work -F . v_tcp exactly while the load is held, zero outside."""
    task, p = study.tasks[1], mix.problems[1]
    empty = TaskProblem(study, task=type(task)(task.name, task.weight, task.reference, Payload(0.0)))
    z = _point(mix, 4)
    zk = np.concatenate([z[:6], z[mix.offsets[1] :]])
    loaded, free = p.evaluate(zk), empty.evaluate(zk)
    ref = task.reference.sample(p.kin, p.times)
    g = study.crane.gravity
    held = (p.times >= SCHEDULE["pick"]) & (p.times < SCHEDULE["release"])
    force = np.where(held[:, None], SCHEDULE["mass"], 0.0) * (np.array([0.0, -g]) - ref.acceleration[:, :2])
    extra = np.sum((loaded.actuators.force - free.actuators.force) * loaded.actuators.velocity, axis=1)
    np.testing.assert_allclose(extra, -np.sum(force * loaded.tcp.velocity[:, :2], axis=1), atol=1e-6)
    assert np.all(loaded.actuators.force[~held] == free.actuators.force[~held])
    assert np.ptp(force[held, 0]) > 0.0  # the inertia part varies while held


def test_single_task_study_is_one_link_length_problem() -> None:
    """A study with one task builds today's problem: same grid, spline and start as before the tasks loader."""
    study = study_from_dict(small_study(), "small.yaml")
    problem = TaskProblem(study)
    np.testing.assert_array_equal(problem.times, np.linspace(0.0, 6.25, 13))
    assert problem.basis.n == 16 and problem.tcp_force is None


@pytest.fixture(scope="module")
def solved(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("mix")
    run_study(study_from_dict(two_tasks(), folder / "two.yaml"), folder / "out", progress=None, figures=False)
    return folder / "out"


@pytest.mark.e2e
def test_two_task_mix_converges_feasible_on_every_task_and_rechecks(solved: Path) -> None:
    """Success, violation <= 1e-6 on every task, re-checked on the fine grid with the other ID path."""
    from hiab_sim.results.read import read_result

    r = read_result(solved)
    assert r.solver.success and r.tasks is not None and len(r.tasks) == 2
    for task in r.tasks:
        assert task.optimal.collocation_max_violation is not None and task.optimal.collocation_max_violation <= 1e-6
        assert task.recheck.max_violation_scaled <= 1e-6 and task.recheck.id_path != task.optimal.id_path
    assert r.optimal.net_electrical_energy_J < r.initial.net_electrical_energy_J


@pytest.mark.e2e
def test_cross_evaluation_is_consistent(solved: Path) -> None:
    """The mix optimum costs the mix no more than any task's optimum; each task's optimum is best on its task."""
    from hiab_sim.results.read import read_result

    pytest.importorskip("casadi")  # the fixed-Xi re-optimisations run on IPOPT
    cross = read_result(solved).cross_evaluation
    assert cross is not None and cross.designs == ("spiral alone", "second alone", "mix")
    # The NLP is not convex: its local optima (here tilt L ~ 1.20 m or ~ 1.13 m) differ by ~1e-5 in
    # cost, so "no more" holds to LOCAL_SPREAD, not to the solver's tolerance.
    mix_cost = [c for c in cross.mix_cost_W2s if c is not None]
    assert len(mix_cost) == 3 and all(mix_cost[-1] <= c * (1 + LOCAL_SPREAD) for c in mix_cost)
    for k in range(2):
        own, on_mix = cross.cost_W2s[k][k], cross.cost_W2s[-1][k]
        assert own is not None and on_mix is not None and own <= on_mix * (1 + LOCAL_SPREAD)
    assert cross.mix_energy_lost_J[-1] == 0.0


@pytest.mark.e2e
def test_summary_says_when_the_cross_evaluation_drives_the_mix_design_for_less(solved: Path) -> None:
    """The two-task mix's solve keeps a trajectory of its second task 1.8 % above the fit's: the answer says so.

    The line's percentage is the cross-evaluation's weighted objective against the optimum's own.
    """
    from hiab_sim.results.read import read_result
    from hiab_sim.study.report.summary import summary_lines

    pytest.importorskip("casadi")
    r = read_result(solved)
    assert r.cross_evaluation is not None and r.cross_evaluation.mix_objective_value is not None
    assert r.sensitivity is not None
    driven, own = r.cross_evaluation.mix_objective_value[-1], r.sensitivity.objective_value
    assert driven is not None and driven < own * (1.0 - 1e-3)
    (line,) = [line for line in summary_lines(r, solved) if line.startswith("Local optimum")]
    assert f"costs {100.0 * (own - driven) / own:.2g} % less" in line


@pytest.mark.slow
def test_duty_mix_converges_from_the_built_crane_and_three_starts_agree(tmp_path: Path) -> None:
    """The shipped duty mix: violation <= 1e-6 on every task (fine grid, other ID path); 3 starts agree or listed."""
    from hiab_sim.results.read import read_result
    from hiab_sim.study.spec.study_file import load_study

    pytest.importorskip("casadi")
    run_study(load_study("xs031_duty_mix"), tmp_path, starts=3, progress=None, figures=False, cross=False)
    r = read_result(tmp_path)
    assert r.solver.success and r.tasks is not None and len(r.tasks) == 3
    assert r.optimal.lengths == r.multistart.starts[0].optimal_lengths
    for task in r.tasks:
        assert task.optimal.collocation_max_violation is not None and task.optimal.collocation_max_violation <= 1e-6
        assert task.recheck.max_violation_scaled <= 1e-6 and task.recheck.id_path != task.optimal.id_path
    ms = r.multistart
    assert ms.converged_starts == 3 and sum(len(d.starts) for d in ms.distinct_optima) == 3
    # one Xi, or the distinct local optima each reported with its mix energy
    assert ms.same_optimum or all(d.net_electrical_energy_J is not None for d in ms.distinct_optima)


def test_study_file_with_tasks_loads_them_and_one_without_either_form_is_refused() -> None:
    """``tasks:`` gives the Study its tasks in order; a study with neither ``tasks:`` nor ``reference:`` is refused."""
    from hiab_sim.errors import ConfigError
    from hiab_sim.study.spec.study_file import load_study

    mix = load_study("xs031_duty_mix")
    assert [t.name for t in mix.tasks] == ["spiral", "pick_and_place", "loading_cycle"]
    assert [t.reference.kind for t in mix.tasks] == ["spiral", "pick_and_place", "csv"]
    assert mix.tasks[1].payload.inertia and mix.tasks[1].payload.pick is not None
    data = small_study()
    del data["reference"]
    with pytest.raises(ConfigError, match="'tasks:'"):
        study_from_dict(data, "none.yaml")


@pytest.mark.e2e
def test_an_infeasible_mix_start_goes_through_the_feasibility_phase_and_converges(tmp_path: Path) -> None:
    """Lift Lc0 + 1.5 mm leaves x < 0 at the low end of the range on both tasks: repaired (IPOPT projection), solved."""
    from hiab_sim.results.read import read_result
    from hiab_sim.study.solvers.feasibility import feasible_start

    pytest.importorskip("casadi")
    data = two_tasks()
    data["initial_lengths"] = {"lift": {"L": 1.0071227324212, "Lc0": 0.0865, "Lc": 0.745},
                               "tilt": {"L": 1.132185817991, "Lc0": 0.085, "Lc": 0.745}}  # fmt: skip
    study = study_from_dict(data, tmp_path / "two.yaml")
    problem = StudyProblem(study)
    z0 = problem.initial_point(study.initial_lengths)
    assert problem.max_violation(z0) > 1e-3
    z, phase = feasible_start(problem, z0)
    assert phase is not None and problem.max_violation(z) <= 1e-9
    assert phase.initial_worst.split(": ")[0] in ("spiral", "second")  # the row is named with its task
    run_study(study, tmp_path / "out", progress=None, figures=False, cross=False)
    r = read_result(tmp_path / "out")
    assert r.feasibility is not None and r.feasibility[0].initial_max_violation > 1e-3
    assert r.solver.success and r.solver.max_violation_scaled <= 1e-6


def test_an_impossible_payload_on_one_task_exits_3_naming_the_limit_and_the_task(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A 2 t schedule on the second task exceeds the lift EMLA at every length: exit 3, the limit and task named."""
    import yaml

    from hiab_sim.cli import main

    pytest.importorskip("casadi")
    data = two_tasks()
    data["tasks"][1]["payload"] = {**SCHEDULE, "mass": 2000.0}
    path = tmp_path / "two.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["optimize", str(path), "--out", str(tmp_path / "run"), "--no-figures", "--no-video", "--quiet"]) == 3
    err = capsys.readouterr().err
    assert "EMLA" in err and "exceeded by" in err and "of task second" in err
    assert not (tmp_path / "run" / "result.json").exists()


def test_each_task_reports_its_thermal_state_over_its_own_cycle_and_the_hourly_rms_is_duty_independent() -> None:
    """A 7.5 s task in a study of 6.25 s grids: its duty is 7.5 s + rest; int tau^2 dt = rms^2 P for any duty.

    The mix's hourly RMS torque (weights as cycles per hour) sums w_k rms_k^2 P_k, so it must not
    depend on the duty the tasks' own RMS values were taken over.
    """
    from hiab_sim.study.report.design_check import design_summary, fine_problem
    from hiab_sim.study.report.energy_section import energy_report, study_duty, weighted_energy_report

    rms, hourly = {}, {}
    for per_hour in (60.0, 120.0):
        data = two_tasks()
        data["tasks"][1]["reference"]["duration"] = 7.5
        data["duty"] = {"cycles_per_hour": per_hour}
        mix = StudyProblem(study_from_dict(data, "two.yaml"))
        z = mix.initial_point(mix.study.initial_lengths)
        reports, periods = [], []
        for k, p in enumerate(mix.problems):
            fine = fine_problem(p)
            state = design_summary(fine, mix.task_z(z, k)).evaluation
            reports.append(energy_report(fine, state, state))
            periods.append(study_duty(fine)[0].period)
        assert "7.5 s cycle" in reports[1].duty and reports[1].optimal.thermal is not None
        rms[per_hour] = {k: th.rms_torque_Nm for k, th in reports[1].optimal.thermal.items()}
        cycles = [task.reference.duration for task in mix.tasks]
        hourly[per_hour] = weighted_energy_report(reports, mix.weights.tolist(), cycles, periods).hourly_rms_torque_Nm
    for name, value in rms[60.0].items():  # periods 60 s and 30 s: the same int tau^2 dt over the 7.5 s cycle
        assert value**2 * 60.0 == pytest.approx(rms[120.0][name] ** 2 * 30.0, rel=1e-12)
        assert value > 0.0
    assert hourly[60.0] is not None and hourly[120.0] is not None
    for name, value in hourly[60.0].items():
        assert value == pytest.approx(hourly[120.0][name], rel=1e-12) and value > 0.0
