"""MuJoCo inverse dynamics: power balance, virtual work at rest, agreement with the trigonometric path, bad input."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lengths_helper import feasible_lengths

from hiab_sim.crane import mechanism
from hiab_sim.crane.description import ChainLengths, Crane, LinkLengths
from hiab_sim.crane.loader import load_crane
from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics, mechanical_energy
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.errors import InvalidInputError

CRANE = load_crane("xs031")
LOW = np.array([CRANE.lift.joint_range[0], CRANE.tilt.joint_range[0], CRANE.telescope.joint_range[0]])
HIGH = np.array([CRANE.lift.joint_range[1], CRANE.tilt.joint_range[1], CRANE.telescope.joint_range[1]])


def sweep(t: np.ndarray, duration: float = 4.0) -> JointSamples:
    """Smooth motion from 3 % to 97 % of every joint's range and back, phases shifted, over ``duration`` [s]."""
    w = 2.0 * np.pi / duration
    phase = np.array([0.0, 0.6, 1.3])
    mid, amp = (LOW + HIGH) / 2.0, 0.47 * (HIGH - LOW)
    arg = w * np.asarray(t, dtype=float)[:, None] + phase
    return JointSamples(mid - amp * np.cos(arg), amp * w * np.sin(arg), amp * w**2 * np.cos(arg))


def power_residual(inverse: MujocoInverseDynamics, t: np.ndarray, h: float = 1e-4) -> tuple[float, float]:
    """Largest |sum f v - dE/dt| relative to the peak |sum f v|; dE/dt from MuJoCo's energies at t +- h."""
    power = inverse(sweep(t)).power.sum(axis=1)
    after, before = (sum(inverse.energy(sweep(t + s))) for s in (h, -h))
    rate = (after - before) / (2.0 * h)
    peak = float(np.max(np.abs(power)))
    return float(np.max(np.abs(power - rate))) / peak, peak


def test_power_balance_along_the_working_range(crane: Crane) -> None:
    """Eq. dynamics: sum f_x v_x = d/dt (kinetic + potential) to 1e-6 of peak power, default lengths."""
    t = np.linspace(0.0, 4.0, 41)
    joints = sweep(t)
    assert np.all(joints.position.min(axis=0) < LOW + 0.04 * (HIGH - LOW))
    assert np.all(joints.position.max(axis=0) > HIGH - 0.04 * (HIGH - LOW))
    residual, peak = power_residual(MujocoInverseDynamics(crane), t)
    assert peak > 1e3
    assert residual < 1e-6


@settings(max_examples=20, deadline=None)
@given(st.lists(st.floats(0.0, 1.0), min_size=6, max_size=6).map(np.array))
def test_power_balance_for_random_link_lengths(u: np.ndarray) -> None:
    """The power balance holds for any feasible link-length set (few samples per set)."""
    residual, _ = power_residual(MujocoInverseDynamics(CRANE, feasible_lengths(u)), np.linspace(0.0, 4.0, 9))
    assert residual < 1e-6


def test_actuator_motion_agrees_with_the_trigonometric_path(crane: Crane) -> None:
    """x, v_x, a_x from MuJoCo's kinematics equal those of eqs. qus .. DDthetas (independent path)."""
    lengths = feasible_lengths(np.full(6, 0.4))
    joints = sweep(np.linspace(0.0, 4.0, 25))
    out = MujocoInverseDynamics(crane, lengths)(joints)
    for k, chain in enumerate(crane.chains):
        x, v, a = mechanism.joint_to_actuator(
            chain, getattr(lengths, chain.name), joints.position[:, k], joints.velocity[:, k], joints.acceleration[:, k]
        )
        np.testing.assert_allclose(out.stroke[:, k], x, atol=1e-12)
        np.testing.assert_allclose(out.velocity[:, k], v, atol=1e-11)
        np.testing.assert_allclose(out.acceleration[:, k], a, atol=1e-10)
    np.testing.assert_array_equal(out.stroke[:, 2], joints.position[:, 2])


def _potential(inverse: MujocoInverseDynamics, theta: np.ndarray, load: np.ndarray) -> tuple[float, np.ndarray]:
    """Own potential V = sum m g z_com - F . p_tcp [J] at a loop-consistent pose, and the strokes there."""
    qpos, _, _ = inverse.state(JointSamples.at_rest(theta[None]))
    model, data = inverse.model, mujoco.MjData(inverse.model)
    data.qpos[:] = qpos[0]
    mujoco.mj_kinematics(model, data)
    gravity = CRANE.gravity * float(model.body_mass @ data.xipos[:, 2])
    payload = -float(load @ data.site("tcp").xpos)
    strokes = qpos[0, [model.joint(n).qposadr[0] for n in ("x1", "x2", "xt2")]]
    return gravity + payload, strokes


@pytest.mark.parametrize("payload", [0.0, 300.0])
def test_static_forces_are_the_virtual_work_of_gravity(crane: Crane, payload: float) -> None:
    """At rest f = dV/dx (virtual work: f . dx = dV), from potential energy alone, with and without a payload.

    V is differentiated along each joint by central differences and mapped to the actuator coordinates
    with the stroke Jacobian G = dx/dtheta, dV/dx = G^-T dV/dtheta.
    """
    inverse = MujocoInverseDynamics(crane)
    tcp_force = np.array([0.0, -payload * crane.gravity, 0.0])
    load = np.array([tcp_force[0], -tcp_force[2], tcp_force[1]])  # {W} -> MuJoCo world
    h = 1e-6
    for fraction in (0.2, 0.5, 0.8):
        theta = LOW + fraction * (HIGH - LOW)
        grad, jac = np.empty(3), np.empty((3, 3))
        for j in range(3):
            step = np.zeros(3)
            step[j] = h
            (vp, xp), (vm, xm) = _potential(inverse, theta + step, load), _potential(inverse, theta - step, load)
            grad[j], jac[:, j] = (vp - vm) / (2 * h), (xp - xm) / (2 * h)
        expected = np.linalg.solve(jac.T, grad)
        force = inverse(JointSamples.at_rest(theta[None]), tcp_force=tcp_force).force[0]
        np.testing.assert_allclose(force, expected, rtol=1e-6, atol=1e-6 * np.abs(expected).max())


def test_energy_is_kinetic_plus_potential_and_zero_kinetic_at_rest(crane: Crane) -> None:
    """mechanical_energy = potential + kinetic; at rest the kinetic part vanishes."""
    inverse = MujocoInverseDynamics(crane)
    rest = JointSamples.at_rest((LOW + HIGH)[None] / 2.0)
    potential, kinetic = inverse.energy(rest)
    assert kinetic[0] == 0.0
    assert mechanical_energy(crane, None, rest)[0] == pytest.approx(potential[0], rel=1e-14)


def test_samples_are_independent_and_the_object_reusable(crane: Crane) -> None:
    """Perturbing one sample changes only its row; repeated calls give identical results."""
    inverse = MujocoInverseDynamics(crane)
    joints = sweep(np.linspace(0.0, 4.0, 7))
    first = inverse(joints).force
    np.testing.assert_array_equal(inverse(joints).force, first)
    position = joints.position.copy()
    position[3, 1] += 1e-3
    changed = inverse(JointSamples(position, joints.velocity, joints.acceleration)).force
    np.testing.assert_array_equal(np.delete(changed, 3, axis=0), np.delete(first, 3, axis=0))
    assert np.any(changed[3] != first[3])


@pytest.mark.parametrize(
    ("column", "value", "field"),
    [(0, 3.0, "theta1"), (1, 0.5, "theta2"), (2, 1.5, "xt2"), (2, -0.1, "xt2")],
)
def test_out_of_range_joint_samples_name_the_field(crane: Crane, column: int, value: float, field: str) -> None:
    """A joint sample outside its range raises InvalidInputError naming the joint, before MuJoCo runs."""
    position = np.tile((LOW + HIGH) / 2.0, (4, 1))
    position[2, column] = value
    with pytest.raises(InvalidInputError) as error:
        MujocoInverseDynamics(crane)(JointSamples.at_rest(position))
    assert error.value.field == field


def test_nan_input_names_the_field(crane: Crane) -> None:
    """NaN in joint samples or in the TCP force raises InvalidInputError naming the field."""
    position = np.tile((LOW + HIGH) / 2.0, (2, 1))
    with pytest.raises(InvalidInputError, match=r"joints\.velocity"):
        JointSamples(position, np.full((2, 3), np.nan), np.zeros((2, 3)))
    with pytest.raises(InvalidInputError, match="tcp_force"):
        MujocoInverseDynamics(crane)(JointSamples.at_rest(position), tcp_force=[0.0, np.nan, 0.0])


def test_infeasible_lengths_name_the_field(crane: Crane) -> None:
    """Lengths that cannot serve the working range raise InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError, match=r"tilt\.joint_range"):
        MujocoInverseDynamics(crane, LinkLengths(crane.default_lengths.lift, ChainLengths(1.0, 0.085, 0.745)))


def test_qfrc_inverse_at_a_cylinder_slide_is_not_the_cylinder_force(crane: Crane) -> None:
    """qfrc_inverse at a cylinder slide is not the cylinder force (the trap the projection avoids).

    With the soft loops on, mj_inverse on a loop-consistent state puts almost no force in the
    connect constraints, so qfrc_inverse at x1/x2 is a small fraction of the cylinder force.
    """
    from hiab_sim.model.mjcf import build_model

    t = np.linspace(0.0, 4.0, 9)
    inverse = MujocoInverseDynamics(crane)
    forces = inverse(sweep(t)).force
    qpos, qvel, qacc = inverse.state(sweep(t))
    model = build_model(crane)
    data = mujoco.MjData(model)
    naive = np.zeros((len(t), 2))
    for k in range(len(t)):
        data.qpos[:], data.qvel[:], data.qacc[:] = qpos[k], qvel[k], qacc[k]
        mujoco.mj_inverse(model, data)
        naive[k] = [data.qfrc_inverse[model.joint(name).dofadr[0]] for name in ("x1", "x2")]
    assert np.max(np.abs(naive) / np.abs(forces[:, :2])) < 0.01  # measured: ~110 N against 37-142 kN
    assert np.min(np.abs(forces[:, :2])) > 1e4  # the cylinders carry tens of kN
