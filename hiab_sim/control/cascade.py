"""Cascade tracking controller: planned feedforward plus stroke position and velocity feedback -> i_q*.

Per actuator, with the plan's stroke x_p, rod velocity v_p and feedforward current i_ff (the
steady-state q-current of the planned load force, rate and acceleration, eqs. ``torque_force``,
``torque_torque``, ``dq0voltage``; :mod:`hiab_sim.env.reference`), and the measured motor-side
stroke x and rate v (the encoder, :mod:`hiab_sim.env.plant.sensors`):

    x_r  = x_p + f_x / k_s,  v_r = v_p + (df_x/dt) / k_s        (the planned spring deflection, if compliant)
    v*   = v_r + w_x (x_r - x)                                  (position loop, P)
    f_fb = m (w_v (v* - v) + w_i int (v* - v) dt)               (velocity loop, PI) [N]
    i_q* = i_ff + f_fb / (k K_t)                                 (force -> current, k = 2 pi G / rho)

m is the rod-side inertia the velocity loop acts on, taken as the drive's reflected inertia
J_m k^2 + M_sm (it dominates the crane's own inertia at the slides), so w_v and w_x are the
loops' bandwidths [rad/s]. The output is clipped to the drive's current limit; the integrator
stops while the output is clipped (anti-windup). The motor-side feedback is collocated with the
drive, so the drive train's spring lies outside the loops; f_x / k_s puts the motor side where the
planned load holds the rod on its path.

Design rules (:meth:`CascadeGains.design`): w_v = min(2 pi 8 Hz, omega_lock / 2), with omega_lock
the lowest drive-train resonance (the locked-rod frequency sqrt(k_s / m_m),
:mod:`hiab_sim.env.plant.drivetrain`), so the velocity loop crosses over an octave below it (with the
motor-side, collocated feedback the resonance cannot destabilise an ideal loop; the octave keeps it
out of the crossover, where the delays of sampling and sensing would excite it); the position loop
a factor 4 slower, w_x = w_v / 4 (the usual separation of cascaded loops); the integral corner
w_i = w_v / 8, an octave below the position loop. 8 Hz is the rigid-train bandwidth, 1/60 of the
500 Hz current loop. On the realistic plant a factor 3 instead of 2 doubles the largest TCP error
(11.9 mm instead of 6.2 mm on the default study's initial design; docs/plant.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import dm_env
import numpy as np

from hiab_sim.emla.drive_sim import DriveArrays
from hiab_sim.env.reference import PlannedMotion
from hiab_sim.errors import InvalidInputError

#: Velocity-loop bandwidth of a rigid drive train [Hz], and the design ratios of the module docstring.
RIGID_VELOCITY_BANDWIDTH_HZ = 8.0
RESONANCE_MARGIN = 2.0
POSITION_RATIO = 4.0
INTEGRAL_RATIO = 8.0


@dataclass(frozen=True)
class CascadeGains:
    """Loop bandwidths [rad/s]: position w_x, velocity w_v, velocity integral w_i."""

    position: float = 2.0 * math.pi * RIGID_VELOCITY_BANDWIDTH_HZ / POSITION_RATIO
    velocity: float = 2.0 * math.pi * RIGID_VELOCITY_BANDWIDTH_HZ
    integral: float = 2.0 * math.pi * RIGID_VELOCITY_BANDWIDTH_HZ / INTEGRAL_RATIO

    def __post_init__(self) -> None:
        for name in ("position", "velocity", "integral"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise InvalidInputError(f"gains.{name}", value, "must be finite and >= 0", "rad/s")

    @classmethod
    def design(cls, lowest_resonance_hz: float | None = None) -> CascadeGains:
        """Gains of the design rules (module docstring) for the lowest drive-train resonance [Hz] (None: rigid)."""
        velocity = 2.0 * math.pi * RIGID_VELOCITY_BANDWIDTH_HZ
        if lowest_resonance_hz is not None:
            if not (math.isfinite(lowest_resonance_hz) and lowest_resonance_hz > 0):
                raise InvalidInputError("lowest_resonance_hz", lowest_resonance_hz, "must be finite and > 0", "Hz")
            velocity = min(velocity, 2.0 * math.pi * lowest_resonance_hz / RESONANCE_MARGIN)
        return cls(position=velocity / POSITION_RATIO, velocity=velocity, integral=velocity / INTEGRAL_RATIO)


class CascadeController:
    """A policy for :func:`hiab_sim.env.load` environments: ``action = controller(time_step)``.

    Args:
        motion: The planned motion.
        drives: The controller's drive model (the planned one).
        gains: Loop bandwidths (default: :meth:`CascadeGains.design` of a rigid train).
        stiffness: k_s [N/m] of the drive train the controller assumes, or None (rigid).

    """

    def __init__(
        self,
        motion: PlannedMotion,
        drives: DriveArrays,
        gains: CascadeGains | None = None,
        stiffness: float | None = None,
    ) -> None:
        self.motion = motion
        self.gains = gains or CascadeGains()
        self.mass = drives.reflected_inertia
        self.force_to_current = 1.0 / (drives.ratio * drives.torque_constant)
        self.limit = drives.current_limit
        self.stroke = motion.stroke
        self.rate = motion.rod_velocity
        if stiffness is not None:
            step = float(motion.time[1] - motion.time[0])
            self.stroke = motion.stroke + motion.force / stiffness
            self.rate = motion.rod_velocity + np.gradient(motion.force, step, axis=0) / stiffness
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
        v_star = self.rate[k] + g.position * (self.stroke[k] - obs["measured_stroke"])
        error = v_star - obs["measured_velocity"]
        force = self.mass * (g.velocity * error + g.integral * g.velocity * self.integral)
        command = self.motion.current[k] + force * self.force_to_current
        clipped = np.clip(command, -self.limit, self.limit)
        self.integral += np.where(clipped == command, error * dt, 0.0)
        return clipped
