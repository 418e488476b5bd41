"""Cascade tracking controller: planned feedforward plus stroke position and velocity feedback -> i_q*.

Per actuator, with the plan's stroke x_p, rod velocity v_p and feedforward current i_ff (the
steady-state q-current of the planned load force, rate and acceleration, eqs. ``torque_force``,
``torque_torque``, ``dq0voltage``; :mod:`hiab_sim.env.reference`):

    v*   = v_p + w_x (x_p - x)                                  (position loop, P)
    f_fb = m (w_v (v* - v) + w_i int (v* - v) dt)               (velocity loop, PI) [N]
    i_q* = i_ff + f_fb / (k K_t)                                 (force -> current, k = 2 pi G / rho)

m is the rod-side inertia the velocity loop acts on, taken as the drive's reflected inertia
J_m k^2 + M_sm (it dominates the crane's own inertia at the slides), so w_v and w_x are the
loops' bandwidths [rad/s]. The output is clipped to the drive's current limit; the integrator
stops while the output is clipped (anti-windup).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import dm_env
import numpy as np

from hiab_sim.emla.drive_sim import DriveArrays
from hiab_sim.env.reference import PlannedMotion
from hiab_sim.errors import InvalidInputError


@dataclass(frozen=True)
class CascadeGains:
    """Loop bandwidths [rad/s]: position w_x, velocity w_v, velocity integral w_i."""

    position: float = 2.0 * math.pi * 2.0
    velocity: float = 2.0 * math.pi * 8.0
    integral: float = 2.0 * math.pi * 1.0

    def __post_init__(self) -> None:
        for name in ("position", "velocity", "integral"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise InvalidInputError(f"gains.{name}", value, "must be finite and >= 0", "rad/s")


class CascadeController:
    """A policy for :func:`hiab_sim.env.load` environments: ``action = controller(time_step)``."""

    def __init__(self, motion: PlannedMotion, drives: DriveArrays, gains: CascadeGains | None = None) -> None:
        self.motion = motion
        self.gains = gains or CascadeGains()
        self.mass = drives.reflected_inertia
        self.force_to_current = 1.0 / (drives.ratio * drives.torque_constant)
        self.limit = drives.current_limit
        self.integral = np.zeros(3)
        self.last_time = 0.0

    def reset(self) -> None:
        """Clear the integrator."""
        self.integral = np.zeros(3)
        self.last_time = 0.0

    def __call__(self, time_step: dm_env.TimeStep) -> np.ndarray:
        """q-current references [A] for the observation of ``time_step`` (module docstring)."""
        obs = time_step.observation
        time = float(obs["time"][0])
        if time_step.first():
            self.reset()
        dt = time - self.last_time
        self.last_time = time
        k = self.motion.index(time)
        g = self.gains
        v_star = self.motion.rod_velocity[k] + g.position * (self.motion.stroke[k] - obs["stroke"])
        error = v_star - obs["rod_velocity"]
        force = self.mass * (g.velocity * error + g.integral * g.velocity * self.integral)
        command = self.motion.current[k] + force * self.force_to_current
        clipped = np.clip(command, -self.limit, self.limit)
        self.integral += np.where(clipped == command, error * dt, 0.0)
        return clipped
