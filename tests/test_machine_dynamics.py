"""The two generic inverse-dynamics paths: agreement with each other and with the XS 031's own paths.

The Newton-Euler path (per-body free-body solve, numpy) and the MuJoCo path (``mj_inverse`` and the
loop projection) are independent; on the XS 031 both must also reproduce the crane-specific paths of
:mod:`hiab_sim.dynamics` (trigonometric chain solve, and MuJoCo on the crane's own MJCF).
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lengths_helper import feasible_lengths
from test_machine_dynamics_machines import excavator, hand_machine, random_states

from hiab_sim.crane.loader import load_crane
from hiab_sim.dynamics.analytic_id import analytic_inverse_dynamics
from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.mjcf_build import SimulationExtras, build_machine_model
from hiab_sim.machine.dynamics.mujoco_path import MujocoMachineDynamics
from hiab_sim.machine.dynamics.newton_euler import NewtonEulerInverseDynamics
from hiab_sim.machine.dynamics.paths import MACHINE_ID_PATHS, make_machine_dynamics
from hiab_sim.machine.dynamics.tree import MachineActuatorSamples
from hiab_sim.machine.kinematics import closure
from hiab_sim.machine.loader import load_machine
from hiab_sim.machine.parts import Pose, rot_z
from hiab_sim.model.drives import SlideDrives
from hiab_sim.model.mjcf import build_model

CRANE = load_crane("xs031")
XS031 = load_machine("xs031")
EXACT = load_machine("exact")  # the shipped excavator preset
EXCAVATOR = excavator()  # the same arm written in the test from the reference sheet, other actuator bodies
#: The test excavator standing on a 12 deg slope, its chassis frame moved off the world origin.
SLOPE = Pose((0.4, -0.2, 0.05), rot_z(np.radians(12.0)))
MACHINES = pytest.mark.parametrize(
    "machine",
    [XS031, EXACT, EXCAVATOR, hand_machine(reversed_actuator=True), excavator(SLOPE)],
    ids=["xs031", "exact", "test-excavator", "cylinder-on-driven-link", "on-a-slope"],
)


def relative(a: np.ndarray, b: np.ndarray) -> float:
    """Largest |a - b| per column relative to that column's peak |b|, over all columns (peak-normalised)."""
    a2 = a.reshape(a.shape[0], -1)
    b2 = b.reshape(b.shape[0], -1)
    return float(np.max(np.max(np.abs(a2 - b2), axis=0) / np.maximum(np.max(np.abs(b2), axis=0), 1e-300)))


def payload_forces(samples: int, seed: int, scale: float = 2000.0) -> np.ndarray:
    """Random planar TCP forces (T, 2) [N]."""
    return np.random.default_rng(seed).normal(0.0, scale, (samples, 2))


def xs031_design(u: np.ndarray) -> np.ndarray:
    """A feasible XS 031 design [L, Lc0, Lc] x 2 [m] (the crane tests' sampler), in the machine's variable order."""
    assert XS031.variable_keys == ["lift.L", "lift.Lc0", "lift.Lc", "tilt.L", "tilt.Lc0", "tilt.Lc"]
    return feasible_lengths(u).as_array()


def test_newton_euler_equals_the_crane_analytic_path_on_the_xs031() -> None:
    """The generic Newton-Euler path gives the crane analytic path's f_x, v_x, a_x, x (1e-12), with a TCP force."""
    q, dq, ddq = random_states(XS031, 200, seed=1)
    force = payload_forces(200, seed=2)
    for u in (None, 0.3, 0.8):
        lengths = CRANE.default_lengths if u is None else feasible_lengths(np.full(6, u))
        machine = XS031.with_design(lengths.as_array(), check_bounds=False)
        ref = analytic_inverse_dynamics(CRANE, lengths, JointSamples(q, dq, ddq), np.c_[force, np.zeros(200)])
        out = NewtonEulerInverseDynamics(machine)(q, dq, ddq, force)
        assert relative(out.force, ref.force) < 1e-12
        assert relative(out.velocity, ref.velocity) < 1e-12
        assert relative(out.acceleration, ref.acceleration) < 1e-12
        np.testing.assert_allclose(out.stroke, ref.stroke, atol=1e-13)


def test_mujoco_path_equals_the_crane_mujoco_path_on_the_xs031() -> None:
    """The generic MuJoCo path (MJCF built from the machine file) gives the crane MJCF path's forces (1e-12)."""
    q, dq, ddq = random_states(XS031, 60, seed=3)
    force = payload_forces(60, seed=4)
    lengths = feasible_lengths(np.full(6, 0.6))
    ref = MujocoInverseDynamics(CRANE, lengths)(JointSamples(q, dq, ddq), np.c_[force, np.zeros(60)])
    out = MujocoMachineDynamics(XS031, lengths.as_array())(q, dq, ddq, force)
    assert relative(out.force, ref.force) < 1e-12
    assert relative(out.velocity, ref.velocity) < 1e-12
    np.testing.assert_allclose(out.stroke, ref.stroke, atol=1e-13)


def _both(machine: Machine, samples: int, seed: int) -> tuple[MachineActuatorSamples, MachineActuatorSamples]:
    q, dq, ddq = random_states(machine, samples, seed)
    force = payload_forces(samples, seed + 100)
    return (
        NewtonEulerInverseDynamics(machine)(q, dq, ddq, force),
        MujocoMachineDynamics(machine)(q, dq, ddq, force),
    )


@MACHINES
def test_both_paths_agree_on_random_states(machine: Machine) -> None:
    """Newton-Euler and MuJoCo give the same actuator forces and pin forces (1e-10 relative; measured ~1e-14)."""
    ne, mj = _both(machine, 80, seed=5)
    assert ne.names == mj.names == tuple(machine.actuator_names)
    assert ne.pins.names == mj.pins.names
    assert relative(mj.force, ne.force) < 1e-10
    assert relative(mj.velocity, ne.velocity) < 1e-10
    assert relative(mj.acceleration, ne.acceleration) < 1e-10
    np.testing.assert_allclose(mj.stroke, ne.stroke, atol=1e-12)
    assert relative(mj.pins.world, ne.pins.world) < 1e-10
    peak = np.max(np.abs(ne.pins.world))
    assert np.max(np.abs(mj.pins.local - ne.pins.local)) < 1e-10 * peak


@MACHINES
def test_strokes_equal_the_machine_closure(machine: Machine) -> None:
    """The dynamics' own closed-form closure gives the strokes of the machine kinematics' closure (1e-12 m)."""
    q, dq, ddq = random_states(machine, 50, seed=9)
    out = NewtonEulerInverseDynamics(machine)(q, dq, ddq)
    for k, chain in enumerate(machine.chains):
        x = closure.joint_to_stroke(machine, chain, q[:, machine.joint_names.index(chain.joint)])
        np.testing.assert_allclose(out.stroke[:, k], x, atol=1e-12, err_msg=chain.name)


def test_excavator_pins_include_every_four_bar_pin() -> None:
    """The bucket linkage reports its rocker hinge, the rocker-link pin, the rod pin and the link-bucket pin."""
    ne, _ = _both(EXACT, 3, seed=6)
    for pin in ("bucket.base_pin", "bucket.rocker_pin", "bucket.link_pin", "bucket.rod_pin", "bucket.coupler_pin"):
        assert pin in ne.pins.names
        assert np.all(np.linalg.norm(ne.pins.force(pin), axis=1) > 1.0)  # every pin carries load


@settings(max_examples=10, deadline=None)
@given(st.lists(st.floats(0.0, 1.0), min_size=6, max_size=6).map(np.array))
def test_both_paths_agree_for_any_feasible_xs031_design(u: np.ndarray) -> None:
    """For any feasible XS 031 design the two generic paths agree (1e-10 relative)."""
    machine = XS031.with_design(xs031_design(u), check_bounds=False)
    ne, mj = _both(machine, 8, seed=int(1000 * u[0]))
    assert relative(mj.force, ne.force) < 1e-10
    assert relative(mj.pins.world, ne.pins.world) < 1e-10


@settings(max_examples=10, deadline=None)
@given(st.lists(st.floats(0.0, 1.0), min_size=9, max_size=9).map(np.array))
def test_both_paths_agree_for_any_excavator_design_in_its_bounds(u: np.ndarray) -> None:
    """For any design of the excavator preset inside its declared bounds the two paths agree (1e-10 relative)."""
    low, high = EXACT.design_bounds()
    machine = EXACT.with_design(low + u * (high - low))
    ne, mj = _both(machine, 8, seed=int(1000 * u[0]))
    assert relative(mj.force, ne.force) < 1e-10
    assert relative(mj.pins.world, ne.pins.world) < 1e-10


def test_simulation_extras_add_armature_and_damping_on_the_motor_side() -> None:
    """With extras the MuJoCo force is f_x + J a_x + b v_x (eqs. torque_torque, torque_force); pins unchanged.

    MuJoCo carries the armature in its mass matrix and the damping as a passive force; the
    Newton-Euler path adds both to the load-side force: the two agree.
    """
    q, dq, ddq = random_states(EXACT, 20, seed=7)
    extras = SimulationExtras((310.0, 420.0, 530.0), (1.5e3, 2.5e3, 3.5e3))
    bare = MujocoMachineDynamics(EXACT)(q, dq, ddq)
    drive = MujocoMachineDynamics(EXACT, extras=extras)(q, dq, ddq)
    expected = bare.force + np.array(extras.armature_kg) * bare.acceleration
    expected += np.array(extras.damping_Ns_per_m) * bare.velocity
    assert relative(drive.force, expected) < 1e-12
    assert relative(drive.pins.world, bare.pins.world) < 1e-12
    analytic = NewtonEulerInverseDynamics(EXACT, extras=extras)(q, dq, ddq)
    assert relative(analytic.force, drive.force) < 1e-10


@pytest.mark.parametrize("path", MACHINE_ID_PATHS)
def test_paths_by_name_give_the_same_forces(path: str) -> None:
    """make_machine_dynamics builds either path for a design; an unknown path names the field id_path."""
    design = EXACT.design_values()
    q, dq, ddq = random_states(EXACT, 10, seed=16)
    out = make_machine_dynamics(EXACT, design, path)(q, dq, ddq, [500.0, -300.0])
    reference = NewtonEulerInverseDynamics(EXACT)(q, dq, ddq, [500.0, -300.0])
    assert relative(out.force, reference.force) < 1e-10
    with pytest.raises(InvalidInputError, match="id_path"):
        make_machine_dynamics(EXACT, path="trigonometric")


def test_bad_samples_and_forces_name_their_field() -> None:
    """Out-of-range joints, wrong shapes, NaN and an undriven joint raise InvalidInputError naming the field."""
    dynamics = NewtonEulerInverseDynamics(EXCAVATOR)
    q, dq, ddq = random_states(EXCAVATOR, 4, seed=8)
    bad = q.copy()
    bad[1, 2] = 1.5  # gamma above its 0.7839 rad limit
    with pytest.raises(InvalidInputError, match="gamma"):
        dynamics(bad, dq, ddq)
    with pytest.raises(InvalidInputError, match="tcp_force"):
        dynamics(q, dq, ddq, np.zeros((3, 2)))
    with pytest.raises(InvalidInputError, match="tcp_force"):
        dynamics(q, dq, ddq, [np.nan, 0.0])
    with pytest.raises(InvalidInputError, match=r"joints\.velocity"):
        dynamics(q, dq[:, :2], ddq)
    undriven = EXCAVATOR.__class__(**{**EXCAVATOR.__dict__, "chains": EXCAVATOR.chains[:2]})
    with pytest.raises(InvalidInputError, match="gamma"):
        NewtonEulerInverseDynamics(undriven)
    for path in (MujocoMachineDynamics, NewtonEulerInverseDynamics):
        with pytest.raises(InvalidInputError, match="extras"):
            path(EXCAVATOR, extras=SimulationExtras((1.0,), (1.0,)))


def test_xs031_simulation_model_equals_the_crane_simulation_model() -> None:
    """The machine MJCF with extras has the crane simulation MJCF's mass matrix, bias and passive forces.

    Compared at the same loop-consistent states, joints matched by name (1e-12 relative).
    """
    armature, damping = (310.0, 420.0, 53.0), (1500.0, 2500.0, 350.0)
    crane_model = build_model(CRANE, drives=SlideDrives(armature, damping, (1e5, 1e5, 1e5)))
    machine_model = build_machine_model(XS031, extras=SimulationExtras(armature, damping))
    same = {"lift_q1": "lift.base_pin", "x1": "lift.stroke", "tilt_q1": "tilt.base_pin", "x2": "tilt.stroke"}
    order = [
        int(machine_model.joint(same.get(name, name)).dofadr[0])
        for name in (crane_model.joint(j).name for j in range(crane_model.njnt))
    ]
    q, dq, ddq = random_states(XS031, 5, seed=10)
    crane_state = MujocoInverseDynamics(CRANE).state(JointSamples(q, dq, ddq))
    machine_state = MujocoMachineDynamics(XS031).state(q, dq, ddq)
    crane_data, machine_data = mujoco.MjData(crane_model), mujoco.MjData(machine_model)
    nv = crane_model.nv
    for i in range(len(q)):
        crane_data.qpos[:], crane_data.qvel[:] = crane_state[0][i], crane_state[1][i]
        machine_data.qpos[:], machine_data.qvel[:] = machine_state[0][i], machine_state[1][i]
        np.testing.assert_allclose(machine_data.qvel[order], crane_data.qvel, atol=1e-12)
        mujoco.mj_forward(crane_model, crane_data)
        mujoco.mj_forward(machine_model, machine_data)
        crane_mass, machine_mass = np.zeros((nv, nv)), np.zeros((nv, nv))
        mujoco.mj_fullM(crane_model, crane_data, crane_mass)
        mujoco.mj_fullM(machine_model, machine_data, machine_mass)
        assert relative(machine_mass[np.ix_(order, order)], crane_mass) < 1e-12
        bias_scale = np.max(np.abs(crane_data.qfrc_bias))
        assert np.max(np.abs(machine_data.qfrc_bias[order] - crane_data.qfrc_bias)) < 1e-12 * bias_scale
        np.testing.assert_allclose(machine_data.qfrc_passive[order], crane_data.qfrc_passive, atol=1e-9)
