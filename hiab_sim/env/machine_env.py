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

Only the ideal plant: the plant effects of :mod:`hiab_sim.env.plant` are built on the crane's
model and names.
"""

from __future__ import annotations

from collections.abc import Callable

import mujoco
import numpy as np
from dm_control import mujoco as dm_mujoco
from dm_control.rl import control
from numpy.typing import NDArray

from hiab_sim.control.cascade import CascadeGains
from hiab_sim.emla.drive_sim import DriveArrays, DriveSimulator
from hiab_sim.env import CURRENT_BANDWIDTH_HZ, PHYSICS_TIMESTEP
from hiab_sim.env.drive_losses import DriveLossModel
from hiab_sim.env.machine_loop_design import machine_loop_design
from hiab_sim.env.machine_plan import MachinePlan
from hiab_sim.env.physics import CranePhysics
from hiab_sim.env.reference import PlannedMotion, motion_of_plan, physics_times
from hiab_sim.env.rollout import ClosedLoopRun, run_environment
from hiab_sim.env.task import CraneTrackingTask
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.dynamics.mjcf_build import spec_of_tree
from hiab_sim.machine.dynamics.mujoco_path import MujocoMachineDynamics
from hiab_sim.machine.dynamics.tree import MachineActuatorSamples, SimulationExtras, machine_tree
from hiab_sim.model.mjcf import source_to_world

Array = NDArray[np.float64]


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
    force = np.stack([np.interp(times, plan.time, plan.tcp_force[:, i]) for i in range(3)], axis=1)
    dynamics = MujocoMachineDynamics(plan.machine)

    def loaded_dynamics(pos: Array, vel: Array, acc: Array) -> tuple[MachineActuatorSamples, Array, Array]:
        actuators = dynamics(pos, vel, acc, tcp_force=force[:, :2])
        qpos, qvel, _ = dynamics.state(pos, vel, acc)
        return actuators, qpos, qvel

    reference = np.stack([np.interp(times, plan.time, plan.reference_tcp[:, i]) for i in range(2)], axis=1)
    motion = motion_of_plan(plan, times, dynamics.model, loaded_dynamics, plan.emlas, _to_world(reference))
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


class TcpLoad:
    """The plan's TCP force applied at site ``tcp`` each physics step (module docstring)."""

    def __init__(self, model: mujoco.MjModel, force: Array, timestep: float) -> None:
        self.site = int(model.site("tcp").id)
        self.body = int(model.site_bodyid[self.site])
        self.force = force
        self.timestep = timestep

    def apply(self, model: mujoco.MjModel, data: mujoco.MjData, holding: bool) -> None:
        """Set ``xfrc_applied`` of the TCP's body to F at the site (force and moment about the com)."""
        k = 0 if holding else int(min(max(round(data.time / self.timestep), 0), len(self.force) - 1))
        force = self.force[k]
        arm = data.site_xpos[self.site] - data.xipos[self.body]
        data.xfrc_applied[self.body, :3] = force
        data.xfrc_applied[self.body, 3:] = np.cross(arm, force)


def machine_environment(
    plan: MachinePlan,
    *,
    physics_timestep: float = PHYSICS_TIMESTEP,
    control_timestep: float = 2 * PHYSICS_TIMESTEP,
    current_bandwidth_hz: float = CURRENT_BANDWIDTH_HZ,
) -> control.Environment:
    """Closed-loop environment of a machine design's plan (the ideal plant, module docstring)."""
    if not (0.0 < physics_timestep <= 0.01):
        raise InvalidInputError("physics_timestep", physics_timestep, "must lie in (0, 0.01]", "s")
    n_sub = round(control_timestep / physics_timestep)
    if n_sub < 1 or abs(n_sub * physics_timestep - control_timestep) > 1e-9:
        raise InvalidInputError("control_timestep", control_timestep, "must be a multiple of the physics step", "s")
    motion, force = machine_motion(plan, physics_timestep)
    tree = machine_tree(plan.machine)
    spec = spec_of_tree(tree, _extras(plan))
    spec.option.timestep = physics_timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST  # implicit in the slides' damping
    physics = CranePhysics.from_model(dm_mujoco.wrapper.MjModel(spec.compile()))
    physics.attach_drives(
        DriveSimulator(DriveArrays.from_params(plan.emlas), bandwidth_hz=current_bandwidth_hz),
        DriveLossModel(plan.emlas),
        joints=tuple(tree.bodies[b].joint for b in tree.actuated),
        actuators=tuple(plan.machine.actuator_names),
    )
    physics.tcp_load = TcpLoad(physics.model.ptr, force, physics_timestep)
    task = CraneTrackingTask(plan, motion, physics.drives.drives.current_limit)  # type: ignore[arg-type]
    steps = round(plan.duration / control_timestep)
    return control.Environment(
        physics, task, time_limit=(steps - 0.5) * control_timestep, n_sub_steps=n_sub, flat_observation=False
    )


def run_machine_closed_loop(
    plan: MachinePlan,
    gains: CascadeGains | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> tuple[ClosedLoopRun, CranePhysics]:
    """One cycle of a machine design's plan under the cascade controller; the log and the Physics (free it)."""
    env = machine_environment(plan)
    motion = env.task.motion
    design = machine_loop_design(plan, machine_load_mass(plan, motion), gains)
    drives = DriveArrays.from_params(plan.emlas)
    run = run_environment(
        env, design, drives, plan.design, 0.0, plan, progress, None, 1, actuator_names=plan.actuator_names
    )
    return run, env.physics
