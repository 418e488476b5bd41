"""The simulation MJCF: EMLA armature, damping, stops and force range; the ID paths keep the load-side force."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest
from closed_loop_helper import synthetic_plan

from hiab_sim.cli import main
from hiab_sim.crane.description import Crane
from hiab_sim.dynamics.analytic_id import analytic_inverse_dynamics
from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.emla import load_emla_set
from hiab_sim.env.reference import quintic_hermite
from hiab_sim.errors import InvalidInputError
from hiab_sim.model.drives import HomePose, SlideDrives
from hiab_sim.model.mjcf import SLIDES, build_model, build_spec

EMLAS = load_emla_set()


def _reflected(name: str) -> float:
    """J_m (2 pi G / rho)^2 + M_sm from the EMLA preset's numbers."""
    p = EMLAS[name]
    return p.motor.rotor_inertia * (2 * math.pi * p.gear_ratio / p.screw_lead) ** 2 + p.screw_moving_mass


def test_simulation_model_carries_the_drives_and_the_id_model_does_not(crane: Crane) -> None:
    """Slides get armature J_m k^2, damping b_f, force range k (tau_peak - tau_f), stops; the ID model none."""
    sim = build_model(crane, drives=SlideDrives.from_emla(EMLAS))
    ident = MujocoInverseDynamics(crane).model
    assert np.all(ident.dof_armature == 0) and np.all(ident.dof_damping == 0) and not np.any(ident.jnt_limited)
    for name, slide in zip(("lift", "tilt", "telescope"), SLIDES, strict=True):
        p = EMLAS[name]
        dof = sim.joint(slide).dofadr[0]
        assert sim.dof_armature[dof] == pytest.approx(_reflected(name), rel=1e-12)
        assert sim.dof_damping[dof] == pytest.approx(p.viscous_friction)
        eta = p.losses.transmission_efficiency_forward  # 0.87 in the shipped set, 1 in the paper's
        limit = 2 * math.pi * p.gear_ratio * eta * (p.motor.peak_torque - p.motor.rotor_coulomb_friction) / p.screw_lead
        np.testing.assert_allclose(sim.actuator(name).forcerange, [-limit, limit], rtol=1e-12)
        assert sim.jnt_limited[sim.joint(slide).id]
    assert 25e3 < _reflected("lift") < 35e3  # the ~30 t that dominates the slides' dynamics
    np.testing.assert_allclose(sim.joint("x1").range, [0.0, min(crane.lift.stroke, crane.lift.default_lengths.Lc)])


def _feedforward_drift(crane: Crane, forces: np.ndarray, with_drives: bool, seconds: float = 0.6) -> float:
    """Largest TCP distance [m] between open-loop simulation under slide forces and the plan."""
    plan = synthetic_plan(crane)
    h = 5e-4
    times = np.arange(0.0, seconds + 1e-12, h)
    pos, vel, acc = quintic_hermite(plan.time, plan.position, plan.velocity, plan.acceleration, times)
    joints = JointSamples(pos, vel, acc)
    dynamics = MujocoInverseDynamics(crane)
    qpos, qvel, _ = dynamics.state(joints)
    actuators = dynamics(joints)
    drives = SlideDrives.from_emla(EMLAS)
    model = build_model(crane, drives=drives)
    model.opt.timestep = h
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = qpos[0], qvel[0]
    kin = mujoco.MjData(model)
    site = model.site("tcp").id
    reflected = np.asarray(drives.armature) * actuators.acceleration + np.asarray(drives.damping) * actuators.velocity
    slide_force = forces + (reflected if with_drives else 0.0)
    worst = 0.0
    for k in range(len(times) - 1):
        data.ctrl[:] = 0.5 * (slide_force[k] + slide_force[k + 1])
        mujoco.mj_step(model, data)
        kin.qpos[:] = qpos[k + 1]
        mujoco.mj_kinematics(model, kin)
        mujoco.mj_kinematics(model, data)
        worst = max(worst, float(np.linalg.norm(data.site_xpos[site] - kin.site_xpos[site])))
    return worst


@pytest.mark.parametrize("path", ["analytic", "mujoco"])
def test_both_id_paths_give_the_load_side_force(crane: Crane, path: str) -> None:
    """f_x + (J_m k^2 + M_sm) a_x + b_f v_x drives the simulation model along the plan; f_x alone does not.

    The rod force of either ID path is the load-side force of eq. torque_force: adding the drive's
    reflected inertia and viscous force gives the screw force the armature/damped slides need.
    """
    plan = synthetic_plan(crane)
    h = 5e-4
    times = np.arange(0.0, 0.6 + 1e-12, h)
    joints = JointSamples(*quintic_hermite(plan.time, plan.position, plan.velocity, plan.acceleration, times))
    if path == "analytic":
        forces = analytic_inverse_dynamics(crane, crane.default_lengths, joints).force
    else:
        forces = MujocoInverseDynamics(crane)(joints).force
    assert _feedforward_drift(crane, forces, with_drives=True) < 1e-3  # 0.15 mm: soft loops, 0.5 ms steps
    assert _feedforward_drift(crane, forces, with_drives=False) > 1e-2  # 51 mm


def test_exported_model_opens_standing_at_home_and_a_slider_moves_it(tmp_path: Path) -> None:
    """``hiab-sim mjcf``: qpos0 closes both loops and holds still with ctrl = 0; ctrl = +5 cm extends x1."""
    path = tmp_path / "crane.xml"
    assert main(["mjcf", "-o", str(path)]) == 0
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)  # what the viewer opens: qpos0, ctrl = 0
    mujoco.mj_forward(model, data)
    for chain in ("lift", "tilt"):
        np.testing.assert_allclose(data.site(f"{chain}_rod_end").xpos, data.site(f"{chain}_boom_pivot").xpos, atol=1e-9)
    start = data.qpos.copy()
    for _ in range(int(2.0 / model.opt.timestep)):
        mujoco.mj_step(model, data)
    assert np.max(np.abs(data.qpos - start)) < 1e-4
    x1 = model.joint("x1").qposadr[0]
    data.ctrl[0] = 0.05
    for _ in range(int(4.0 / model.opt.timestep)):
        mujoco.mj_step(model, data)
    assert 0.04 < data.qpos[x1] - start[x1] < 0.055


def test_bad_drive_values_are_rejected() -> None:
    """Negative armature or a non-finite home pose name the field."""
    with pytest.raises(InvalidInputError, match=r"drives\.armature"):
        SlideDrives(armature=(-1.0, 0.0, 0.0), damping=(0.0, 0.0, 0.0), force_limit=(1.0, 1.0, 1.0))
    with pytest.raises(InvalidInputError, match=r"home\.qpos\.x1"):
        HomePose(qpos={"x1": math.nan}, force=(0.0, 0.0, 0.0))


def test_home_pose_places_the_bodies_without_changing_joint_meaning(crane: Crane) -> None:
    """With a home pose as joint ref, the same qpos puts the TCP at the same place as without it."""
    plain = build_model(crane)
    data = mujoco.MjData(plain)
    qpos = MujocoInverseDynamics(crane).state(JointSamples.at_rest([[0.6, -1.3, 0.5]]))[0][0]
    names = [plain.joint(j).name for j in range(plain.njnt)]
    home = HomePose(qpos=dict(zip(names, map(float, qpos), strict=True)), force=(0.0, 0.0, 0.0))
    placed = build_spec(crane, drives=SlideDrives.from_emla(EMLAS), home=home).compile()
    np.testing.assert_allclose(placed.qpos0, qpos, atol=1e-12)
    other = mujoco.MjData(placed)
    for d, m in ((data, plain), (other, placed)):
        d.qpos[:] = qpos + np.array([0.05, -0.02, 0.1, 0.0, 0.0, 0.0, 0.0])
        mujoco.mj_kinematics(m, d)
    np.testing.assert_allclose(other.site("tcp").xpos, data.site("tcp").xpos, atol=1e-12)
