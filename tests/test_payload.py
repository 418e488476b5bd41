"""Payload schedules: the TCP force, and the actuator-force jumps at pick and release on both ID paths."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hiab_sim.crane import kinematics, mechanism
from hiab_sim.dynamics.analytic_id import analytic_inverse_dynamics, energy_rate
from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.study.motion import trajectory as tr
from hiab_sim.study.spec.payload import Payload
from hiab_sim.study.spec.study_file import load_study

STUDY = load_study()
CRANE = STUDY.crane
LENGTHS = CRANE.default_lengths
KIN = tr.TcpKinematics(CRANE)
#: Picked and released while the spiral moves, so the jump carries weight and inertia.
PAYLOAD = Payload(mass=250.0, pick=1.9, release=4.4)


def _spiral(times: np.ndarray) -> tuple[tr.Reference, JointSamples]:
    ref = STUDY.reference.sample(KIN, times)
    assert STUDY.reference.centre_joints is not None
    ik = tr.inverse_kinematics(KIN, ref, STUDY.reference.centre_joints)
    return ref, JointSamples(ik.position, ik.velocity, ik.acceleration)


def _stroke_jacobian_transpose(theta: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """J_x^T (3 x 3): d p_tcp / d (x_lift, x_tilt, xt2), from the foundation FK and the chain trigonometry."""

    def tcp(q: np.ndarray) -> np.ndarray:
        return kinematics.tcp_position(CRANE, q[0], q[1], q[2]).reshape(3)

    def strokes(q: np.ndarray) -> np.ndarray:
        x = [float(mechanism.joint_to_stroke(c, getattr(LENGTHS, c.name), q[j])) for j, c in enumerate(CRANE.chains)]
        return np.array([*x, q[2]])

    J_theta = np.zeros((3, 3))
    dx_dtheta = np.zeros((3, 3))
    for j in range(3):
        step = np.zeros(3)
        step[j] = h
        J_theta[:, j] = (tcp(theta + step) - tcp(theta - step)) / (2 * h)
        dx_dtheta[:, j] = (strokes(theta + step) - strokes(theta - step)) / (2 * h)
    return np.asarray((J_theta @ np.linalg.inv(dx_dtheta)).T)


def _id_paths() -> list:
    mujoco = MujocoInverseDynamics(CRANE, LENGTHS)
    return [
        lambda joints, force: mujoco(joints, tcp_force=force),
        lambda joints, force: analytic_inverse_dynamics(CRANE, LENGTHS, joints, tcp_force=force),
    ]


@pytest.mark.parametrize("path", [0, 1], ids=["mujoco", "analytic"])
@pytest.mark.parametrize("instant", ["pick", "release"])
def test_actuator_forces_jump_by_the_payloads_weight_and_inertia(path: int, instant: str) -> None:
    """At pick and release f jumps by exactly -J_x^T m (g - a_tcp) (J_x by finite differences of the FK)."""
    t = getattr(PAYLOAD, instant)
    ref, joints = _spiral(np.array([t]))
    twice = JointSamples(*(np.repeat(a, 2, axis=0) for a in (joints.position, joints.velocity, joints.acceleration)))
    times = np.array([np.nextafter(t, -np.inf), t])  # just before, at the instant
    force = PAYLOAD.tcp_force(times, np.repeat(ref.acceleration[:, :2], 2, axis=0), CRANE.gravity)
    jump_f = force[1] - force[0]
    out = _id_paths()[path](twice, force)
    expected = -_stroke_jacobian_transpose(joints.position[0]) @ jump_f
    assert np.linalg.norm(ref.acceleration[0, :2]) > 0.1  # the jump carries inertia, not only weight
    np.testing.assert_allclose(out.force[1] - out.force[0], expected, rtol=1e-6, atol=1e-6 * np.abs(expected).max())
    # power balance across the jump: the rods' power changes by minus the power of the force step
    v_tcp = KIN.samples(joints.position, joints.velocity, joints.acceleration).velocity[0, :2]
    jump_power = (out.force[1] - out.force[0]) @ out.velocity[0]
    assert jump_power == pytest.approx(-jump_f[:2] @ v_tcp, rel=1e-9, abs=1e-9 * np.abs(jump_f).max())


@pytest.mark.parametrize("path", [0, 1], ids=["mujoco", "analytic"])
def test_power_balance_holds_with_a_payload_schedule(path: int) -> None:
    """Power balance sum f v + F . v_tcp = dE/dt (dE/dt from energies alone) before, with and after the load."""
    times = np.linspace(0.3, 6.0, 24)
    ref, joints = _spiral(times)
    force = PAYLOAD.tcp_force(times, ref.acceleration[:, :2], CRANE.gravity)
    assert 0 < np.count_nonzero(force[:, 1]) < len(times)
    out = _id_paths()[path](joints, force)
    v_tcp = KIN.samples(joints.position, joints.velocity, joints.acceleration).velocity[:, :2]
    power = out.power.sum(axis=1) + np.einsum("ti,ti->t", force[:, :2], v_tcp)
    rate = energy_rate(CRANE, LENGTHS, joints)
    assert np.max(np.abs(power - rate)) <= 1e-6 * np.max(np.abs(out.power.sum(axis=1)))


def test_constant_payload_without_inertia_is_todays_tcp_force() -> None:
    """A plain number is a constant mass; without inertia its force is the study's (0, -m g, 0)."""
    payload = Payload.from_value({"mass": 150.0, "inertia": False})
    force = payload.tcp_force(np.linspace(0.0, 1.0, 4), np.ones((4, 2)), CRANE.gravity)
    np.testing.assert_array_equal(force, np.tile([0.0, -150.0 * CRANE.gravity, 0.0], (4, 1)))
    assert Payload.from_value(150) == Payload(150.0)


@settings(max_examples=50, deadline=None)
@given(
    mass=st.floats(0.0, 2000.0),
    pick=st.floats(0.0, 10.0),
    hold=st.floats(1e-3, 10.0),
    t=st.lists(st.floats(0.0, 25.0), min_size=1, max_size=20),
)
def test_mass_is_held_from_pick_until_release(mass: float, pick: float, hold: float, t: list[float]) -> None:
    """m(t) = m exactly for pick <= t < release and 0 elsewhere; at rest the force is the weight along -y."""
    release = pick + hold
    payload = Payload(mass, pick, release)
    times = np.array(t)
    held = (times >= pick) & (times < release)
    np.testing.assert_array_equal(payload.mass_at(times), np.where(held, mass, 0.0))
    force = payload.tcp_force(times, np.zeros((len(times), 2)), 9.81)
    np.testing.assert_array_equal(force[:, [0, 2]], 0.0)
    np.testing.assert_allclose(force[:, 1], -9.81 * np.where(held, mass, 0.0))


@pytest.mark.parametrize(
    ("value", "match"),
    [
        (-1.0, "payload.mass"),
        ({"mass": 10.0, "pick": 3.0, "release": 2.0}, "payload.release"),
        ({"mass": 10.0, "pick": -1.0}, "payload.pick"),
        ({"mass": 10.0, "inertia": "yes"}, "payload.inertia"),
        ({"mass": 10.0, "drop": 1.0}, "unknown key"),
        ({"pick": 1.0}, "missing key"),
        (True, "expected a mapping"),
    ],
)
def test_bad_payload_raises_naming_the_field(value: object, match: str) -> None:
    """Every bad payload raises one error naming the field."""
    with pytest.raises((InvalidInputError, ConfigError), match=match):
        Payload.from_value(value)
