"""B-spline trajectories, the spiral reference, planar TCP kinematics and inverse kinematics."""

from __future__ import annotations

import numpy as np
import pytest

from hiab_sim.crane import kinematics
from hiab_sim.crane.description import Crane
from hiab_sim.errors import InvalidInputError
from hiab_sim.study.motion import trajectory as tr
from hiab_sim.study.references.kinds import Spiral
from hiab_sim.study.spec.study_file import load_study

STUDY = load_study()


def test_spline_derivative_matrices_match_numerical_differentiation() -> None:
    """dB/dt and d2B/dt2 (eqs. matrix_basis_d, _dd) equal central differences of B(t)."""
    basis = tr.SplineBasis(22, 5, 6.25)
    t = np.linspace(0.05, 6.2, 37)
    h = 1e-5
    B, dB, ddB = basis.matrices(t)
    np.testing.assert_allclose(dB, (basis.matrix(t + h) - basis.matrix(t - h)) / (2 * h), atol=1e-6)
    np.testing.assert_allclose(ddB, (basis.matrix(t + h, 1) - basis.matrix(t - h, 1)) / (2 * h), atol=1e-5)
    np.testing.assert_allclose(B.sum(axis=1), 1.0, atol=1e-14)  # partition of unity


def test_design_matrix_agrees_with_vector_valued_spline() -> None:
    """Scipy's design matrix and the vector-valued BSpline give the same basis."""
    basis = tr.SplineBasis(12, 3, 2.0)
    t = np.linspace(0.0, 2.0, 9)
    np.testing.assert_allclose(basis.matrix(t), basis._spline(t), atol=1e-14)


def test_tcp_kinematics_match_forward_kinematics(crane: Crane) -> None:
    """The planar complex-number TCP equals the foundation's forward kinematics."""
    rng = np.random.default_rng(0)
    q = np.column_stack([rng.uniform(0.0, 1.2, 20), rng.uniform(-2.2, -0.3, 20), rng.uniform(0.0, 1.0, 20)])
    kin = tr.TcpKinematics(crane)
    np.testing.assert_allclose(kin.position(q), kinematics.tcp_position(crane, q[:, 0], q[:, 1], q[:, 2]), atol=1e-12)


def test_tcp_partials_match_finite_differences(crane: Crane) -> None:
    """The analytic partials of TCP position, velocity, acceleration w.r.t. (theta, dtheta, ddtheta)."""
    rng = np.random.default_rng(1)
    X = np.column_stack([rng.uniform(0.2, 1.0, 6), rng.uniform(-2.0, -0.5, 6), rng.uniform(0.1, 0.9, 6)])
    X = np.concatenate([X, rng.normal(size=(6, 6))], axis=1)
    kin = tr.TcpKinematics(crane)

    def f(x: np.ndarray) -> np.ndarray:
        s = kin.samples(x[:, 0:3], x[:, 3:6], x[:, 6:9])
        return np.stack([s.position, s.velocity, s.acceleration])

    s = kin.samples(X[:, 0:3], X[:, 3:6], X[:, 6:9])
    for j in range(9):
        h = 1e-6
        xp, xm = X.copy(), X.copy()
        xp[:, j] += h
        xm[:, j] -= h
        fd = (f(xp) - f(xm)) / (2 * h)
        exact = np.stack([s.d_position[:, :, j], s.d_velocity[:, :, j], s.d_acceleration[:, :, j]])
        np.testing.assert_allclose(exact, fd, atol=1e-7)


def test_spiral_starts_and_ends_at_rest_and_is_consistent() -> None:
    """Velocity and acceleration vanish at both ends; they are the time derivatives of the path."""
    kin = tr.TcpKinematics(STUDY.crane)
    t = np.linspace(0.0, 6.25, 2001)
    ref = STUDY.reference.sample(kin, t)
    for rate in (ref.velocity, ref.acceleration):
        np.testing.assert_allclose(rate[[0, -1]], 0.0, atol=1e-12)
    dt = t[1] - t[0]
    np.testing.assert_allclose(np.gradient(ref.position, dt, axis=0)[2:-2], ref.velocity[2:-2], atol=2e-5)
    np.testing.assert_allclose(np.gradient(ref.velocity, dt, axis=0)[2:-2], ref.acceleration[2:-2], atol=2e-4)
    radius = np.hypot(ref.position[:, 0] - ref.centre[0], ref.position[:, 1] - ref.centre[1])
    assert radius[0] == pytest.approx(0.05) and radius[-1] == pytest.approx(0.4)


def test_inverse_kinematics_puts_the_tcp_on_the_reference() -> None:
    """IK joints reproduce the reference position, velocity and acceleration exactly."""
    kin = tr.TcpKinematics(STUDY.crane)
    t = np.linspace(0.0, 6.25, 101)
    ref = STUDY.reference.sample(kin, t)
    ik = tr.inverse_kinematics(kin, ref, (0.6, -1.3))
    s = kin.samples(ik.position, ik.velocity, ik.acceleration)
    np.testing.assert_allclose(s.position, ref.position, atol=1e-10)
    np.testing.assert_allclose(s.velocity, ref.velocity, atol=1e-10)
    np.testing.assert_allclose(s.acceleration, ref.acceleration, atol=1e-9)


def test_fitted_spline_is_at_rest_and_tracks_within_a_millimetre() -> None:
    """The initial coefficients: rest at both ends, TCP within 0.2 mm of the spiral on a fine grid."""
    kin = tr.TcpKinematics(STUDY.crane)
    basis = tr.SplineBasis(22, 5, 6.25)
    t = STUDY.grid.fine_times()
    ref = STUDY.reference.sample(kin, t)
    c = tr.fit_coefficients(basis, tr.inverse_kinematics(kin, ref, (0.6, -1.3)))
    joints = tr.evaluate(basis, c, t)
    np.testing.assert_allclose(joints.velocity[[0, -1]], 0.0, atol=1e-10)
    np.testing.assert_allclose(joints.acceleration[[0, -1]], 0.0, atol=1e-9)
    s = kin.samples(joints.position, joints.velocity, joints.acceleration)
    assert np.max(np.abs(s.position - ref.position)) < 2e-4


def test_unreachable_reference_is_rejected() -> None:
    """A spiral beyond the crane's reach raises the named-field error."""
    kin = tr.TcpKinematics(STUDY.crane)
    spec = Spiral(
        duration=6.25,
        start_radius=0.05,
        end_radius=6.0,
        turns=1.0,
        telescope_start=0.4,
        start_angle=0.0,
        telescope_amplitude=0.0,
        centre_joints=(0.6, -1.3),
    )
    ref = spec.sample(kin, np.linspace(0.0, 6.25, 60))
    with pytest.raises(InvalidInputError, match="reference"):
        tr.inverse_kinematics(kin, ref, (0.6, -1.3))
