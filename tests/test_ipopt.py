"""The IPOPT backend's own NLP: two-sided range rows, the sparse Jacobian assembly, and a solve against SLSQP."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from test_mix import LOCAL_SPREAD, two_tasks

from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.errors import HiabSimError, InvalidInputError
from hiab_sim.study.nlp.id_partials import id_length_partials
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.nlp.task_problem import XI_SCALE
from hiab_sim.study.solvers.slsqp import solve
from hiab_sim.study.solvers.sparse_rows import SparseJacobian, range_pairs, task_rows, task_z
from hiab_sim.study.spec.study_file import study_from_dict


@pytest.fixture(scope="module")
def mix() -> StudyProblem:
    return StudyProblem(study_from_dict(two_tasks(), "two.yaml"))


def _points(mix: StudyProblem, count: int) -> list[np.ndarray]:
    """Admissible points around the start: Xi moved by up to +-5 mm, every coefficient perturbed.

    The built crane's tilt chain uses its whole stroke, so some moves of Xi leave no working range:
    those draws are skipped (fixed seed, so the points are the same on every run).
    """
    rng = np.random.default_rng(7)
    z0 = mix.initial_point(mix.study.initial_lengths)
    out: list[np.ndarray] = []
    while len(out) < count:
        z = z0.copy()
        z[:6] += rng.uniform(-5e-3, 5e-3, 6) / XI_SCALE
        z[6:] += rng.normal(0.0, 5e-3, len(z) - 6)
        try:
            mix.evaluate(z)
        except InvalidInputError:
            continue
        out.append(z)
    return out


def test_range_pairs_add_up_to_a_constant_and_have_opposite_jacobians(mix: StudyProblem) -> None:
    """Every declared pair (a, b): g_a + g_b is the same at points with other Xi and coefficients; D g_a = -D g_b."""
    points = _points(mix, 3)
    for k, p in enumerate(mix.problems):
        first, second = range_pairs(p)
        assert len(first) == 17 * len(p.times)  # tracking 9, joint 3, joint velocity 3, stroke 2 per sample
        sums = [p.constraints(task_z(mix, z, k))[first] + p.constraints(task_z(mix, z, k))[second] for z in points]
        spread = np.abs(sums[0] - sums[1]).max(), np.abs(sums[0] - sums[2]).max()
        assert max(spread) <= 1e-12 * np.abs(sums[0]).max()
        assert np.ptp([p.constraints(task_z(mix, z, k))[first] for z in points], axis=0).max() > 1e-3  # rows move
        jac = p.constraints_jacobian(task_z(mix, points[0], k))
        np.testing.assert_array_equal(jac[first], -jac[second])


def test_sparse_jacobian_holds_the_dense_jacobians_rows_and_each_pair_once(mix: StudyProblem) -> None:
    """Values, rows and bounds of the IPOPT NLP against the mix's dense assembly, row for row."""
    z0, z = _points(mix, 2)
    jac = SparseJacobian(mix, z0)
    dense, g = mix.constraints_jacobian(z), mix.constraints(z)
    held = []
    start = 0
    for t, kept in zip(task_rows(mix), mix.rows, strict=True):
        position = {row: i for i, row in enumerate(kept)}
        held += [start + position[row] for row in t.rows]
        start += len(kept)
    held_rows = np.array(held)
    # the values' buffer is overwritten point after point: a first point's values must not leak into the next
    np.testing.assert_array_equal(
        jac.dense(z0), np.vstack([mix.equalities_jacobian(z0), mix.constraints_jacobian(z0)[held_rows]])
    )
    np.testing.assert_array_equal(jac.dense(z), np.vstack([mix.equalities_jacobian(z), dense[held_rows]]))
    np.testing.assert_array_equal(jac.rows(z), np.concatenate([mix.equalities(z), g[held_rows]]))
    pairs = sum(len(range_pairs(p)[0]) for p in mix.problems)
    assert jac.shape[0] == len(mix.equality_names) + len(g) - pairs
    upper = jac.upper(z0)[jac.m_eq :]
    assert np.isinf(upper).sum() == len(g) - 2 * pairs and np.all(upper[np.isfinite(upper)] > 0.0)
    # a two-sided row's upper bound less its value is its dropped partner's row, at any point
    partners = np.concatenate(
        [
            p.constraints(task_z(mix, z, k))[t.partner[t.partner >= 0]]
            for k, (p, t) in enumerate(zip(mix.problems, task_rows(mix), strict=True))
        ]
    )
    paired = np.isfinite(upper)
    np.testing.assert_allclose(upper[paired] - jac.rows(z)[jac.m_eq :][paired], partners, atol=1e-12)


def test_length_partials_on_the_stacked_analytic_path_equal_mujocos_per_design_models(mix: StudyProblem) -> None:
    """dY/dXi with a per-sample payload force: 12 stacked analytic designs against 12 MuJoCo models (1e-6 relative)."""
    p = mix.problems[1]  # the task with the payload schedule
    ev = p.evaluate(task_z(mix, _points(mix, 1)[0], 1))
    samples = JointSamples(ev.joints.position, ev.joints.velocity, ev.joints.acceleration)
    assert np.ndim(p.tcp_force) == 2
    analytic = id_length_partials(p.crane, ev.lengths, samples, "analytic", 1e-6, p.tcp_force)
    mujoco = id_length_partials(p.crane, ev.lengths, samples, "mujoco", 1e-6, p.tcp_force)
    assert np.abs(mujoco).max() > 1e3
    np.testing.assert_allclose(analytic, mujoco, atol=1e-6 * np.abs(mujoco).max())


@pytest.mark.e2e
def test_ipopt_and_dense_slsqp_reach_the_same_design_of_the_two_task_mix() -> None:
    """Two solvers, two Jacobian assemblies (sparse two-sided rows vs dense one-sided): same Xi, feasible, same cost."""
    pytest.importorskip("casadi")
    out = {}
    for method in ("slsqp", "ipopt"):
        # the paper's smooth EMLA model: the drive losses' steep brake smoothing spreads local optima beyond 1e-4
        study = study_from_dict({**two_tasks(method=method), "emla": "paper"}, "two.yaml")
        problem = StudyProblem(study)
        result = solve(problem, study.initial_lengths, progress=None)
        assert problem.max_violation(result.z) <= 1e-6
        out[method] = (problem.cost(result.z), problem.unpack(result.z)[0].as_array())
    assert out["ipopt"][0] == pytest.approx(out["slsqp"][0], rel=LOCAL_SPREAD)
    np.testing.assert_allclose(out["ipopt"][1], out["slsqp"][1], atol=1e-3)


def test_sparse_jacobian_of_a_machine_with_nine_design_variables_is_the_dense_one() -> None:
    """The excavator (9 design variables, 3 joints): IPOPT's pattern and columns hold every nonzero of the rows."""
    from hiab_sim.study import load_study

    study = StudyProblem(load_study("exact_grading"))
    assert study.n_xi == 9
    z0 = study.initial_point(study.study.initial_lengths)
    rng = np.random.default_rng(3)
    z = z0.copy()
    z[: study.n_xi] += rng.uniform(-1e-3, 1e-3, study.n_xi) / XI_SCALE
    z[study.n_xi :] += rng.normal(0.0, 1e-3, len(z) - study.n_xi)
    jac = SparseJacobian(study, z0)
    (t,) = task_rows(study)
    position = {row: i for i, row in enumerate(study.rows[0])}
    held = np.array([position[row] for row in t.rows])
    dense = study.constraints_jacobian(z)[held]
    assert np.count_nonzero(dense[:, study.n_xi - 3 : study.n_xi]) > 0  # the design variables past the sixth move rows
    np.testing.assert_array_equal(jac.dense(z), np.vstack([study.equalities_jacobian(z), dense]))


def test_the_studys_lbfgs_history_is_the_one_ipopt_keeps(monkeypatch: pytest.MonkeyPatch) -> None:
    """``solver.lbfgs_history`` reaches IPOPT's ``limited_memory_max_history``; IPOPT's own default 6 otherwise."""
    casadi = pytest.importorskip("casadi")
    seen: list[dict] = []

    class StopError(Exception):
        pass

    def nlpsol(name: str, plugin: str, nlp: dict, options: dict) -> None:
        seen.append(options)
        raise StopError

    monkeypatch.setattr(casadi, "nlpsol", nlpsol)
    for solver, expected in (({"method": "ipopt"}, 6), ({"method": "ipopt", "lbfgs_history": 37}, 37)):
        problem = StudyProblem(study_from_dict(two_tasks(**solver), "two.yaml"))
        with pytest.raises(StopError):
            solve(problem, problem.study.initial_lengths, progress=None)
        assert seen[-1]["ipopt.limited_memory_max_history"] == expected


def test_an_ipopt_solve_prints_nothing_on_stdout() -> None:
    """IPOPT's licence banner is off: a solve in a fresh process (the banner comes once per process) writes no stdout.

    The banner is C-level output, so the solve runs in a subprocess whose stdout is read whole.
    """
    pytest.importorskip("casadi")
    script = (
        "import sys; sys.path.insert(0, 'tests')\n"
        "from test_mix import two_tasks\n"
        "from hiab_sim.study.nlp.problem import StudyProblem\n"
        "from hiab_sim.study.solvers.slsqp import solve\n"
        "from hiab_sim.study.spec.study_file import study_from_dict\n"
        "p = StudyProblem(study_from_dict(two_tasks(method='ipopt', maxiter=3), 'two.yaml'))\n"
        "from hiab_sim.errors import SolverError\n"
        "try:\n"
        "    solve(p, p.study.initial_lengths, progress=None)\n"
        "except SolverError:\n"  # three iterations do not converge: the banner comes at the first
        "    pass\n"
    )
    root = Path(__file__).resolve().parents[1]
    done = subprocess.run([sys.executable, "-c", script], cwd=root, capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout == ""


@pytest.mark.parametrize("value", [0, 2.5, "many", 501])
def test_a_bad_lbfgs_history_names_the_field(value: object) -> None:
    """0, a fraction, a word or more than 500 pairs: one line naming ``solver.lbfgs_history`` and the value."""
    with pytest.raises(HiabSimError, match=rf"solver\.lbfgs_history.*{value}"):
        study_from_dict(two_tasks(method="ipopt", lbfgs_history=value), "two.yaml")


def test_a_jacobian_written_point_after_point_into_one_buffer_is_the_fresh_one(mix: StudyProblem) -> None:
    """With ``jacobian_buffer`` set, each point's Jacobian overwrites the last in place and equals a new one."""
    points = _points(mix, 3)
    fresh = [[p.constraints_jacobian(task_z(mix, z, k)).copy() for k, p in enumerate(mix.problems)] for z in points]
    again = StudyProblem(mix.study)  # no cached gradients
    for p in again.problems:
        p.jacobian_buffer = np.zeros((len(p.constraint_names), p.n))
    for z, expected in zip([*points, points[0]], [*fresh, fresh[0]], strict=True):
        for k, p in enumerate(again.problems):
            got = p.constraints_jacobian(task_z(again, z, k))
            assert got is p.jacobian_buffer
            np.testing.assert_array_equal(got, expected[k])


def test_a_trial_point_outside_the_models_domain_is_an_evaluation_error_ipopt_backs_off_from(
    mix: StudyProblem, capfd: pytest.CaptureFixture[str]
) -> None:
    """An objective that leaves the domain past a radius: IPOPT cuts its steps back and ends inside it.

    The objective |z - z_target|^2 with z_target outside the domain (InvalidInputError beyond 2 mm of
    the start, less than the 10 mm the rows let the last coefficient move): IPOPT's trials cross the
    edge, it backs off and ends inside with a lower objective; CasADi prints no Python traceback, and a solve
    that starts outside says why in its message.
    """
    pytest.importorskip("casadi")
    from hiab_sim.study.solvers.ipopt import solve_ipopt

    z0 = mix.initial_point(mix.study.initial_lengths)
    step = np.zeros_like(z0)
    step[-1] = 1.0  # the last spline coefficient: the model itself stays in its domain
    target, radius = z0 + step, 2e-3
    outside: list[float] = []

    def value(z: np.ndarray) -> float:
        if np.linalg.norm(z - z0) > radius:
            outside.append(float(np.linalg.norm(z - z0)))
            raise InvalidInputError("design", "a trial point", "inside the domain (a test's edge)")
        return float(np.sum((z - target) ** 2))

    def gradient(z: np.ndarray) -> np.ndarray:
        value(z)
        return 2.0 * (z - target)

    outcome = solve_ipopt(mix, z0, 12, 1e-9, objective=(value, gradient))  # 12 iterations cross the edge (50: 9 s)
    assert outside  # some trial crossed the edge
    assert np.linalg.norm(outcome.z - z0) <= radius  # every point it kept was inside
    assert np.linalg.norm(outcome.z - target) < np.linalg.norm(z0 - target)  # and it made progress
    failed = solve_ipopt(mix, z0 + 2 * radius * step, 5, 1e-9, objective=(value, gradient))
    assert not failed.success and "outside the model's domain" in failed.message and "a test's edge" in failed.message
    assert "Traceback" not in capfd.readouterr().err
