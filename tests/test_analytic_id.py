"""Analytic inverse dynamics: power balance, virtual work, Lagrange's equations, input checks."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from hiab_sim.crane import kinematics, mechanism
from hiab_sim.crane.description import ChainLengths, Crane, LinkLengths
from hiab_sim.crane.loader import load_crane
from hiab_sim.dynamics.analytic_id import (
    analytic_inverse_dynamics,
    link_wrenches,
    mechanical_energy,
    spatial_inverse_dynamics,
    tcp_velocity,
)
from hiab_sim.dynamics.analytic_kinematics import crane_motion
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.errors import InvalidInputError
from hiab_sim.validation import lengths_from_fractions

CRANE = load_crane("xs031")
DEFAULT = CRANE.default_lengths
PAYLOAD = np.array([150.0, -2500.0, 0.0])  # N, a 255 kg payload with a small sideways pull


def _trajectory(t: np.ndarray, crane: Crane = CRANE) -> JointSamples:
    """Smooth sinusoids inside 10 %..90 % of each joint's working range."""
    ranges = np.array([crane.lift.joint_range, crane.tilt.joint_range, crane.telescope.joint_range])
    mid, amp = ranges.mean(axis=1), 0.4 * (ranges[:, 1] - ranges[:, 0])
    w, phase = np.array([0.7, 1.1, 0.9]), np.array([0.0, 0.5, 1.0])
    arg = w * np.asarray(t)[:, None] + phase
    return JointSamples(mid + amp * np.sin(arg), amp * w * np.cos(arg), -amp * w**2 * np.sin(arg))


def _random_states(rng: np.random.Generator, n: int, crane: Crane = CRANE) -> JointSamples:
    ranges = np.array([crane.lift.joint_range, crane.tilt.joint_range, crane.telescope.joint_range])
    position = ranges[:, 0] + rng.uniform(0.02, 0.98, (n, 3)) * (ranges[:, 1] - ranges[:, 0])
    return JointSamples(position, rng.normal(0.0, 0.4, (n, 3)), rng.normal(0.0, 1.0, (n, 3)))


def _energy_rate(lengths: LinkLengths, joints: JointSamples, h: float = 1e-3) -> np.ndarray:
    """dE/dt by a 5-point stencil along q(t) = q + dq t + ddq t^2 / 2 (positions and velocities only)."""
    q, dq, ddq = joints.position, joints.velocity, joints.acceleration
    energies = [
        mechanical_energy(
            CRANE, lengths, JointSamples(q + dq * k * h + 0.5 * ddq * (k * h) ** 2, dq + ddq * k * h, ddq)
        ).total
        for k in (-2, -1, 1, 2)
    ]
    return (energies[0] - 8 * energies[1] + 8 * energies[2] - energies[3]) / (12 * h)


IMPLEMENTATIONS = pytest.mark.parametrize(
    "inverse_dynamics", [analytic_inverse_dynamics, spatial_inverse_dynamics], ids=["planar", "spatial"]
)


def _power_residual(
    lengths: LinkLengths, joints: JointSamples, tcp_force: np.ndarray | None, inverse_dynamics=analytic_inverse_dynamics
) -> float:
    out = inverse_dynamics(CRANE, lengths, joints, tcp_force=tcp_force)
    power = out.power.sum(axis=1)
    if tcp_force is not None:
        power = power + tcp_velocity(CRANE, lengths, joints) @ tcp_force
    return float(np.max(np.abs(power - _energy_rate(lengths, joints))) / np.max(np.abs(power)))


@IMPLEMENTATIONS
@pytest.mark.parametrize("tcp_force", [None, PAYLOAD], ids=["free", "payload"])
def test_actuator_power_equals_rate_of_mechanical_energy(inverse_dynamics, tcp_force: np.ndarray | None) -> None:
    """Power balance: sum f_x v_x + F_tcp . v_tcp = dE/dt along a smooth trajectory, to 1e-6 of the peak power."""
    assert _power_residual(DEFAULT, _trajectory(np.linspace(0.0, 9.0, 60)), tcp_force, inverse_dynamics) <= 1e-6


def _stroke_samples(x: np.ndarray, lengths: LinkLengths) -> np.ndarray:
    """Joint positions (T, 3) for actuator strokes (T, 3)."""
    theta1 = mechanism.stroke_to_joint(CRANE.lift, lengths.lift, x[:, 0])
    theta2 = mechanism.stroke_to_joint(CRANE.tilt, lengths.tilt, x[:, 1])
    return np.stack([theta1, theta2, x[:, 2]], axis=1)


def _potential(x: np.ndarray, lengths: LinkLengths) -> np.ndarray:
    return mechanical_energy(CRANE, lengths, JointSamples.at_rest(_stroke_samples(x, lengths))).potential


@IMPLEMENTATIONS
def test_static_forces_equal_the_gradient_of_potential_energy(inverse_dynamics) -> None:
    """Gravity only, at rest: f_j = dU/dx_j (virtual work), to 1e-7 of the largest force."""
    rng = np.random.default_rng(3)
    joints = _random_states(rng, 12)
    static = JointSamples.at_rest(joints.position)
    out = inverse_dynamics(CRANE, DEFAULT, static)
    h = 1e-5
    for j in range(3):
        step = np.zeros(3)
        step[j] = h
        gradient = (_potential(out.stroke + step, DEFAULT) - _potential(out.stroke - step, DEFAULT)) / (2 * h)
        np.testing.assert_allclose(out.force[:, j], gradient, atol=1e-7 * np.max(np.abs(out.force)))


def _kinetic(x: np.ndarray, dx: np.ndarray, lengths: LinkLengths) -> np.ndarray:
    joints = []
    for j, chain in enumerate(CRANE.chains):
        theta, dtheta, _ = mechanism.actuator_to_joint(
            chain, getattr(lengths, chain.name), x[:, j], dx[:, j], 0.0 * x[:, j]
        )
        joints.append((theta, dtheta))
    position = np.stack([joints[0][0], joints[1][0], x[:, 2]], axis=1)
    velocity = np.stack([joints[0][1], joints[1][1], dx[:, 2]], axis=1)
    return mechanical_energy(CRANE, lengths, JointSamples(position, velocity, np.zeros_like(x))).kinetic


def _mass_matrix(x: np.ndarray, lengths: LinkLengths) -> np.ndarray:
    """M(x) (T, 3, 3) in actuator coordinates, by polarisation of the kinetic energy."""
    eye = np.eye(3)
    ones = np.ones((x.shape[0], 1))
    M = np.zeros((x.shape[0], 3, 3))
    for i in range(3):
        for j in range(3):
            both = _kinetic(x, ones * (eye[i] + eye[j]), lengths)
            M[:, i, j] = both - _kinetic(x, ones * eye[i], lengths) - _kinetic(x, ones * eye[j], lengths)
    return M


@IMPLEMENTATIONS
def test_forces_satisfy_lagranges_equations_in_actuator_coordinates(inverse_dynamics) -> None:
    """Lagrange: f = M(x) ddx + dM/dt dx - d(dx^T M dx / 2)/dx + dU/dx, with M from the energy function alone."""
    rng = np.random.default_rng(11)
    joints = _random_states(rng, 8)
    out = inverse_dynamics(CRANE, DEFAULT, joints)
    x, dx, ddx = out.stroke, out.velocity, out.acceleration
    h = 1e-5
    expected = np.einsum("tij,tj->ti", _mass_matrix(x, DEFAULT), ddx)
    for k in range(3):
        step = np.zeros(3)
        step[k] = h
        dM = (_mass_matrix(x + step, DEFAULT) - _mass_matrix(x - step, DEFAULT)) / (2 * h)
        dU = (_potential(x + step, DEFAULT) - _potential(x - step, DEFAULT)) / (2 * h)
        expected += np.einsum("tij,tj->ti", dM, dx) * dx[:, k : k + 1]
        expected[:, k] += -0.5 * np.einsum("ti,tij,tj->t", dx, dM, dx) + dU
    np.testing.assert_allclose(out.force, expected, atol=1e-6 * np.max(np.abs(out.force)))


@IMPLEMENTATIONS
def test_forces_equal_virtual_power_of_link_wrenches(inverse_dynamics) -> None:
    """Virtual power: f_j = sum_i F_i . dV_i/dv_j: the partial twists' virtual power equals the tip-to-base solve."""
    rng = np.random.default_rng(5)
    joints = _random_states(rng, 10)
    out = inverse_dynamics(CRANE, DEFAULT, joints, tcp_force=PAYLOAD)
    wrenches = link_wrenches(
        CRANE, DEFAULT, crane_motion(CRANE, DEFAULT, joints.position, joints.velocity, joints.acceleration)
    )
    for j in range(3):
        unit = np.zeros_like(out.velocity)
        unit[:, j] = 1.0
        velocity = np.zeros_like(unit)
        for c, chain in enumerate(CRANE.chains):
            k1, _, _ = mechanism.velocity_ratios(
                out.stroke[:, c], getattr(DEFAULT, chain.name).L, chain.L1, getattr(DEFAULT, chain.name).x0
            )
            velocity[:, c] = -k1 * unit[:, c]
        velocity[:, 2] = unit[:, 2]
        partial = JointSamples(joints.position, velocity, np.zeros_like(velocity))
        motion = crane_motion(CRANE, DEFAULT, partial.position, partial.velocity, partial.acceleration)
        virtual = np.zeros(len(joints))
        for name, link in motion.links.items():
            w = np.einsum("tij,tj->ti", link.rotation, link.twist[:, :3])
            v_origin = np.einsum("tij,tj->ti", link.rotation, link.twist[:, 3:]) - np.cross(w, link.position)
            virtual += np.einsum("ti,ti->t", wrenches[name][:, :3], w) + np.einsum(
                "ti,ti->t", wrenches[name][:, 3:], v_origin
            )
        virtual -= tcp_velocity(CRANE, DEFAULT, partial) @ PAYLOAD
        np.testing.assert_allclose(out.force[:, j], virtual, atol=1e-9 * np.max(np.abs(out.force)))


def test_link_poses_match_forward_kinematics_and_twists_its_time_derivative() -> None:
    """Poses equal kinematics.forward_kinematics; world velocities equal its central differences."""
    t, h = np.linspace(0.0, 6.0, 25), 1e-5
    joints = _trajectory(t)
    motion = crane_motion(CRANE, DEFAULT, joints.position, joints.velocity, joints.acceleration)
    now = kinematics.forward_kinematics(CRANE, DEFAULT, *joints.position.T)
    plus = kinematics.forward_kinematics(CRANE, DEFAULT, *_trajectory(t + h).position.T)
    minus = kinematics.forward_kinematics(CRANE, DEFAULT, *_trajectory(t - h).position.T)
    for name, link in motion.links.items():
        np.testing.assert_allclose(link.rotation, now.rotation[name], atol=1e-14)
        np.testing.assert_allclose(link.position, now.position[name], atol=1e-14)
        velocity = np.einsum("tij,tj->ti", link.rotation, link.twist[:, 3:])
        np.testing.assert_allclose(velocity, (plus.position[name] - minus.position[name]) / (2 * h), atol=1e-8)
        spin = np.einsum("tij,tj->ti", link.rotation, link.twist[:, :3])
        dR = (plus.rotation[name] - minus.rotation[name]) / (2 * h)
        omega_hat = dR @ np.swapaxes(link.rotation, 1, 2)
        np.testing.assert_allclose(spin[:, 2], omega_hat[:, 1, 0], atol=1e-8)


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(0.0, 1.0), min_size=6, max_size=6), st.integers(0, 2**31))
def test_power_balance_holds_for_other_lengths_and_states(fractions: list[float], seed: int) -> None:
    """Power balance to 1e-6 for random feasible lengths, states and a payload; planar = 6D to round-off."""
    lengths = lengths_from_fractions(CRANE, np.array(fractions))
    assume(lengths is not None)
    assert lengths is not None
    joints = _random_states(np.random.default_rng(seed), 6)
    assert _power_residual(lengths, joints, PAYLOAD) <= 1e-6
    planar = analytic_inverse_dynamics(CRANE, lengths, joints, tcp_force=PAYLOAD)
    spatial = spatial_inverse_dynamics(CRANE, lengths, joints, tcp_force=PAYLOAD)
    np.testing.assert_allclose(planar.force, spatial.force, rtol=0, atol=1e-12 * np.max(np.abs(spatial.force)))
    np.testing.assert_allclose(planar.velocity, spatial.velocity, rtol=0, atol=1e-13)


def test_tcp_force_adds_its_virtual_work_to_the_static_forces() -> None:
    """A TCP force F changes the static forces by df_j = -F . dp_tcp/dx_j (virtual work of F)."""
    position = _random_states(np.random.default_rng(2), 5).position
    static = JointSamples.at_rest(position)
    free = analytic_inverse_dynamics(CRANE, DEFAULT, static)
    loaded = analytic_inverse_dynamics(CRANE, DEFAULT, static, tcp_force=PAYLOAD)
    h = 1e-6
    for j in range(3):
        step = np.zeros(3)
        step[j] = h
        p_plus = kinematics.tcp_position(CRANE, *_stroke_samples(free.stroke + step, DEFAULT).T)
        p_minus = kinematics.tcp_position(CRANE, *_stroke_samples(free.stroke - step, DEFAULT).T)
        expected = -(p_plus - p_minus) / (2 * h) @ PAYLOAD
        np.testing.assert_allclose(loaded.force[:, j] - free.force[:, j], expected, rtol=1e-7, atol=1e-6)


@pytest.mark.parametrize(
    ("column", "value", "field"),
    [(0, 2.5, "theta1"), (1, 0.5, "theta2"), (2, 1.5, "xt2"), (2, -0.1, "xt2")],
)
@IMPLEMENTATIONS
def test_joint_sample_outside_its_range_names_the_field(
    inverse_dynamics, column: int, value: float, field: str
) -> None:
    """A joint sample outside the usable range raises InvalidInputError naming the joint."""
    position = _trajectory(np.linspace(0, 1, 4)).position.copy()
    position[2, column] = value
    with pytest.raises(InvalidInputError) as info:
        inverse_dynamics(CRANE, DEFAULT, JointSamples.at_rest(position))
    assert info.value.field == field


@IMPLEMENTATIONS
def test_bad_lengths_and_tcp_force_name_the_field(inverse_dynamics) -> None:
    """Non-positive lengths and a wrongly shaped TCP force are rejected with the field named."""
    joints = _trajectory(np.linspace(0, 1, 4))
    bad = LinkLengths(ChainLengths(DEFAULT.lift.L, DEFAULT.lift.Lc0, -0.1), DEFAULT.tilt)
    with pytest.raises(InvalidInputError, match=r"lift\.Lc"):
        inverse_dynamics(CRANE, bad, joints)
    with pytest.raises(InvalidInputError) as info:
        inverse_dynamics(CRANE, DEFAULT, joints, tcp_force=np.ones(2))
    assert info.value.field == "tcp_force"


def test_analytic_module_does_not_import_mujoco() -> None:
    """The analytic path and everything it imports are free of MuJoCo."""
    import subprocess
    import sys

    code = "import sys, hiab_sim.dynamics.analytic_id; print('mujoco' in sys.modules)"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "False"
