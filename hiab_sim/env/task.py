"""The tracking task on the crane Physics: observations, reward, episode = the study's cycle.

Action: the drives' q-current references i_q* [A] (the crane's lift, tilt, telescope, or a machine's
chains, :mod:`hiab_sim.env.machine_env`; shapes (3,) below are (A,) there), bounded by the drive
current limit I_max = tau_peak / (3/2 p Phi_PM) (i_d* = 0, zero-d-axis-current control).

Observations (``OrderedDict`` of float arrays):

* ``time`` (1,) [s]; ``joint_position`` (nq,) and ``joint_velocity`` (nv,) of every MuJoCo joint;
* ``stroke`` (3,) [m] and ``rod_velocity`` (3,) [m/s] of x1, x2, xt2;
* ``measured_stroke`` (3,) [m] and ``measured_velocity`` (3,) [m/s]: what the controller reads, the
  motor-side stroke and rate from the encoder (:mod:`hiab_sim.env.plant.sensors`; exact, and the
  rod's own, when the plant has no sensors and a rigid drive train);
* ``tcp`` and ``reference_tcp`` (3,) [m], MuJoCo world, the reference at this time;
* ``current_dq`` and ``voltage_dq`` (3, 2) [A, V]: (d, q) of each drive at the end of the last step;
* ``electrical_power`` (3,) [W]: mean 3/2 (v_d i_d + v_q i_q) of each drive over the last physics
  step; ``bus_power`` (1,) [W]: their sum, drawn from the DC bus (negative while regenerating).

Reward: minus the TCP tracking error in millimetres, r = -1000 |p_tcp - p_ref| (0 is perfect).
"""

from __future__ import annotations

import collections

import numpy as np
from dm_control.suite import base
from dm_env import specs

from hiab_sim.env.physics import CranePhysics
from hiab_sim.env.plan import DesignPlan
from hiab_sim.env.reference import PlannedMotion


class CraneTrackingTask(base.Task):
    """Track the planned motion of one design with the EMLA drives (module docstring)."""

    def __init__(self, plan: DesignPlan, motion: PlannedMotion, current_limit: np.ndarray) -> None:
        super().__init__(random=None)
        self.plan = plan
        self.motion = motion
        self.current_limit = np.asarray(current_limit, dtype=float)

    def initialize_episode(self, physics: CranePhysics) -> None:
        """Start at the plan's first state with the drives at its feedforward currents."""
        physics.data.qpos[:] = self.motion.qpos[0]
        physics.data.qvel[:] = self.motion.qvel[0]
        physics.drives.reset(0.0, self.motion.current[0])
        physics.current_reference = self.motion.current[0].copy()
        physics.reset_counters()
        if physics.drive_train is not None:
            physics.drive_train.reset(self.motion.stroke[0], self.motion.rod_velocity[0], self.motion.force[0])
        physics.forward()
        physics.sensor.reset(*physics.motor_state())

    def action_spec(self, physics: CranePhysics) -> specs.BoundedArray:
        """q-current references [A] within the drives' current limit."""
        return specs.BoundedArray(
            shape=self.current_limit.shape,
            dtype=np.float64,
            minimum=-self.current_limit,
            maximum=self.current_limit,
            name="i_q_ref",
        )

    def before_step(self, action: np.ndarray, physics: CranePhysics) -> None:
        """Hand the current references to the drives."""
        physics.current_reference = np.asarray(action, dtype=float).copy()

    def get_observation(self, physics: CranePhysics) -> collections.OrderedDict:
        """The observations of the module docstring."""
        data = physics.data
        time = float(data.time)
        last = physics.last
        h = physics.timestep()
        drives = physics.drives
        if last is None:
            omega = drives.drives.ratio * physics.rod_velocity()
            current = np.stack([drives.i_d, drives.i_q], axis=1)
            voltage = np.stack(drives.limited_command(drives.i_d, drives.i_q, drives.i_d, drives.i_q, omega), axis=1)
            power = 1.5 * np.sum(current * voltage, axis=1)
        else:
            current = np.stack([last.i_d, last.i_q], axis=1)
            voltage = np.stack([last.v_d, last.v_q], axis=1)
            power = last.electrical_energy / h
        obs = collections.OrderedDict()
        obs["time"] = np.array([time])
        obs["joint_position"] = data.qpos.copy()
        obs["joint_velocity"] = data.qvel.copy()
        obs["stroke"] = physics.stroke().copy()
        obs["rod_velocity"] = physics.rod_velocity().copy()
        measured_stroke, measured_velocity = physics.sensor.measured()
        obs["measured_stroke"] = np.array(measured_stroke, dtype=float)
        obs["measured_velocity"] = np.array(measured_velocity, dtype=float)
        obs["tcp"] = data.site_xpos[physics.tcp_site].copy()
        obs["reference_tcp"] = self.motion.reference_tcp[self.motion.index(time)].copy()
        obs["current_dq"] = current
        obs["voltage_dq"] = voltage
        obs["electrical_power"] = power
        obs["bus_power"] = np.array([float(np.sum(power))])
        return obs

    def get_reward(self, physics: CranePhysics) -> float:
        """-1000 |p_tcp - p_ref| (TCP error in mm, negated)."""
        time = float(physics.data.time)
        error = physics.data.site_xpos[physics.tcp_site] - self.motion.reference_tcp[self.motion.index(time)]
        return -1000.0 * float(np.sqrt(error @ error))
