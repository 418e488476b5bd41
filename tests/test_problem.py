"""The NLP of eq. costf2: gradients vs finite differences, the cost vs an independent quadrature, bad starts."""

from __future__ import annotations

import numpy as np
import pytest
from test_study_small import small_study

from hiab_sim.crane.description import ChainLengths, LinkLengths
from hiab_sim.dynamics.analytic_id import analytic_inverse_dynamics
from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.emla import electrical_power, load_emla_set
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.study.nlp import task_problem as problem_module
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.solvers.slsqp import START_TOLERANCE, check_start, start_points
from hiab_sim.study.spec.study_file import load_study, study_from_dict

STUDY = study_from_dict(small_study(), "small.yaml")


@pytest.fixture(scope="module", params=["analytic", "mujoco"])
def problem(request: pytest.FixtureRequest) -> TaskProblem:
    """The small study's NLP on either inverse-dynamics path."""
    return TaskProblem(STUDY, id_path=request.param)


def _point(problem: TaskProblem) -> np.ndarray:
    rng = np.random.default_rng(3)
    z = problem.initial_point(start_points(problem, 2)[1])
    return z + np.concatenate([np.zeros(6), rng.normal(0.0, 0.02, problem.n_c)])


def _central(fun, z: np.ndarray, i: int, h: float) -> np.ndarray:  # type: ignore[no-untyped-def]
    zp, zm = z.copy(), z.copy()
    zp[i] += h
    zm[i] -= h
    return (np.asarray(fun(zp)) - np.asarray(fun(zm))) / (2.0 * h)


def test_cost_gradient_matches_finite_differences(problem: TaskProblem) -> None:
    """D f / dz (ID partials batched, chained through the B-spline matrices) equals central differences."""
    z = _point(problem)
    grad = problem.cost_gradient(z)
    fd = np.array([_central(problem.cost, z, i, 1e-5 if i < 6 else 1e-4) for i in range(problem.n)])
    np.testing.assert_allclose(grad, fd, atol=1e-5 * np.max(np.abs(grad)), rtol=1e-4)


def test_constraint_jacobian_matches_finite_differences(problem: TaskProblem) -> None:
    """D g / dz for every constraint row, Xi and spline-coefficient columns alike."""
    z = _point(problem)
    jac = problem.constraints_jacobian(z)
    cols = [*range(6), *range(6, problem.n, 5)]
    for i in cols:
        fd = _central(problem.constraints, z, i, 1e-5 if i < 6 else 1e-4)
        np.testing.assert_allclose(jac[:, i], fd, atol=2e-5 * np.max(np.abs(jac[:, i])) + 1e-7, err_msg=f"column {i}")


def test_per_sample_rows_on_the_spline_band_equal_the_full_spline_product() -> None:
    """A per-sample block's rows chained through B on its band are the product with the full (3, K, N) matrices.

    The full product sum_o dq[k, m, o, j] B[o, k, n] over every column n, zeros outside each
    sample's support included, is the plain reading of the chain rule; the problem multiplies only
    the W columns per sample where B is nonzero and writes them into the Jacobian's rows in place.
    """
    from hiab_sim.study.nlp.interface import SampleRows
    from hiab_sim.study.nlp.task_problem import C_SCALE, XI_SCALE

    p = TaskProblem(STUDY, id_path="analytic")
    K, nj, r = len(p.times), p.n_joints, 4
    rng = np.random.default_rng(7)
    jac = SampleRows(dq=rng.normal(size=(K, r, 3 * nj)), dxi=rng.normal(size=(K, r, p.n_xi)))
    out = np.zeros((K * r, p.n))
    p._to_z(None, jac, out)  # type: ignore[arg-type]  (the block is not read for sample rows)
    full = np.zeros((K, r, nj, p.basis.n))
    for o in range(3):
        for j in range(nj):
            full[:, :, j, :] += jac.dq[:, :, o * nj + j, None] * p.B[o][:, None, :]
    np.testing.assert_allclose(out[:, p.n_xi :], full.reshape(K * r, p.n_c) * C_SCALE, rtol=1e-14, atol=1e-14)
    np.testing.assert_array_equal(out[:, : p.n_xi], jac.dxi.reshape(K * r, p.n_xi) * XI_SCALE)
    assert p.chain.band.shape[2] == STUDY.spline.degree + 1  # the band of a B-spline: degree + 1 functions per sample


def test_equality_jacobian_is_exact(problem: TaskProblem) -> None:
    """The rest-to-rest equalities are linear in c; their jacobian reproduces them."""
    z = _point(problem)
    jac = problem.equalities_jacobian(z)
    z0 = problem.initial_point(STUDY.initial_lengths)
    np.testing.assert_allclose(problem.equalities(z) - problem.equalities(z0), jac @ (z - z0), atol=1e-9)


@pytest.mark.parametrize("path", ["analytic", "mujoco"])
def test_cost_equals_a_quadrature_of_power_from_the_other_id_path(path: str) -> None:
    """F = 1/2 Dt sum_k (sum_i P_i(t_k))^2 with P from the EMLA model fed by the *other* ID path's forces.

    The joint samples at z are taken from the problem; the forces are recomputed by calling the other
    inverse-dynamics implementation directly, and Dt is the grid's spacing (6.25 s / 12 intervals).
    """
    problem = TaskProblem(STUDY, id_path=path)
    ev = problem.evaluate(_point(problem))
    joints = JointSamples(ev.joints.position, ev.joints.velocity, ev.joints.acceleration)
    if path == "analytic":
        act = MujocoInverseDynamics(STUDY.crane, ev.lengths)(joints)
    else:
        act = analytic_inverse_dynamics(STUDY.crane, ev.lengths, joints)
    power = sum(
        electrical_power(p, act.force[:, i], act.velocity[:, i], act.acceleration[:, i])
        for i, p in enumerate(load_emla_set())
    )
    assert len(power) == 13 and np.ptp(power) > 1e3  # a real power history, not a constant
    assert ev.cost == pytest.approx(0.5 * (6.25 / 12) * np.sum(power**2), rel=1e-10)
    np.testing.assert_allclose(ev.power.sum(axis=1), power, rtol=1e-10, atol=1e-6)
    assert len(ev.constraints) == len(problem.constraint_names)


def test_default_collocation_grid_has_26_points_a_quarter_second_apart() -> None:
    """T = {0, 0.25, ..., 6.25} s (M = 25): 26 points, Dt = 0.25 s, on the default study's problem."""
    study = load_study()
    times = study.grid.times()
    assert len(times) == 26 and times[0] == 0.0 and times[-1] == 6.25
    problem = TaskProblem(study, id_path="analytic", cost_scale=1.0)
    assert problem.dt == 0.25
    np.testing.assert_allclose(np.diff(problem.times), 0.25, rtol=0, atol=1e-15)


def test_cost_of_known_powers_matches_a_hand_computation(monkeypatch: pytest.MonkeyPatch) -> None:
    """The cost of known powers on 26 points 0.25 s apart equals its hand value, 690.625 W^2 s.

    With P_lift(t_k) = k W, P_tilt = 100 W, P_telescope = -100 W: sum_i P_i = k and
    f = 1/2 * 0.25 s * sum_{k=0}^{25} k^2 W^2 = 0.125 * 5525 = 690.625 W^2 s, a rectangle sum over all
    26 points (the seed's form), not a trapezoid (which gives 651.5625 W^2 s).
    """
    powers = iter(())

    def fake_power(params, force, velocity, acceleration):  # type: ignore[no-untyped-def]
        return next(powers)

    monkeypatch.setattr(problem_module, "electrical_power", fake_power)
    problem = TaskProblem(STUDY, id_path="analytic", times=np.linspace(0.0, 6.25, 26), cost_scale=1.0)
    powers = iter([np.arange(26.0), np.full(26, 100.0), np.full(26, -100.0)])
    ev = problem.evaluate(problem.initial_point(STUDY.initial_lengths))
    assert ev.cost == 690.625
    np.testing.assert_array_equal(ev.power.sum(axis=1), np.arange(26.0))
    assert problem.cost(ev.z) == 690.625  # cost_scale = 1


def test_built_crane_is_a_start_with_no_violation() -> None:
    """The built XS 031 (strokes exactly 0 at the low end of the working range) starts with violation ~0.

    The optimiser's working-range clearance is not a constraint of the start.
    """
    problem = TaskProblem(STUDY, id_path="analytic")
    z0 = problem.initial_point(STUDY.initial_lengths)
    assert problem.max_violation(z0) <= 1e-9
    assert problem.margins(z0).min() >= -1e-12
    check_start(problem, z0)
    assert START_TOLERANCE <= 1e-9


def test_start_violating_a_constraint_names_it() -> None:
    """A start whose stroke leaves [0, stroke] is rejected with the constraint's name."""
    problem = TaskProblem(STUDY, id_path="analytic")
    bad = LinkLengths(ChainLengths(1.0071227324212, 0.2, 0.745), STUDY.initial_lengths.tilt)
    with pytest.raises(InvalidInputError, match=r"initial_lengths .*lift"):
        check_start(problem, problem.initial_point(bad))


def test_start_violating_a_constraint_by_a_small_real_amount_is_rejected() -> None:
    """Lc0 + 10 um makes the lift stroke -1e-5 m at the low end of the working range: -1e-4 scaled, rejected."""
    problem = TaskProblem(STUDY, id_path="analytic")
    built = STUDY.initial_lengths.lift
    bad = LinkLengths(ChainLengths(built.L, built.Lc0 + 1e-5, built.Lc), STUDY.initial_lengths.tilt)
    z = problem.initial_point(bad)
    assert problem.max_violation(z) == pytest.approx(1e-4, rel=1e-6)
    with pytest.raises(InvalidInputError, match=r"working_range\.lift\.x >= 0 at the low end") as info:
        check_start(problem, z)
    assert info.value.value == pytest.approx(-1e-4, rel=1e-6)


@pytest.mark.parametrize(
    ("change", "error", "field"),
    [
        ({"spline": {"control_points": 16, "degree": 2}}, InvalidInputError, "spline.degree"),
        ({"grid": {"duration": -1.0}}, InvalidInputError, "grid.duration"),
        ({"solver": {"id_path": "magic"}}, InvalidInputError, "solver.id_path"),
        ({"typo": 1}, ConfigError, "typo"),
        ({"reference": {"start_radius": 0.1}}, ConfigError, "missing"),
    ],
)
def test_malformed_study_names_the_field(change: dict, error: type, field: str) -> None:
    """Unknown keys, missing keys and out-of-range values name the field."""
    with pytest.raises(error, match=field):
        study_from_dict(small_study(**change), "bad.yaml")
