"""The planned motion at the physics rate: joints, actuator strokes, ID forces and feedforward currents.

The fine-grid samples of the plan (positions, rates and accelerations of Θ1, Θ2, xt2) are joined by
quintic Hermite interpolation, which matches position, rate and acceleration at every sample (exact
for the quintic B-spline between knots). MuJoCo inverse dynamics (:mod:`hiab_sim.dynamics.mujoco_id`,
on the model without drives) then gives the load-side actuator force f_x, velocity, acceleration and
stroke at every physics step (eq. ``dynamics``), and :func:`hiab_sim.emla.drive_state` the q-current
that produces them in steady electrical state (eqs. ``torque_force``, ``torque_torque``, ``dq0voltage``).
The TCP reference is interpolated with a cubic spline. :func:`motion_of_plan` is the one builder
of a :class:`PlannedMotion`: the crane's (:func:`planned_motion`) and a machine file's
(:func:`hiab_sim.env.machine_env.machine_motion`) differ only in the inverse dynamics, the drives the
feedforward inverts and how the reference is read.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

import mujoco
import numpy as np
from scipy.interpolate import CubicSpline

from hiab_sim.arrays import Array
from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
from hiab_sim.dynamics.samples import ActuatorSamples, JointSamples
from hiab_sim.emla.drive import drive_state
from hiab_sim.emla.params import EmlaParams
from hiab_sim.env.plan import DesignPlan, PlannedDesign
from hiab_sim.machine.dynamics.tree import MachineActuatorSamples
from hiab_sim.model.mjcf import source_to_world
from hiab_sim.model.states import site_positions


def quintic_hermite(
    grid: Array, position: Array, velocity: Array, acceleration: Array, times: Array
) -> tuple[Array, Array, Array]:
    """Position, rate and acceleration at ``times`` of the quintic Hermite interpolant of (K, n) samples."""
    index = np.clip(np.searchsorted(grid, times, side="right") - 1, 0, len(grid) - 2)
    h = (grid[index + 1] - grid[index])[:, None]
    s = ((times - grid[index])[:, None]) / h
    p0, p1 = position[index], position[index + 1]
    v0, v1 = velocity[index] * h, velocity[index + 1] * h
    a0, a1 = acceleration[index] * h * h, acceleration[index + 1] * h * h
    # Coefficients of p(s) = sum c_k s^k on [0, 1] matching p, p', p'' at both ends.
    c0, c1, c2 = p0, v0, 0.5 * a0
    c3 = 10 * (p1 - p0) - 6 * v0 - 4 * v1 - 1.5 * a0 + 0.5 * a1
    c4 = -15 * (p1 - p0) + 8 * v0 + 7 * v1 + 1.5 * a0 - a1
    c5 = 6 * (p1 - p0) - 3 * v0 - 3 * v1 - 0.5 * a0 + 0.5 * a1
    pos = c0 + s * (c1 + s * (c2 + s * (c3 + s * (c4 + s * c5))))
    vel = (c1 + s * (2 * c2 + s * (3 * c3 + s * (4 * c4 + s * 5 * c5)))) / h
    acc = (2 * c2 + s * (6 * c3 + s * (12 * c4 + s * 20 * c5))) / (h * h)
    return pos, vel, acc


@dataclass(frozen=True)
class PlannedMotion:
    """The plan sampled every physics step; arrays (N, .) over times k * timestep, k = 0 .. N-1.

    Attributes:
        time: [s].
        qpos, qvel: Loop-consistent full MuJoCo state of the planned motion.
        stroke, rod_velocity, rod_acceleration: Actuator x [m], v_x [m/s], a_x [m/s^2] (lift, tilt, telescope).
        force: Load-side f_x [N] from inverse dynamics.
        current: Steady-state q-current of each drive for (f_x, v_x, a_x) [A].
        reference_tcp: The study's TCP reference in MuJoCo world coordinates [m].
        planned_tcp: The TCP of the planned motion (MuJoCo kinematics), world [m].

    """

    time: Array
    qpos: Array
    qvel: Array
    stroke: Array
    rod_velocity: Array
    rod_acceleration: Array
    force: Array
    current: Array
    reference_tcp: Array
    planned_tcp: Array

    def index(self, time: float) -> int:
        """Sample index nearest to ``time`` [s], clipped to the plan."""
        step = self.time[1] - self.time[0]
        return int(min(max(round(time / step), 0), len(self.time) - 1))


#: Inverse dynamics of a planned motion at the physics rate: the independent joints' positions, rates
#: and accelerations (N, J) -> the actuators' load-side samples and the loop-consistent MuJoCo
#: ``qpos``, ``qvel`` (N, nv) of the model the planned TCP is read on.
MotionDynamics = Callable[[Array, Array, Array], tuple[ActuatorSamples | MachineActuatorSamples, Array, Array]]


def physics_times(plan: PlannedDesign, timestep: float) -> Array:
    """Times [s] (N,) of the physics steps over the plan's cycle, from its first sample, ``timestep`` [s] apart."""
    count = round(plan.duration / timestep) + 1
    return plan.time[0] + timestep * np.arange(count)


def motion_of_plan(
    plan: PlannedDesign,
    times: Array,
    model: mujoco.MjModel,
    dynamics: MotionDynamics,
    drives: Iterable[EmlaParams],
    reference_tcp: Array,
) -> PlannedMotion:
    """The plan at ``times`` (:func:`physics_times`): joints, inverse dynamics, feedforward currents, TCPs.

    The joints are the quintic Hermite interpolant of the plan's fine-grid samples; ``dynamics``
    gives f_x, v_x, a_x, x and the loop-consistent state (eq. ``dynamics``); each drive of ``drives``
    (the model the feedforward inverts, in actuator order) gives the steady-state q-current of
    :func:`hiab_sim.emla.drive_state`; the planned TCP is site ``tcp`` of ``model`` at that state.
    ``reference_tcp`` is the study's reference at ``times`` in MuJoCo world coordinates (N, 3) [m].
    """
    pos, vel, acc = quintic_hermite(plan.time, plan.position, plan.velocity, plan.acceleration, times)
    actuators, qpos, qvel = dynamics(pos, vel, acc)
    current = np.stack(
        [
            drive_state(params, actuators.force[:, i], actuators.velocity[:, i], actuators.acceleration[:, i]).i_q
            for i, params in enumerate(drives)
        ],
        axis=1,
    )
    return PlannedMotion(
        time=times - plan.time[0],
        qpos=qpos,
        qvel=qvel,
        stroke=actuators.stroke,
        rod_velocity=actuators.velocity,
        rod_acceleration=actuators.acceleration,
        force=actuators.force,
        current=current,
        reference_tcp=reference_tcp,
        planned_tcp=site_positions(model, qpos, "tcp"),
    )


def reference_at(plan: PlannedDesign, times: Array) -> Array:
    """The study's TCP reference at ``times`` [s] in MuJoCo world coordinates (N, 3) [m], a cubic spline of the plan's.

    All three coordinates (x_tcp, y_tcp, z_tcp) of {W}: the reference is a path in the plane the TCP moves
    in, z = z_tcp (the TCP's out-of-plane offset, constant when every joint turns about, or slides along, the
    plane), so its distance to the simulated TCP is the in-plane tracking error, and any out-of-plane motion
    of the TCP still counts (a projection onto the plane would hide it).
    """
    return source_to_world(CubicSpline(plan.time, plan.reference_tcp, axis=0)(times))


def planned_motion(plan: DesignPlan, timestep: float) -> PlannedMotion:
    """Sample a crane file's plan every ``timestep`` [s] (see the module docstring)."""
    times = physics_times(plan, timestep)
    dynamics = MujocoInverseDynamics(plan.crane, plan.lengths)
    tcp_force = plan.id_tcp_force(times)  # the payload's weight, or the task's F(t) where it is one per sample

    def crane_dynamics(pos: Array, vel: Array, acc: Array) -> tuple[ActuatorSamples, Array, Array]:
        joints = JointSamples(pos, vel, acc)
        actuators = dynamics(joints, tcp_force)
        qpos, qvel, _ = dynamics.state(joints)
        return actuators, qpos, qvel

    # the feedforward inverts the simulated drive, which has the EMLA file's screw and gearbox efficiency
    # (hiab_sim.env.drive_losses): the planner's own drive model, transmission loss included
    drives = list(plan.emlas)
    return motion_of_plan(plan, times, dynamics.model, crane_dynamics, drives, reference_at(plan, times))
