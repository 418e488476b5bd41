"""MJCF model: names, frames and inertia agree with the crane description; link lengths move only the cylinders."""

from __future__ import annotations

import copy
from pathlib import Path

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lengths_helper import feasible_lengths

from hiab_sim.cli import main
from hiab_sim.crane import kinematics
from hiab_sim.crane.description import ChainLengths, Crane, LinkLengths
from hiab_sim.crane.loader import load_crane
from hiab_sim.errors import InvalidInputError
from hiab_sim.model import build_model, to_xml
from hiab_sim.model.mjcf import SOURCE_TO_WORLD, source_to_world

CRANE = load_crane("xs031")
LINKS = ("lift_boom", "lift_cylinder", "lift_rod", "tilt_boom", "tilt_cylinder", "tilt_rod", "telescope_rod")


UNIT = st.lists(st.floats(0.0, 1.0), min_size=6, max_size=6).map(np.array)


def _pose_from_source(model: mujoco.MjModel, lengths: LinkLengths, theta1: float, theta2: float, xt2: float):
    """Set qpos from the source's forward kinematics (trigonometric path) and run mj_kinematics."""
    frames = kinematics.forward_kinematics(CRANE, lengths, [theta1], [theta2], [xt2])
    data = mujoco.MjData(model)
    data.joint("theta1").qpos = theta1
    data.joint("theta2").qpos = theta2
    data.joint("xt2").qpos = xt2
    for chain, slide in ((CRANE.lift, "x1"), (CRANE.tilt, "x2")):
        relative = frames.rotation[chain.parent][0].T @ frames.rotation[f"{chain.name}_cylinder"][0]
        data.joint(f"{chain.name}_q1").qpos = np.arctan2(relative[1, 0], relative[0, 0]) - chain.base_axis_angle
        data.joint(slide).qpos = frames.stroke[chain.name][0]
    mujoco.mj_kinematics(model, data)
    return frames, data


@settings(max_examples=25, deadline=None)
@given(st.floats(0.02, 0.98), st.floats(0.02, 0.98), st.floats(0.0, 1.1))
def test_joint_qpos_are_the_source_angles(a: float, b: float, xt2: float) -> None:
    """With qpos = (Θ1, Θ2, xt2), every body frame and the TCP sit where the source's kinematics put them."""
    (l1, h1), (l2, h2) = CRANE.lift.joint_range, CRANE.tilt.joint_range
    model = build_model(CRANE)
    frames, data = _pose_from_source(model, CRANE.default_lengths, l1 + a * (h1 - l1), l2 + b * (h2 - l2), xt2)
    for link in LINKS:
        np.testing.assert_allclose(data.body(link).xpos, source_to_world(frames.position[link][0]), atol=1e-12)
        world = SOURCE_TO_WORLD @ frames.rotation[link][0]
        np.testing.assert_allclose(data.body(link).xmat.reshape(3, 3), world, atol=1e-12)
    np.testing.assert_allclose(data.site("tcp").xpos, source_to_world(frames.position["tcp"][0]), atol=1e-12)
    tcp_rotation = SOURCE_TO_WORLD @ frames.rotation["tcp"][0]
    np.testing.assert_allclose(data.site("tcp").xmat.reshape(3, 3), tcp_rotation, atol=1e-12)
    for chain in ("lift", "tilt"):  # the source's loop-consistent pose closes MuJoCo's loops
        np.testing.assert_allclose(
            data.site(f"{chain}_rod_end").xpos, data.site(f"{chain}_boom_pivot").xpos, atol=1e-12
        )


def test_world_z_is_up_and_the_crane_moves_in_the_xz_plane(crane: Crane) -> None:
    """Gravity is -z; every hinge axis is world -y (source z), so the motion stays in the x-z plane."""
    model = build_model(crane)
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    np.testing.assert_allclose(model.opt.gravity, [0.0, 0.0, -crane.gravity])
    hinges = [j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    np.testing.assert_allclose(data.xaxis[hinges], np.tile([0.0, -1.0, 0.0], (len(hinges), 1)), atol=1e-15)
    assert model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_CONTACT


def test_names_users_rely_on_exist(crane: Crane) -> None:
    """Joints theta1, theta2, x1, x2, xt2, site tcp, motors lift/tilt/telescope on x1/x2/xt2, two connect loops."""
    model = build_model(crane)
    for joint in ("theta1", "theta2", "x1", "x2", "xt2"):
        model.joint(joint)
    model.site("tcp")
    targets = [model.joint(model.actuator(name).trnid[0]).name for name in ("lift", "tilt", "telescope")]
    assert targets == ["x1", "x2", "xt2"]
    assert list(model.eq_type) == [mujoco.mjtEq.mjEQ_CONNECT] * 2
    assert list(model.actuator_gear[:, 0]) == [1.0, 1.0, 1.0]
    assert not model.actuator_ctrllimited.any()


@settings(max_examples=10, deadline=None)
@given(UNIT)
def test_mass_and_centre_of_mass_are_the_descriptions(u: np.ndarray) -> None:
    """Total mass and the crane's centre of mass equal those of crane.bodies_for(lengths) at any pose."""
    lengths = feasible_lengths(u)
    model = build_model(CRANE, lengths)
    frames, data = _pose_from_source(model, lengths, 0.5, -1.0, 0.3)
    bodies = CRANE.bodies_for(lengths)
    total = sum(body.mass for body in bodies)
    com = sum(body.mass * frames.point(body.link, body.com)[0] for body in bodies) / total
    assert model.body_subtreemass[0] == pytest.approx(total, rel=1e-12)
    mujoco.mj_comPos(model, data)
    np.testing.assert_allclose(data.subtree_com[0], source_to_world(com), atol=1e-12)


@settings(max_examples=20, deadline=None)
@given(UNIT)
def test_changing_lengths_keeps_hinges_and_tcp(u: np.ndarray) -> None:
    """Xi moves only the cylinder base pivots (along their fixed direction); booms, hinges and TCP stay."""
    lengths = feasible_lengths(u)
    default, moved = build_model(CRANE), build_model(CRANE, lengths)
    for name in ("lift_boom", "tilt_boom", "telescope_rod"):
        np.testing.assert_array_equal(default.body(name).pos, moved.body(name).pos)
        np.testing.assert_array_equal(default.body(name).quat, moved.body(name).quat)
        np.testing.assert_allclose(default.body(name).mass, moved.body(name).mass, rtol=1e-15)
    np.testing.assert_array_equal(default.site("tcp").pos, moved.site("tcp").pos)
    for chain in CRANE.chains:
        pivot = moved.body(f"{chain.name}_cylinder").pos
        offset = chain.boom_hinge - pivot
        assert np.linalg.norm(offset) == pytest.approx(getattr(lengths, chain.name).L, rel=1e-12)
        np.testing.assert_allclose(offset / np.linalg.norm(offset), chain.base_axis, atol=1e-12)


def test_infeasible_lengths_name_the_field(crane: Crane) -> None:
    """A negative or too short length raises InvalidInputError naming the chain's field, before MuJoCo."""
    bad = LinkLengths(ChainLengths(1.0, 0.085, -0.7), crane.default_lengths.tilt)
    with pytest.raises(InvalidInputError, match=r"lift\.Lc"):
        build_model(crane, bad)
    short = LinkLengths(crane.default_lengths.lift, ChainLengths(1.132, 0.085, 0.3))
    with pytest.raises(InvalidInputError, match=r"tilt\.stroke"):
        build_model(crane, short)


def test_xml_round_trip_keeps_the_model(crane: Crane) -> None:
    """to_xml() reloads into the same model to round-off (MuJoCo's own writer would round to 6 digits)."""
    lengths = feasible_lengths(np.full(6, 0.3))
    model = build_model(crane, lengths)
    again = mujoco.MjModel.from_xml_string(to_xml(crane, lengths))
    assert (again.nbody, again.nv, again.neq, again.nu) == (model.nbody, model.nv, model.neq, model.nu)
    for field in ("body_pos", "body_quat", "body_ipos", "body_iquat", "body_mass", "body_inertia", "site_pos"):
        np.testing.assert_allclose(getattr(again, field), getattr(model, field), rtol=1e-15, atol=1e-15)
    np.testing.assert_array_equal(again.eq_solref, model.eq_solref)


def test_cli_writes_a_loadable_model(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """`hiab-sim mjcf --lengths ... -o FILE` writes a model that from_xml_path loads, with those lengths."""
    out = tmp_path / "crane.xml"
    lengths = feasible_lengths(np.full(6, 0.5))
    text = ",".join(repr(float(v)) for v in lengths.as_array())
    assert main(["mjcf", "--lengths", text, "-o", str(out)]) == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.site("lift_rod_end").pos[0] == pytest.approx(lengths.lift.Lc, rel=1e-15)
    x2_home = model.qpos0[model.joint("x2").qposadr[0]]  # bodies are placed at home (joint ref)
    assert model.body("tilt_rod").pos[0] - x2_home == pytest.approx(lengths.tilt.Lc0, rel=1e-15)
    assert list(tmp_path.iterdir()) == [out]  # no temporary file left behind
    assert "wrote" in capsys.readouterr().out


@pytest.mark.parametrize(
    "lengths", ["1,2,3", "a,b,c,d,e,f", "1.0,0.085,0.745,1.1,0.085,-0.7", "1,0.085,0.745,1.1,nan,0.7"]
)
def test_cli_rejects_bad_lengths_with_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str], lengths: str) -> None:
    """Bad --lengths exit with status 2 and a one-line message, no traceback, no file."""
    out = tmp_path / "crane.xml"
    assert main(["mjcf", "--lengths", lengths, "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "error:" in err and "Traceback" not in err
    assert not out.exists()


def _drift_from_home(model: mujoco.MjModel, hold: bool, seconds: float = 0.2) -> float:
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    if not hold:  # the actuators switched off: the crane falls
        model = copy.copy(model)
        model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_ACTUATION)
    start = data.qpos[:3].copy()  # theta1, theta2, xt2
    for _ in range(round(seconds / model.opt.timestep)):
        mujoco.mj_step(model, data)
    return float(np.max(np.abs(data.qpos[:3] - start)))


def test_exported_home_keyframe_is_a_loop_consistent_static_equilibrium(tmp_path: Path) -> None:
    """In the written file, key 'home' closes both loops and the actuators hold the crane still.

    The soft loop constraints take ~(1 - solimp) of the load at the first step and settle within
    a few time constants (2 ms), so the check is the drift over 0.2 s of simulation, against the
    fall without the actuators.
    """
    out = tmp_path / "crane.xml"
    assert main(["mjcf", "-o", str(out)]) == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)
    for chain in ("lift", "tilt"):
        gap = data.site(f"{chain}_rod_end").xpos - data.site(f"{chain}_boom_pivot").xpos
        assert np.linalg.norm(gap) < 1e-12
    assert _drift_from_home(model, hold=True) < 1e-4
    assert _drift_from_home(model, hold=False) > 1e-2
