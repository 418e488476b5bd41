"""Hinge and pin friction on the crane: where it sits, and that what it dissipates is what the crane loses."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from closed_loop_helper import synthetic_plan

from hiab_sim.crane.description import Crane
from hiab_sim.env.plant.config import JointFriction
from hiab_sim.env.plant.friction import FrictionMeter, add_joint_friction
from hiab_sim.env.reference import planned_motion
from hiab_sim.model.drives import HomePose, SlideDrives
from hiab_sim.model.mjcf import JOINTS, SLIDES, build_spec


def _swing(crane: Crane, friction: JointFriction, h: float) -> tuple[float, float, float, float]:
    """Release the crane at a mid-plan state (rates x3) under constant slide forces for 0.3 s.

    Returns:
        (change of mechanical energy, work of the slide forces, dissipated by the meter, of it the slides' damping) [J].

    """
    plan = synthetic_plan(crane)
    motion = planned_motion(plan, h)
    k0 = len(motion.time) // 2
    slides = SlideDrives.from_emla(plan.emlas)
    spec = build_spec(crane, plan.lengths, slides)
    names = [spec.joints[i].name for i in range(len(spec.joints))]
    force = (float(motion.force[k0, 0]), float(motion.force[k0, 1]), float(motion.force[k0, 2]))
    home = HomePose(qpos={n: float(motion.qpos[k0, i]) for i, n in enumerate(names)}, force=force)
    spec = build_spec(crane, plan.lengths, slides, home)
    joints, tendons = add_joint_friction(spec, friction, hinges=JOINTS)
    spec.option.timestep = h
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    model = spec.compile()
    data = mujoco.MjData(model)
    meter = FrictionMeter(model, joints, tendons)
    dofs = [model.jnt_dofadr[model.joint(s).id] for s in SLIDES]
    screw = model.dof_damping[dofs]  # the screws' viscous friction, the slides' damping
    data.qpos[:] = motion.qpos[k0]
    data.qvel[:] = 3.0 * motion.qvel[k0]
    data.ctrl[:] = force
    mujoco.mj_forward(model, data)
    energy0, x0 = float(data.energy.sum()), data.qpos[dofs].copy()
    dissipated = slides_dissipated = 0.0
    for _ in range(round(0.3 / h)):
        mujoco.mj_step(model, data)
        dissipated += h * meter.power(model, data)
        slides_dissipated += h * float(screw @ data.qvel[dofs] ** 2)
    mujoco.mj_forward(model, data)
    work = float(np.asarray(force) @ (data.qpos[dofs] - x0))
    return float(data.energy.sum()) - energy0, work, dissipated, slides_dissipated


def test_friction_sits_on_the_hinges_pins_and_rod_pin_tendons(crane: Crane) -> None:
    """Each closed chain gets friction on its boom hinge and base pin, and a rod-pin tendon q_boom - q_barrel."""
    spec = build_spec(crane)
    joints, tendons = add_joint_friction(spec, JointFriction(True, 150.0, 50.0, 100.0, 20.0), hinges=JOINTS)
    model = spec.compile()
    assert len(joints) == 4 and len(tendons) == 2
    for name in joints:
        assert model.dof_frictionloss[model.jnt_dofadr[model.joint(name).id]] in (150.0, 100.0)
    assert np.all(model.tendon_frictionloss == 100.0) and np.all(model.tendon_damping == 20.0)
    meter = FrictionMeter(model, joints, tendons)
    assert np.all(np.abs(meter.tendon_rows).sum(axis=1) == 2.0)  # +1 boom hinge, -1 barrel hinge


def test_hinge_friction_dissipates_the_energy_the_crane_loses(crane: Crane) -> None:
    """Mechanical energy change = work of the slide forces - (hinge and pin friction + screw damping) dissipation.

    The dissipation is the meter's integral of f (J v') (Coulomb rows) and c v'^2 (viscous); the
    energy is MuJoCo's own potential + kinetic energy. The balance closes to 1 % of the friction's
    share at h = 0.25 ms, and without friction the friction meter reads zero.
    """
    change, work, friction, slides = _swing(crane, JointFriction(True, 150.0, 50.0, 100.0, 20.0), 2.5e-4)
    free_change, free_work, none, free_slides = _swing(crane, JointFriction(True, 0.0, 0.0, 0.0, 0.0), 2.5e-4)
    assert none == 0.0
    assert friction > 20.0
    assert change == pytest.approx(work - friction - slides, abs=0.01 * friction)
    assert free_change == pytest.approx(free_work - free_slides, abs=0.01 * friction)
