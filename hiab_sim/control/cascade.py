"""Cascade tracking controller: planned feedforward plus stroke position and velocity feedback -> i_q*.

Per actuator, with the plan's stroke x_p, rod velocity v_p and feedforward current i_ff (the
steady-state q-current of the planned load force, rate and acceleration, eqs. ``torque_force``,
``torque_torque``, ``dq0voltage``; :mod:`hiab_sim.env.reference`), and the measured motor-side
stroke x and rate v (the encoder, :mod:`hiab_sim.env.plant.sensors`):

    x_r  = x_p + f_x / k_s,  v_r = v_p + (df_x/dt) / k_s        (the planned spring deflection, if compliant)
    v*   = v_r + w_x (x_r - x)                                  (position loop, P)
    f_fb = m (w_v (v* - v) + w_i int (v* - v) dt)               (velocity loop, PI) [N]
    i_q* = i_ff + f_fb / (k K_t)                                 (force -> current, k = 2 pi G / rho)

m is the inertia the velocity loop moves: the drive's reflected inertia J_m k^2 + M_sm plus, when
given, the crane's own effective mass at the slide along the plan (``load_mass``, the diagonal of
the slide-space mass matrix, :mod:`hiab_sim.env.loop_design`), so that w_v and w_x are the loops'
bandwidths [rad/s] on the crane as it is, not only on the motor side (on the XS 031 the booms add
1.1-2.1 times the lift's and tilt's reflected rotor inertia: with the rotor alone a nominal 8 Hz
loop crosses over at 2.6-3.9 Hz on them). The output is clipped to the drive's current limit; the integrator
stops while the output is clipped (anti-windup). The motor-side feedback is collocated with the
drive, so the drive train's spring lies outside the loops; f_x / k_s puts the motor side where the
planned load holds the rod on its path.

Design rules (:meth:`CascadeGains.design`): w_v / 2 pi = min(8 Hz, f_lock / 2, DESIGN_RATIO f_1):

* f_1, the structure's lowest natural frequency along the plan (locked rotor,
  :mod:`hiab_sim.structure.natural_frequency`): the check of
  :func:`~hiab_sim.structure.natural_frequency.bandwidth_margin` wants f_v <= f_1 / 3, and
  DESIGN_RATIO = 0.3 leaves a margin of 0.1 of that limit (our choice);
* f_lock, the lowest drive-train resonance of a compliant plant (the locked-rod frequency
  sqrt(k_s / m_m), :mod:`hiab_sim.env.plant.drivetrain`), an octave above the loop (with the
  motor-side, collocated feedback it cannot destabilise an ideal loop; the octave keeps it out of
  the crossover, where the delays of sampling and sensing would excite it);
* 8 Hz, the rigid-train bandwidth, 1/60 of the 500 Hz current loop.

The position loop is a factor 4 slower, w_x = w_v / 4 (the usual separation of cascaded loops),
and the integral corner w_i = w_v / 8, an octave below it. On a rigid mass the cascade is the
position PID m (w_v s + w_v (w_x + w_i) + w_v w_x w_i / s), whose closed loop
s^3 + w_v s^2 + w_v (w_x + w_i) s + w_v w_x w_i has a real pole at 0.114 w_v and a pair at
0.52 w_v with damping 0.85; :meth:`CascadeController.settle_time` is 5 time constants of the
slowest pole, the hold of a settled start (:meth:`CascadeController.hold`).
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
DESIGN_RATIO = 0.3
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

    @property
    def velocity_Hz(self) -> float:
        """Velocity-loop bandwidth w_v / 2 pi [Hz]."""
        return self.velocity / (2.0 * math.pi)

    @classmethod
    def design(
        cls, lowest_resonance_hz: float | None = None, first_natural_frequency_hz: float | None = None
    ) -> CascadeGains:
        """Gains of the design rules (module docstring).

        Args:
            lowest_resonance_hz: f_lock of a compliant drive train [Hz], or None (rigid).
            first_natural_frequency_hz: The structure's lowest natural frequency f_1 [Hz], or None (no data).

        """
        velocity = 2.0 * math.pi * RIGID_VELOCITY_BANDWIDTH_HZ
        for name, value, ratio in (
            ("lowest_resonance_hz", lowest_resonance_hz, 1.0 / RESONANCE_MARGIN),
            ("first_natural_frequency_hz", first_natural_frequency_hz, DESIGN_RATIO),
        ):
            if value is not None:
                if not (math.isfinite(value) and value > 0):
                    raise InvalidInputError(name, value, "must be finite and > 0", "Hz")
                velocity = min(velocity, 2.0 * math.pi * value * ratio)
        return cls(position=velocity / POSITION_RATIO, velocity=velocity, integral=velocity / INTEGRAL_RATIO)


class CascadeController:
    """A policy for :func:`hiab_sim.env.load` environments: ``action = controller(time_step)``.

    Args:
        motion: The planned motion.
        drives: The controller's drive model (the planned one).
        gains: Loop bandwidths (default: :meth:`CascadeGains.design` of a rigid train).
        stiffness: k_s [N/m] per drive of the drive train the controller assumes, or None (rigid).
        load_mass: The crane's effective mass at each slide [kg], (N, 3) at the motion's samples or
            (3,), added to the reflected inertia; None: the reflected inertia alone.

    """

    def __init__(
        self,
        motion: PlannedMotion,
        drives: DriveArrays,
        gains: CascadeGains | None = None,
        stiffness: float | np.ndarray | None = None,
        load_mass: np.ndarray | None = None,
    ) -> None:
        self.motion = motion
        self.gains = gains or CascadeGains()
        reflected = np.asarray(drives.reflected_inertia, dtype=float)
        extra = np.zeros(len(reflected)) if load_mass is None else np.asarray(load_mass, dtype=float)
        self.mass = np.broadcast_to(reflected + extra, motion.stroke.shape)
        self.force_to_current = 1.0 / (drives.ratio * drives.torque_constant)
        self.limit = drives.current_limit
        self.stroke = motion.stroke
        self.rate = motion.rod_velocity
        if stiffness is not None:
            step = float(motion.time[1] - motion.time[0])
            self.stroke = motion.stroke + motion.force / stiffness
            self.rate = motion.rod_velocity + np.gradient(motion.force, step, axis=0) / stiffness
        self.integral = np.zeros(len(reflected))
        self.last_time = 0.0
        self.settled = False

    def reset(self) -> None:
        """Clear the integrator."""
        self.integral = np.zeros_like(self.integral)
        self.last_time = 0.0
        self.settled = False

    def settle_time(self) -> float:
        """5 time constants of the slowest pole of the cascade on a rigid mass [s] (99.3 % settled)."""
        g = self.gains
        w = g.velocity
        poles = np.roots([1.0, w, w * (g.position + g.integral), w * g.position * g.integral])
        return 5.0 / float(np.min(-poles.real))

    def hold(self, observation: dict[str, np.ndarray], dt: float) -> np.ndarray:
        """q-current references [A] holding the plan's first pose at rest, integrating over dt [s].

        The settled start of a cycle (:func:`hiab_sim.env.rollout.run_closed_loop`): the loops hold the
        first sample's stroke at zero rate until the integrator carries what the feedforward misses
        (a heavier load); the next :meth:`__call__` then keeps that state instead of clearing it.
        """
        self.settled = True
        return self._command(observation, 0, dt, np.zeros_like(self.integral))

    def __call__(self, time_step: dm_env.TimeStep) -> np.ndarray:
        """q-current references [A] for the observation of ``time_step`` (module docstring)."""
        obs = time_step.observation
        time = float(obs["time"][0])
        if time_step.first():
            if not self.settled:
                self.reset()
            self.settled = False
            self.last_time = time
        dt = time - self.last_time
        self.last_time = time
        return self._command(obs, self.motion.index(time), dt)

    def _command(self, obs: dict[str, np.ndarray], k: int, dt: float, rate: np.ndarray | None = None) -> np.ndarray:
        """The cascade's output at plan sample k, integrating the velocity error over dt [s]."""
        g = self.gains
        v_star = (self.rate[k] if rate is None else rate) + g.position * (self.stroke[k] - obs["measured_stroke"])
        error = v_star - obs["measured_velocity"]
        force = self.mass[k] * (g.velocity * error + g.integral * g.velocity * self.integral)
        command = self.motion.current[k] + force * self.force_to_current
        clipped = np.clip(command, -self.limit, self.limit)
        self.integral += np.where(clipped == command, error * dt, 0.0)
        return clipped
