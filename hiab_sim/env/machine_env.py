"""Any machine file's design in closed loop: the generic MJCF, EMLA drives per chain, the cascade, the plan.

The crane's environment (:mod:`hiab_sim.env`) with the machine's model in place of the XS 031's;
the Physics (:class:`~hiab_sim.env.physics.CranePhysics`), the tracking task
(:class:`~hiab_sim.env.task.CraneTrackingTask`), the controller
(:class:`~hiab_sim.control.cascade.CascadeController`) and the rollout
(:func:`hiab_sim.env.rollout.run_environment`) are the same code, sized by the machine's chains:

* **Model.** :func:`hiab_sim.machine.dynamics.mjcf_build.spec_of_tree` of the design with the
  simulation extras per chain: armature J_m k^2 + M_sm [kg] and damping b_f [N s/m] on the rod slide
  (eqs. ``torque_torque``, ``torque_force``), loops as ``connect`` equalities, one force motor per
  chain (ctrl = the drive's rod force k (tau - tau_f) [N]); implicit-fast integration at 1 ms.
* **Planned motion.** The crane's builder (:func:`hiab_sim.env.reference.motion_of_plan`): the
  plan's joint samples joined by quintic Hermite interpolation at the physics rate, closed on the
  loops and solved for the load-side f_x, v_x, a_x, x by MuJoCo inverse dynamics of the bare
  mechanism with the study's TCP force
  (:class:`~hiab_sim.machine.dynamics.mujoco_path.MujocoMachineDynamics`, eq. ``dynamics``); the
  feedforward current is :func:`hiab_sim.emla.drive.drive_state`'s i_q of the study's drives.
* **TCP load.** The plan's TCP force F(t) (:mod:`hiab_sim.env.machine_plan`) is applied at site
  ``tcp`` every physics step (``xfrc_applied``, with its moment about the body's centre of mass),
  at the planned time; during the settled start's hold, the first sample's. It is the planner's
  load exactly (no inertia of its own where the study gives its payload none).
* **Load mass.** m_L,a = (J_x^-T G^T M G J_x^-1)_aa: M the open tree's mass matrix (``mj_fullM``),
  G = d qvel / d dq the loop-consistent velocity map of the independent joints (columns from unit
  rates), J_x = rows of G at the rod slides; the crane's rule (:mod:`hiab_sim.env.loop_design`).
* **Gains.** :meth:`~hiab_sim.control.cascade.CascadeGains.design` of a rigid train against the
  machine's lowest locked-rotor natural frequency f_1 over the plan, and the run's
  ``bandwidth_check`` of the velocity loop against it (:mod:`hiab_sim.env.machine_loop_design`).

* **Plant.** The effects of :mod:`hiab_sim.env.plant` on the machine's own parts, through the
  crane's code (:mod:`hiab_sim.env.plant.assembly`): the mismatch on the machine description and
  the payload's share of the TCP force (:func:`~hiab_sim.env.plant.mismatch.true_machine`,
  :class:`TcpLoad`), the two-mass drive train on each chain's rod slide with the EMLA file's
  ``drive_stiffness`` (the rotor off the slide: armature = the plant's rod-side mass, no damping),
  hinge friction on the machine's joints and pin friction on the chains' hinges and loop pins
  (:func:`~hiab_sim.env.plant.friction.add_joint_friction`), sensors, the discrete current loop and
  the winding temperature. With every effect off the model is the ideal one, step for step; the
  study's hot windings set R_s as on the crane (:func:`hiab_sim.env.planned_energy.hot_resistance`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import mujoco
import numpy as np
from dm_control import mujoco as dm_mujoco
from dm_control.rl import control

from hiab_sim.arrays import Array
from hiab_sim.control.cascade import CascadeGains
from hiab_sim.emla.drive_sim import DriveArrays
from hiab_sim.env import CURRENT_BANDWIDTH_HZ, PHYSICS_TIMESTEP, episode, sub_steps
from hiab_sim.env.machine_loop_design import machine_loop_design
from hiab_sim.env.machine_plan import MachinePlan
from hiab_sim.env.physics import CranePhysics
from hiab_sim.env.planned_energy import resampled_prediction
from hiab_sim.env.plant.assembly import (
    active_plant,
    compliant_stiffness,
    drive_train_resonance,
    plant_parts,
    spring_actuators,
)
from hiab_sim.env.plant.config import Plant
from hiab_sim.env.plant.friction import add_joint_friction
from hiab_sim.env.plant.mismatch import friction_factor, payload_factor, true_drive_arrays, true_machine
from hiab_sim.env.reference import PlannedMotion, motion_of_plan, physics_times, reference_at
from hiab_sim.env.rollout import ClosedLoopRun, check_cycles, run_environment
from hiab_sim.env.task import CraneTrackingTask
from hiab_sim.env.tcp_load import TcpLoad
from hiab_sim.machine.dynamics.mjcf_build import spec_of_tree
from hiab_sim.machine.dynamics.mujoco_path import MujocoMachineDynamics
from hiab_sim.machine.dynamics.tree import MachineActuatorSamples, SimulationExtras, machine_tree
from hiab_sim.model.mjcf import source_to_world


def _extras(plan: MachinePlan) -> SimulationExtras:
    """Armature J_m k^2 + M_sm [kg] and screw damping b_f [N s/m] per chain."""
    params = plan.emlas.as_tuple()
    return SimulationExtras(
        armature_kg=tuple(p.motor.rotor_inertia * p.transmission_ratio**2 + p.screw_moving_mass for p in params),
        damping_Ns_per_m=tuple(p.viscous_friction for p in params),
    )


def _to_world(points: Array) -> Array:
    """Plane points (x, y) of {W} (..., 2) to MuJoCo world (x, 0, y)."""
    full = np.zeros((*points.shape[:-1], 3))
    full[..., :2] = points
    return source_to_world(full)


def machine_motion(plan: MachinePlan, timestep: float) -> tuple[PlannedMotion, Array]:
    """The plan every ``timestep`` [s] (module docstring) and the TCP force there, MuJoCo world (N, 3) [N]."""
    times = physics_times(plan, timestep)
    force = plan.force_at(plan.tcp_force, times)
    dynamics = MujocoMachineDynamics(plan.machine)

    def loaded_dynamics(pos: Array, vel: Array, acc: Array) -> tuple[MachineActuatorSamples, Array, Array]:
        actuators = dynamics(pos, vel, acc, tcp_force=force[:, :2])
        qpos, qvel, _ = dynamics.state(pos, vel, acc)
        return actuators, qpos, qvel

    # The reference at the TCP's out-of-plane z (the XS 031 machine file's TCP sits at z = -9.23 mm in {W},
    # off the mechanism's plane by the tool's side offset), as on a crane file: reference_at's docstring.
    motion = motion_of_plan(plan, times, dynamics.model, loaded_dynamics, plan.emlas, reference_at(plan, times))
    return motion, _to_world(force[:, :2])


def machine_load_mass(plan: MachinePlan, motion: PlannedMotion) -> Array:
    """m_L per chain (N, A) [kg] at the motion's samples, from the plan's fine grid (module docstring)."""
    dynamics = MujocoMachineDynamics(plan.machine)
    model, data = dynamics.model, mujoco.MjData(dynamics.model)
    tree = dynamics.tree
    slides = [int(model.joint(tree.bodies[b].joint).dofadr[0]) for b in tree.actuated]
    n_joints = plan.position.shape[1]
    eye = np.eye(n_joints)
    masses = np.empty((len(plan.time), len(slides)))
    full = np.zeros((model.nv, model.nv))
    for k, q in enumerate(plan.position):
        rows = np.repeat(q[None], n_joints, axis=0)
        qpos, qvel, _ = dynamics.state(rows, eye, np.zeros_like(eye))
        velocity_map = qvel.T  # (nv, J): column j the loop-consistent qvel of a unit rate of joint j
        data.qpos[:] = qpos[0]
        mujoco.mj_fwdPosition(model, data)
        mujoco.mj_fullM(model, data, full)
        joint_mass = velocity_map.T @ full @ velocity_map
        inverse = np.linalg.inv(velocity_map[slides])
        masses[k] = np.diag(inverse.T @ joint_mass @ inverse)
    grid = plan.time - plan.time[0]
    return np.stack([np.interp(motion.time, grid, masses[:, a]) for a in range(len(slides))], axis=1)


def machine_environment(
    plan: MachinePlan,
    *,
    physics_timestep: float = PHYSICS_TIMESTEP,
    control_timestep: float = 2 * PHYSICS_TIMESTEP,
    current_bandwidth_hz: float = CURRENT_BANDWIDTH_HZ,
    plant: Plant | None = None,
) -> control.Environment:
    """Closed-loop environment of a machine design's plan on ``plant`` (None: the ideal plant; module docstring)."""
    n_sub = sub_steps(control_timestep, physics_timestep)
    motion, force = machine_motion(plan, physics_timestep)
    active = active_plant(plant)
    machine, arrays, extras = plan.machine, DriveArrays.from_params(plan.emlas), _extras(plan)
    if active is not None and active.mismatch.enabled:
        machine = true_machine(machine, active.mismatch)
        arrays = true_drive_arrays(arrays, active.mismatch)
        factor = friction_factor(active.mismatch)
        extras = SimulationExtras(extras.armature_kg, tuple(d * factor for d in extras.damping_Ns_per_m))
    stiffness = compliant_stiffness(plan.emlas, motion, plant, physics_timestep)
    if active is not None and stiffness is not None:  # the rotor and the screw friction move to the motor side
        count = len(extras.armature_kg)
        extras = SimulationExtras((active.drive_train.rod_side_mass_kg,) * count, (0.0,) * count)
    tree = machine_tree(machine)
    spec = spec_of_tree(tree, extras)
    spec.option.timestep = physics_timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST  # implicit in the slides' damping
    actuators = tuple(plan.machine.actuator_names)
    if stiffness is not None:
        spring_actuators(spec, actuators)
    friction: tuple[tuple[str, ...], tuple[str, ...]] = ((), ())
    if active is not None and active.joint_friction.enabled:
        friction = add_joint_friction(spec, active.joint_friction, hinges=machine.joint_names)
    physics = CranePhysics.from_model(dm_mujoco.wrapper.MjModel(spec.compile()))
    joints = tuple(tree.bodies[b].joint for b in tree.actuated)
    parts = plant_parts(physics.model.ptr, plan, motion, arrays, plant, stiffness, friction, current_bandwidth_hz)
    physics.attach_parts(parts, plant, joints, actuators)
    if active is not None and active.mismatch.enabled:
        payload = _to_world(plan.force_at(plan.payload_force, physics_times(plan, physics_timestep))[:, :2])
        offset = np.asarray(active.mismatch.end_mass_com_offset_m, dtype=float)
        physics.tcp_load = TcpLoad(
            physics.model.ptr, force, physics_timestep, payload, payload_factor(active.mismatch), offset
        )
    else:
        physics.tcp_load = TcpLoad(physics.model.ptr, force, physics_timestep)
    task = CraneTrackingTask(plan, motion, physics.drives.drives.current_limit)  # type: ignore[arg-type]
    return episode(physics, task, plan.duration, control_timestep, n_sub)


def run_machine_closed_loop(
    plan: MachinePlan,
    gains: CascadeGains | None = None,
    progress: Callable[[int, int], None] | None = None,
    plant: Plant | None = None,
    cycles: int = 1,
) -> tuple[ClosedLoopRun, CranePhysics]:
    """``cycles`` cycles of a machine design's plan on ``plant`` under the cascade; the last log and the Physics."""
    check_cycles(cycles)
    env = machine_environment(plan, plant=plant)
    motion = env.task.motion
    stiffness, lowest = drive_train_resonance(plan.emlas, motion, plant)
    design = machine_loop_design(plan, machine_load_mass(plan, motion), gains, stiffness, lowest)
    drives = DriveArrays.from_params(plan.emlas)
    run = run_environment(
        env, design, drives, plan.design, 0.0, plan, progress, plant, cycles, actuator_names=plan.actuator_names
    )
    return replace(run, resampled_prediction=resampled_prediction(plan, motion), task=plan.task), env.physics
